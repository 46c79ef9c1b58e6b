// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Simplified Periodic Global Parameterization (Ray et al. 2009, section 2.3,
// after Ray et al. 2006): per-corner texture coordinates (s,t) whose gradient
// in each triangle T follows g_s = d_s / S^T and g_t = d_t / S^T (d_t = n x d_s,
// S^T = mean vertex scale), defined up to integers, so a periodic tile maps
// seamlessly wherever the field allows it.
//
// Per vertex i two unit complex numbers z_s = exp(2 pi i s_i), z_t =
// exp(2 pi i t_i), expressed in the vertex's own frame: the representative of
// its reference face (the first non-border face around halfedge(v)). Each
// face corner knows the quarter turns m between its face's representative and
// its vertex's (the edge matchings accumulated around the vertex), and one
// turn maps (s,t) -> (t,-s), i.e. z_s -> z_t, z_t -> conj(z_s): across a cut
// of the combed 4-field s on one side is t on the other, which independent
// s and t unknowns cannot represent (Ray et al. 2006 couple them the same
// way). The system is therefore real-linear, 4 reals per vertex. For each
// edge (i,j) with faces T, T':
//   alpha_ij = e_ij . (g^T + g^T') / 2            (in periods; the paper's
//              2 pi e.g is the same in radians),
// where g^T' is taken from the representative of T''s N-symmetric cross that
// best matches T's after transport across the edge (the paper says "there is no
// swapping of texture coordinates"; with a 4-field some swapping is
// unavoidable near singularities, and matching per edge keeps the local
// gradients consistent everywhere else). Equation (3) z_j = exp(2 pi i alpha_ij) z_i,
// written in T's frame (alpha_ij is), becomes x_j = P_mj R P_-mi x_i in the
// vertices' frames (x = (Re z_s, Im z_s, Re z_t, Im z_t), P_m the m turns, R
// the two rotations by alpha), solved in the least squares sense,
// F_PGP = sum (A_T + A_T') |x_j - P_mj R P_-mi x_i|^2: a sparse symmetric
// positive definite real form with 4x4 blocks (lower triangle assembled in a
// precomputed order; the free vertices ordered by METIS nested dissection of
// the vertex graph, their 4 unknowns together; CHOLMOD supernodal Cholesky
// keeping that order, ordering and symbolic analysis reused while the free
// set and the cut parities are unchanged). The connectivity-only work runs
// beside the field-dependent work on a second thread (the METIS order beside
// the gradients, alphas, edge maps and the start; the symbolic analysis
// beside the assembly; same bytes on any number of threads), and prepare()
// lets a caller start the order while the direction field is computed.
// CHOLMOD's dense kernels run on the BLAS libcholmod is linked with:
// Debian's default netlib BLAS is single-threaded (and slow: the
// factorisation dominates, about 1.8e9 flops at 52K triangles); an OpenBLAS
// is pinned to one thread so that the bytes do not depend on the machine's
// cores (its threaded build gives different
// bytes per thread count), and, where OpenBLAS 0.3.21 does not know the CPU
// and falls back to its generic SSE3 kernels, it is switched to its AVX-512
// (or AVX2) kernels once per process (PgpResult::blas_core names the set).
// Concurrent calls: Debian 12's serial OpenBLAS (libopenblas0-serial
// 0.3.21) is not safe for them (built without USE_LOCKING: its work-buffer
// table is claimed without a lock); its pthread build
// (libopenblas0-pthread, which scripts/setup.sh installs) is, and pinned to
// one thread it gives the serial build's bytes. Where the BLAS is not known
// to allow concurrent calls, the BLAS-reaching CHOLMOD calls (numeric
// factorisation, solves) of all solvers of the process take turns behind
// one lock: the no-swap s and t halves then run one after the other instead
// of side by side, and two solvers on two threads give the bytes each gives
// alone either way (PgpResult::concurrent_blas).
// The paper writes R with the opposite rotation sign and a 2 pi missing in
// the rounding of (4); we use the self-consistent signs.
//   - initialisation: the paper locks one vertex and minimises F. That
//     minimiser decays away from the locked vertex (median |z| ~ 3e-3 on
//     fandisk) and its phase stops following the field; F's smallest
//     eigenvector (RLL06) localises where the field's curl is low, its tail
//     not following the field either (81% distorted faces on a constant-scale
//     torus). We start from the alphas integrated along a breadth-first
//     spanning tree (exact on the tree, the holonomy piled where branches
//     meet) and relax with `init_iterations` Ginzburg-Landau steps
//       z <- argmin F(z) + mu sum_i M_i |z_i - u_i|^2,  u = z/|z| (previous),
//     mu = `stiffness` x (mean diagonal of F / mean vertex area), one
//     factorisation of F + mu M for all steps; the holonomy becomes a few
//     small vortices (the PGP singularities). One reference vertex per
//     component (`locked_vertex` for its component, the lowest index
//     otherwise) is locked at s = t = 0, as the paper does (with s and t
//     coupled a constant shift is no longer a symmetry to fix afterwards);
//   - local update: vertices outside the effect area's free set keep their z
//     (they enter the right-hand side); `update_iterations` relaxation steps
//     from the previous solution. Gradients, alphas and energies are
//     recomputed only next to the free faces (the mesh must not change
//     between calls, nor the maps outside the area).
// Corner coordinates (equation 4), in the face's own frame (each vertex's
// (s,t) turned by its corner's matching, the alphas of edges whose reference
// face is the neighbour turned by the edge's matching): in face T = (i,j,k)
// (i = target of halfedge(T)), s_i = Arg(z_i)/2pi, s_j = Arg(z_j)/2pi + p_j with the integer
// p_j = round(s_i + alpha_ij - Arg(z_j)/2pi), alpha_ij the edge's shared
// expected increase (as the paper writes it; an earlier version used T's own
// gradient, which let the two faces of an edge round differently and doubled
// the mismatched edges), same for k along (i,k). Two adjacent faces around which
// the jumps close agree exactly on their shared edge.
// The material m of a corner is the vertex material.
//
// With options.curl_correction (off by default) the face gradients g are first
// multiplied by the factor of pgp_curl_correction.h (Ray et al. 2006's curl
// correction): every use of g above (alphas, corners, energies,
// pgp_face_gradients, pgp_halfedge_alphas) sees the corrected target.
//
// Reads the face map direction_map (Vector3 d_s), the vertex maps scale_map
// (S > 0) and material_map (m); writes the halfedge map stm_map (STM, the
// corner of face(h) at target(h)); absent scale/material maps read as 1 / 0.
// After an update only corners of faces in the effect area are rewritten.
// Throws InvalidInputError (missing direction map, non-positive scale, bad
// options), SolverError (symbolic analysis/factorisation/solve failure).
// PgpResult::breakdown gives the wall time of each step (bench_pgp prints it).

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
  /// Curl correction of the target gradients before the solve (Ray et al.
  /// 2006; material_space/pgp_curl_correction.h): g = d/S scaled per vertex
  /// towards curl-free, directions kept. Off by default: Ray et al. 2009
  /// section 2.3 uses d/S as given, and the correction rescales the user's
  /// period locally and makes a local update refresh every face (decision 304).
  bool curl_correction = false;
  /// Swap s and t across the quarter-turn cuts of the combed N-field (Ray et
  /// al. 2006's coupling; the default). false = the paper's simplified PGP
  /// (Ray et al. 2009 section 2.3: "no swapping of texture coordinates"):
  /// s couples only with s and t only with t, two independent systems of a
  /// quarter of the factorisation's flops; the faces along the field's cuts
  /// become singular, which section 3's blending hides (decision 304).
  bool swap_coordinates = true;
  /// With swap_coordinates false only: solve the s and t systems each as the
  /// complex Hermitian n x n system of z_s (z_t) its real 2n x 2n form stands
  /// for (half the real flops; equal to the one-system result up to rounding,
  /// same bytes on any thread count), side by side where the BLAS allows
  /// concurrent calls. false (one real system) is kept for comparison.
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
  /// OpenBLAS kernel set behind CHOLMOD's dense kernels ("" for another
  /// BLAS; see the BLAS note above).
  std::string blas_core;
  /// The BLAS allows concurrent calls (OpenBLAS's pthread build), so two
  /// solvers on two threads, and the no-swap s and t halves, run side by
  /// side instead of taking turns (same bytes either way).
  bool concurrent_blas = false;
  /// Wall-time breakdown of `seconds` (each step's own wall time, seconds).
  /// Three pairs of steps run side by side (tbb::parallel_invoke), so the
  /// sum exceeds `seconds` on several threads: `ordering` beside `field`
  /// (gradients, alphas, matchings and, when every edge map is read, the
  /// edge maps) + `start`; `pattern` beside a local update's edge maps
  /// (counted in `field`); `analysis` beside `assembly`.
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

  /// Optional, ahead of initialize(): the work of the initialisation that
  /// depends on the connectivity only (topology, fill-reducing order of the
  /// free vertices, ~0.1 s at 52K triangles), for a caller to run while it
  /// computes the direction field (e.g. with tbb::parallel_invoke). It reads
  /// the mesh's connectivity and points and no property map, and adds none;
  /// the mesh must not change afterwards (else initialize() redoes it).
  /// initialize() gives the same bytes with or without it.
  void prepare();
  /// The same ahead of update(area): the order of the area's free vertices,
  /// for a caller to compute while it interpolates the orientation and scale
  /// in the area (update() then reuses it; same bytes).
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
