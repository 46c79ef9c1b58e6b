// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Simplified Periodic Global Parameterization (Ray et al. 2009, section 2.3,
// after Ray et al. 2006): per-corner texture coordinates (s,t) whose gradient
// in each triangle T follows g_s = d_s / S^T and g_t = d_t / S^T (d_t = n x d_s,
// S^T = mean vertex scale), defined up to integers, so a periodic tile maps
// seamlessly wherever the field allows it.
//
// Per vertex z_s = exp(2 pi i s), z_t = exp(2 pi i t); a quarter turn across
// a cut maps z_s -> z_t, z_t -> conj(z_s) (Ray et al. 2006): 4 reals per
// vertex. Equation (3) per edge solved in the least-squares sense (sparse SPD,
// METIS + CHOLMOD, analysis reused; BLAS pinned to one thread and locked when
// not concurrent-safe). Start: spanning-tree integration + `init_iterations`
// Ginzburg-Landau steps; corners by equation (4), consistent across edges.
// In full, with why the paper's start was replaced: docs/decisions/305.
// derivation, the BLAS notes and why the paper's initialisation was replaced:
// docs/decisions/305-pgp-solver.md.
//
// With options.curl_correction every use of g sees pgp_curl_correction.h's factor.
//
// Reads the face map direction_map (Vector3 d_s), the vertex maps scale_map
// (S > 0) and material_map (m); writes the halfedge map stm_map (STM, the
// corner of face(h) at target(h)); absent scale/material maps read as 1 / 0.
// After an update only corners of faces in the effect area are rewritten.
// Throws InvalidInputError (missing direction map, non-positive scale, bad
// options), SolverError (symbolic analysis/factorisation/solve failure).
// PgpResult::breakdown: the wall time of each step (bench_pgp prints it).

#include <array>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/property_names.h"

namespace surftex {

struct EffectArea;

struct PgpOptions {
  int symmetry = 4;  ///< symmetry N of the direction field (1, 2 or 4): matching across edges
  std::uint32_t locked_vertex = 0;  ///< has s = t = 0 after initialisation
  /// Relaxation steps of the initialisation (>= 1), each one solve with the
  /// factorisation reused.
  int init_iterations = 16;
  /// Relaxation steps of a local update (>= 1).
  int update_iterations = 4;
  /// Weight mu of the unit-modulus pull, relative to the mean diagonal of
  /// F_PGP over the mean vertex area (> 0). Smaller lets vortices (PGP
  /// singularities) be smaller but |z| sag (docs/decisions/304-pgp-options.md).
  double stiffness = 0.01;
  /// Curl correction of the target gradients (Ray et al. 2006;
  /// pgp_curl_correction.h). Default off, as Ray et al. 2009, 2.3 (decision 304).
  bool curl_correction = false;
  /// Swap s and t across the field's quarter-turn cuts (Ray et al. 2006;
  /// default true). false = the paper's simplified PGP: two independent s and t
  /// systems, a quarter of the flops, singular faces along the cuts (decision 304).
  bool swap_coordinates = true;
  /// swap_coordinates false only: solve each half as its complex n x n system
  /// (half the flops, same result up to rounding). Default true.
  bool separate_halves = true;
  double curl_stiffness = 1.0;   ///< PgpCurlCorrectionOptions::stiffness (> 0)
  double curl_max_factor = 2.0;  ///< PgpCurlCorrectionOptions::max_factor (>= 1)
  PropertyName<FaceIndex, Vector3> direction_map = kFaceDirection;
  PropertyName<VertexIndex, double> scale_map = kVertexScale;
  PropertyName<VertexIndex, double> material_map = kVertexMaterial;
  PropertyName<HalfedgeIndex, STM> stm_map = kCornerSTM;
};

struct PgpResult {
  std::size_t free_vertices = 0;
  double energy_s = 0, energy_t = 0;  ///< F_PGP at the solution (in area units)
  double seconds = 0;
  bool reused_analysis = false;  ///< symbolic factorisation reused from the previous solve
  /// OpenBLAS kernel set behind CHOLMOD ("" for another BLAS).
  std::string blas_core;
  /// The BLAS allows concurrent calls (halves and solvers run side by side).
  bool concurrent_blas = false;
  /// Wall seconds per step; pairs run side by side, so the sum can exceed
  /// `seconds` (ordering beside field + start, analysis beside assembly).
  struct Breakdown {
    double topology = 0;     ///< connectivity, areas, frames (first call only)
    double field = 0;        ///< face gradients, halfedge alphas, matchings, edge maps
    double ordering = 0;     ///< nested-dissection order of the free vertices (when the free set changed)
    double pattern = 0;      ///< sparsity pattern of the free set (when it changed)
    double start = 0;        ///< spanning-tree integration (initialisation only)
    double assembly = 0;     ///< matrix values and locked-vertex right-hand side
    double analysis = 0;     ///< symbolic factorisation (0 when reused)
    double factorization = 0;  ///< numeric factorisation (no-swap halves side by side: the slower half's)
    double factor_flops = 0;     ///< of the numeric factorisation (CHOLMOD's count from the pattern; for the complex halves of the n x n patterns, each a complex operation, ~4 real flops)
    double factor_nonzeros = 0;  ///< in the Cholesky factor L
    double solves = 0;       ///< all relaxation steps (right-hand side + solve; halves side by side: the slower half's)
    int steps = 0;           ///< relaxation steps run
    double energy = 0;       ///< energies at the solution
    double corners = 0;      ///< corner write-back (equation 4)
  } breakdown;
};

/// Expected increase of (s,t) along each halfedge h (source -> target), in
/// periods: alpha_h = e_h . (g^T + g^T')/2 of equation (3) (one-sided on the
/// border), in the frame of the edge's reference face, face(halfedge(e, 0))
/// unless that is the border. Indexed by halfedge `.idx()`; alpha[opposite] = -alpha.
std::vector<std::array<double, 2>> pgp_halfedge_alphas(const Mesh& mesh, const PgpOptions& options);

/// Per face and corner c (0..2 = target of halfedge(f), next, next-next), the
/// texture-space gradient pair (g_s, g_t) as 3D vectors: helper for the
/// distortion test of section 3. Indexed by face `.idx()`.
std::vector<std::array<std::array<double, 3>, 2>> pgp_face_gradients(const Mesh& mesh,
                                                                     const PgpOptions& options);

/// Both of the above from one computation of the target (one curl
/// correction instead of two).
struct PgpTarget {
  std::vector<std::array<std::array<double, 3>, 2>> gradients;  ///< as pgp_face_gradients
  std::vector<std::array<double, 2>> alphas;                    ///< as pgp_halfedge_alphas
};
PgpTarget pgp_target(const Mesh& mesh, const PgpOptions& options);

/// Stateful solver (geometry-central style): keeps the per-vertex complex
/// coordinates and the symbolic analysis between local updates.
class PeriodicGlobalParameterization {
 public:
  PeriodicGlobalParameterization(Mesh& mesh, PgpOptions options = {});
  ~PeriodicGlobalParameterization();
  PeriodicGlobalParameterization(const PeriodicGlobalParameterization&) = delete;
  PeriodicGlobalParameterization& operator=(const PeriodicGlobalParameterization&) = delete;

  /// Optional, ahead of initialize(): the connectivity-only work (topology,
  /// fill-reducing order), for a caller to overlap with the direction field.
  /// Reads connectivity and points only; same bytes with or without it.
  void prepare();
  /// The same ahead of update(area) (the area's free-vertex order).
  void prepare(const EffectArea& area);
  /// Global solve (one locked vertex per component); writes every corner.
  PgpResult initialize();
  /// Local solve: vertices outside area.vertex_free keep their previous
  /// value; corners of faces outside area.face_free are not rewritten.
  /// Throws InvalidInputError if called before initialize() or the area does
  /// not match the mesh.
  PgpResult update(const EffectArea& area);

  /// Per vertex (by `.idx()`) complex coordinates z_s, z_t (unit after solve),
  /// in the vertex's frame (see above; it depends on the direction field).
  const std::vector<std::complex<double>>& z_s() const;
  const std::vector<std::complex<double>>& z_t() const;
  /// Restores a previous state (e.g. loaded from disk for `--update`).
  void set_state(std::vector<std::complex<double>> zs, std::vector<std::complex<double>> zt);
  /// Rewrites the corners of every face from the current state and the
  /// current direction/scale/material maps (e.g. after set_state on a freshly
  /// loaded mesh). Throws InvalidInputError before initialize()/set_state().
  void write_corners();
  /// F_PGP (s part, t part) of the current state recomputed from scratch
  /// over every edge (in each edge's reference frame). Throws
  /// InvalidInputError before initialize()/set_state().
  std::array<double, 2> energies();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Default texture period S for a mesh: `edges_per_period` times the mean
/// edge length (mesh units). Throws InvalidInputError for a value <= 0 or a
/// mesh without edges of positive length.
double pgp_default_scale(const Mesh& mesh, double edges_per_period = 8.0);

/// One-shot: initialise and write the corners.
PgpResult periodic_global_parameterization(Mesh& mesh, const PgpOptions& options = {});

}  // namespace surftex
