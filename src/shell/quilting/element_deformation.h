// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Laplacian deformation of one element (Zhou et al. 2006, section 2.6,
// equations 4-6, after Yu et al. 2004 / Sorkine et al. 2004): new positions w
// minimising
//   sum_i |L(w_i) - L(v_i)|^2 + mu * sum_k |sum_j beta_kj w_kj - c_k|^2
// with L the uniform ("umbrella") Laplacian of eq. 4, L(v) = v - mean of the
// 1-ring. A constraint is a point of the element given by barycentric weights
// on up to three vertices (eq. 6: a point of a face; eq. 5: one vertex, weight
// 1) and its target c_k. The original Laplacian coordinates are kept (not
// rotated), as the paper does for small deformations.
// Locked vertices keep their positions exactly (ours: the part of an output
// element outside the overlap stays, else the element drifts with the seam).
// One SimplicialLDLT factorisation, solved for x, y and z.
// Throws InvalidInputError (vertex index out of range, mu <= 0), SolverError
// (factorisation failure, e.g. no constraint and no locked vertex touches a
// component: that component's translation is undetermined).
#include <array>
#include <vector>

#include "shell/element_mesh.h"

namespace surftex {

struct DeformConstraint {
  std::array<int, 3> vertices{0, 0, 0};
  std::array<double, 3> weights{1, 0, 0};  ///< barycentric weights (sum to 1)
  P3 target{0, 0, 0};                      ///< c_k
};

struct LaplacianDeformOptions {
  double mu = 1.0;  ///< weight of the position constraints (paper: 1), > 0
};

/// Returns the new positions of all vertices of `m` (same order). With no
/// constraint and no locked vertex, returns the positions unchanged.
std::vector<P3> laplacian_deform(const ElementMesh& m, const std::vector<DeformConstraint>& constraints,
                                 const std::vector<char>& locked, const LaplacianDeformOptions& opt = {});

}  // namespace surftex
