// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Curl correction of the PGP's target gradients (Ray et al. 2006, "Periodic
// global parameterization", the curl correction applied to the input field
// before the periodic solve; used by the simplified PGP of Ray et al. 2009,
// section 2.3, through PgpOptions::curl_correction).
//
// The PGP asks for grad s = d_s / S, grad t = d_t / S, which is not curl-free
// in general; the misfit becomes vortices (section 3's singular zones). As we
// read the 2006 paper (from memory: it is not in ../shared/papers/), the
// correction rescales the vectors, keeping their directions: g' = exp(phi) g
// with one log-factor phi per vertex, grad phi ~ q + grad log S, q from the
// discrete curl of the unit frame (faces at field singularities keep only
// grad log S), phi from a screened Dirichlet problem (cotangent Laplacian +
// mu M, mu = stiffness / area; one sparse Cholesky) and clamped to
// [-log max_factor, log max_factor]. The derivation and the measured
// effects (singular faces, clamped vertices): docs/decisions/304-pgp-options.md.
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
/// options.curl_correction): per face, their circulation with the alphas'
/// matching, in periods (0 for a gradient). For diagnosis; removed faces {0, 0}.
std::vector<std::array<double, 2>> pgp_face_circulation(const Mesh& mesh, const PgpOptions& options);

}  // namespace surftex
