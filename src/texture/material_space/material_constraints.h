// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// User constraints of a material-space mapping (Ray et al. 2009, sections 2
// and 4: the brush that fixes the effect area, orientation strokes, scale and
// material picks) read from a JSON file and resolved on a mesh.
//
// Format (every field optional; unknown fields are errors): "effect_radius"
// (> 0, mesh units; absent = whole mesh), "strokes" (faces + direction, or a
// polyline of >= 2 points), "scale" and "material" points with values (S in
// mesh units, m in [0, 1]). Points lie within one box size of the mesh.
// Polylines are sampled about once per mean edge, each sample constraining
// its nearest face; scale and material points go to their nearest vertex.
// The format in full with an example: docs/decisions/303-pbr-maps.md.
//
// Errors throw InvalidInputError "FILE: line L: field F: what" (json_input.h
// limits); read_material_constraints throws IOError if the file cannot be
// read or exceeds 16 MiB.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "geometry/direction_field.h"
#include "geometry/mesh_fwd.h"
#include "geometry/scalar_field_interpolation.h"

namespace surftex {

struct MaterialConstraints {
  std::vector<DirectionConstraint> directions;
  std::vector<ScalarConstraint> scale;
  std::vector<ScalarConstraint> material;
  /// Effect radius in mesh units; +inf when the file gives none.
  double effect_radius = std::numeric_limits<double>::infinity();
  /// Every vertex touched by a constraint (vertices of the constrained faces,
  /// scale and material vertices), sorted and unique: the effect area's seeds.
  std::vector<std::uint32_t> seed_vertices;
  std::size_t strokes = 0;  ///< number of stroke entries in the file
};

/// Parses `text` (the file's content; `source` names it in messages) against
/// `mesh` (a triangle mesh).
MaterialConstraints parse_material_constraints(const std::string& text, const Mesh& mesh,
                                               const std::string& source = "constraints");

/// Reads and parses the file at `path`.
MaterialConstraints read_material_constraints(const std::string& path, const Mesh& mesh);

}  // namespace surftex
