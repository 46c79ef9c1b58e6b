// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The material-space mapping pipeline of Ray et al. 2009, section 2, as one
// driver shared by `surftex material-map`, the demo and bench_pgp (same steps,
// same defaults):
// map(): orientation field (strokes, else smoothed principal directions, else
// +Y; 2.2), scale and material (2.2), PGP (2.3), singular zones (3);
// update(): the same inside the new constraints' effect area (2.1), the rest
// bit for bit; save_state() / load_state(): the solver state as JSON. Fields
// run beside the PGP's preparation (TBB), same bytes.
//
// Writes kFaceDirection, kVertexScale, kVertexMaterial, kCornerSTM (and the
// curvature maps for the curvature field). Throws InvalidInputError (options
// out of range, an update before map/load, an update without constraints, a
// state of another version or mesh), IOError (state files), plus what the
// stages throw.

#include <map>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "texture/material_space/material_constraints.h"
#include "geometry/mesh_fwd.h"
#include "texture/material_space/pgp_singularities.h"

namespace surftex {

class PeriodicGlobalParameterization;

struct MaterialMappingOptions {
  /// Period S in mesh units where no scale constraint applies; > 0, or 0 =
  /// `edges_per_period` x the mean edge length. Default 0.
  double scale = 0;
  /// Automatic period in mean edge lengths, 1..1000. Default 8.
  double edges_per_period = 8;
  /// Orientation without strokes: Curvature (principal directions of the
  /// `curvature_fraction` most anisotropic faces, made soft by
  /// `curvature_smoothing`) or Constant (world +Y projected). Default Curvature.
  enum class Field { Curvature, Constant };
  Field field = Field::Curvature;
  /// Share of faces whose principal directions constrain the field, (0, 1]. Default 0.1.
  double curvature_fraction = 0.1;
  /// Smoothing of those constraints (DirectionFieldOptions::smoothing, about
  /// 8 face rings), >= 0. Default 64.
  double curvature_smoothing = 64;
  /// Curl correction of the PGP target (pgp_curl_correction.h). Default off.
  bool curl_correction = false;
  /// s and t coupled across the field's cuts (false = the paper's simplified
  /// PGP, two independent systems). Default true.
  bool swap_coordinates = true;
};

/// What a map() or update() did, for reports (to_json).
struct MaterialMappingResult {
  std::string mode;              ///< "initialize" or "update"
  std::string field_source;      ///< "strokes", "curvature" or "constant" (map only)
  std::size_t direction_constraints = 0;
  double default_scale = 0;      ///< the period S used where no scale constraint applies
  bool curl_correction = false, swap_coordinates = true;
  double effect_radius = 0;      ///< update: +inf = none given
  std::size_t effect_faces = 0, effect_vertices = 0;  ///< update
  PgpSingularities singularities;
  std::map<std::string, double> seconds;  ///< per stage, wall
};

/// Report fields (no singularity arrays: their counts and fractions).
nlohmann::json to_json(const MaterialMappingResult& r);

class MaterialMapping {
 public:
  /// `mesh` must be a triangle mesh and outlive the object.
  MaterialMapping(Mesh& mesh, const MaterialMappingOptions& options = {});
  ~MaterialMapping();
  MaterialMapping(const MaterialMapping&) = delete;
  MaterialMapping& operator=(const MaterialMapping&) = delete;

  /// Initial mapping from `constraints` (may be empty).
  const MaterialMappingResult& map(const MaterialConstraints& constraints);
  /// Re-solves inside the effect area (effect_radius) of `constraints` (at
  /// least one constraint). Needs map() or load_state() first.
  const MaterialMappingResult& update(const MaterialConstraints& constraints);
  /// Writes the state (format "surftex material-map state v2") atomically.
  void save_state(const std::string& path, bool overwrite) const;
  /// Reads a state written by save_state for this mesh; its PGP variant
  /// (curl correction, swap) replaces the options'.
  void load_state(const std::string& path);

  const MaterialMappingResult& result() const { return result_; }
  const MaterialMappingOptions& options() const { return options_; }

 private:
  void make_solver();
  void detect_singularities();
  Mesh& mesh_;
  MaterialMappingOptions options_;
  std::unique_ptr<PeriodicGlobalParameterization> pgp_;
  MaterialMappingResult result_;
  bool solved_ = false;
};

}  // namespace surftex
