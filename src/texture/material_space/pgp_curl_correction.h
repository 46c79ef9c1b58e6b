// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Curl correction of the PGP's target gradients (Ray et al. 2006, "Periodic
// global parameterization", the curl correction applied to the input field
// before the periodic solve; used by the simplified PGP of Ray et al. 2009,
// section 2.3, through PgpOptions::curl_correction).
//
// Why. The PGP asks for (s,t) with grad s = g_s = d_s / S and grad t = g_t =
// d_t / S. A gradient is curl-free; the target is not in general (a curvature
// field on a curved surface, constant S): the PGP then cannot follow it and
// concentrates the misfit in vortices and T-junctions, the singular zones of
// section 3. The 2006 paper makes the target closer to curl-free before the
// solve; we read its correction as changing the norm of the vectors and
// keeping their directions (the user's orientation is the constraint that
// matters; the scale is relative). The 2006 paper is not in
// ../shared/papers/: this reading is from memory of it and from the 2009
// paper's summary, not checked against its text.
//
// What we do (the paper describes the idea, not a discretisation; these are
// our choices). Corrected target g' = exp(phi) g = exp(phi) d / S with one
// log-factor phi per vertex (piecewise linear; a face uses exp of its three
// vertices' mean). With d_s, d_t a unit orthonormal frame,
//   curl(lambda d) = lambda (grad log lambda x d + curl d),
// so (lambda d_s, lambda d_t) is curl-free iff grad log lambda = q with
//   q = -curl(d_t) d_s + curl(d_s) d_t
// (q does not change when the cross is relabelled by a quarter or half turn),
// and g' is curl-free iff grad phi = q + grad log S. q is computed per face T
// from the discrete curl of the unit frame: curl_T(d) = circulation of d
// around T / A_T, the circulation being the sum over T's edges e
// (counter-clockwise) of e . (d_T + d~_U) / 2, d~_U the neighbour's
// representative of the N-symmetric cross nearest to d_T after transport
// across e (the same matching as the PGP's alphas; d_T itself on a border
// edge); grad log S is the linear interpolant's. Faces with a vertex of
// nonzero field index (direction_field_singularities.h) keep only grad log S:
// the exact factor around a singularity of index k is a cone r^k, which would
// pile up scale change (and clamping) where the PGP makes a vortex anyway
// (measured: fandisk 7.7% -> 6.8% singular faces, armadillo_52k unchanged at
// 23.1%, clamped vertices 168 -> 99, with max_factor 4). Then phi minimises the screened
// Dirichlet problem
//   sum_T A_T |grad phi_T - (q_T + grad log S_T)|^2 + mu sum_i M_i phi_i^2,
//   mu = stiffness / (total area),
// (cotangent Laplacian plus lumped mass, one sparse Cholesky; the mass term
// fixes the free constant and pulls the factor towards 1, i.e. towards the
// user's scale: variations of the user's S over distances longer than the
// screening length sqrt(area / stiffness) are kept, shorter ones are traded
// for integrability like the field's own curl). A scale that already makes
// g curl-free (S proportional to the distance from the axis on a torus with
// a parallels field) gives phi ~ 0. The part of q that is not a gradient
// (Gaussian curvature, field singularities) cannot be removed this way and
// is left to the PGP. phi is finally clamped to [-log max_factor,
// log max_factor]: strongly curved places (the armadillo's fingers and head)
// ask for large factors, and the clamp bounds how far the period departs from
// the user's (measured at 8 mean edges per period, max_factor 4 -> 2:
// armadillo_52k 23.1% -> 24.0% singular faces with factors 0.32..4 -> 0.5..2,
// dragon_25k 54.0% -> 54.3%, fandisk unchanged at 6.8%). The rescaling is
// visible: on the armadillo the checks of a checker tile are about twice as
// large on the thighs as on the forearms (`surftex material-map`, renders).
//
// Units: phi is dimensionless (the factor multiplies g, in periods per mesh
// unit); q is in 1/mesh units; curl in 1/mesh units^2.
//
// Reads the face map `direction_map` (Vector3 d_s) and the vertex map
// `scale_map` (S > 0; absent = 1). Writes nothing on the mesh. Throws
// InvalidInputError (direction map absent, S <= 0, options out of range),
// SolverError (factorisation or solve failure).

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "texture/material_space/periodic_global_parameterization.h"

namespace surftex {

struct PgpCurlCorrectionOptions {
  int symmetry = 4;  ///< symmetry N of the field (1, 2 or 4)
  /// Weight of the pull of phi towards 0 (> 0), relative to the mesh's total
  /// area: 1 lets the factor vary over the whole mesh, larger values keep it
  /// closer to 1 (screening length ~ sqrt(area / stiffness)).
  double stiffness = 1.0;
  /// The factor exp(phi) is clamped to [1/max_factor, max_factor] (>= 1).
  double max_factor = 2.0;
  PropertyName<FaceIndex, Vector3> direction_map = kFaceDirection;
  PropertyName<VertexIndex, double> scale_map = kVertexScale;  ///< S per vertex (absent: 1)
};

struct PgpCurlCorrection {
  std::vector<double> log_factor;         ///< phi per vertex index (0 for isolated vertices)
  std::vector<double> face_factor;        ///< exp(mean phi of its vertices) per face index
  double min_factor = 1, max_factor = 1;  ///< over the faces
  std::size_t clamped_vertices = 0;       ///< vertices whose phi hit the clamp
};

/// Stateful (geometry-central style): keeps the factorisation of the screened
/// Laplacian, which depends only on the mesh geometry and the stiffness, so
/// repeated corrections of a changing field (local updates) cost one solve.
/// The mesh must not change between calls (sizes are checked, positions are not).
class PgpCurlCorrector {
 public:
  explicit PgpCurlCorrector(PgpCurlCorrectionOptions options = {});
  ~PgpCurlCorrector();
  PgpCurlCorrector(const PgpCurlCorrector&) = delete;
  PgpCurlCorrector& operator=(const PgpCurlCorrector&) = delete;

  PgpCurlCorrection compute(const Mesh& mesh);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-shot.
PgpCurlCorrection pgp_curl_correction(const Mesh& mesh, const PgpCurlCorrectionOptions& options = {});

/// Discrete curl of the PGP's target gradients (corrected if
/// options.curl_correction): per face index the circulation of (g_s, g_t)
/// around the face, sum over its edges of e . (g_T + g~_U) / 2 with the same
/// matching as the PGP's alphas, in periods (it is the misfit that the three
/// edge equations (3) of the face cannot satisfy; 0 for a gradient field).
/// For a diagnosis (bench_pgp, tests); removed faces give {0, 0}.
std::vector<std::array<double, 2>> pgp_face_circulation(const Mesh& mesh, const PgpOptions& options);

}  // namespace surftex
