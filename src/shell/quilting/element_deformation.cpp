// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/element_deformation.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <cmath>
#include <string>

#include "geometry/errors.h"

namespace surftex {

std::vector<P3> laplacian_deform(const ElementMesh& m, const std::vector<DeformConstraint>& cons,
                                 const std::vector<char>& locked, const LaplacianDeformOptions& opt) {
  if (!(opt.mu > 0) || !std::isfinite(opt.mu))
    throw InvalidInputError("laplacian_deform: mu must be > 0 (" + std::to_string(opt.mu) + ")");
  const int n = static_cast<int>(m.points.size());
  if (!locked.empty() && static_cast<int>(locked.size()) != n)
    throw InvalidInputError("laplacian_deform: locked has " + std::to_string(locked.size()) +
                            " entries for " + std::to_string(n) + " vertices");
  for (const DeformConstraint& c : cons)
    for (int v : c.vertices)
      if (v < 0 || v >= n)
        throw InvalidInputError("laplacian_deform: constraint vertex " + std::to_string(v) + " out of range");
  bool any_locked = false;
  for (char l : locked) any_locked |= l != 0;
  if (cons.empty() && !any_locked) return m.points;

  // Column index of each free vertex.
  std::vector<int> col(n, -1);
  int nf = 0;
  for (int i = 0; i < n; ++i)
    if (locked.empty() || !locked[i]) col[i] = nf++;
  std::vector<P3> out = m.points;
  if (nf == 0) return out;

  // Rows: n Laplacian rows, then one row per constraint (scaled by sqrt(mu)).
  const auto nb = vertex_neighbours(m);
  const int rows = n + static_cast<int>(cons.size());
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(rows, 3);
  auto add = [&](int r, int v, double w) {
    if (col[v] >= 0)
      trip.emplace_back(r, col[v], w);
    else
      for (int d = 0; d < 3; ++d) rhs(r, d) -= w * m.points[v][d];
  };
  for (int i = 0; i < n; ++i) {
    const double k = nb[i].empty() ? 0.0 : 1.0 / static_cast<double>(nb[i].size());
    // Eq. 4 applied to the original positions: the target Laplacian coordinate.
    P3 delta = m.points[i];
    for (int j : nb[i])
      for (int d = 0; d < 3; ++d) delta[d] -= k * m.points[j][d];
    for (int d = 0; d < 3; ++d) rhs(i, d) += delta[d];
    add(i, i, 1.0);
    for (int j : nb[i]) add(i, j, -k);
  }
  const double s = std::sqrt(opt.mu);
  for (std::size_t c = 0; c < cons.size(); ++c) {
    const int r = n + static_cast<int>(c);
    for (int d = 0; d < 3; ++d) rhs(r, d) += s * cons[c].target[d];
    for (int k = 0; k < 3; ++k)
      if (cons[c].weights[k] != 0) add(r, cons[c].vertices[k], s * cons[c].weights[k]);
  }
  Eigen::SparseMatrix<double> A(rows, nf);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SparseMatrix<double> AtA = A.transpose() * A;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  solver.compute(AtA);  // factor once, solve for x, y, z
  if (solver.info() != Eigen::Success)
    throw SolverError("laplacian_deform: factorisation failed (" + std::to_string(n) + " vertices, " +
                      std::to_string(cons.size()) + " constraints)");
  Eigen::MatrixXd Atb = A.transpose() * rhs;
  Eigen::MatrixXd x = solver.solve(Atb);
  if (solver.info() != Eigen::Success || !x.allFinite())
    throw SolverError("laplacian_deform: solve failed (" + std::to_string(n) + " vertices)");
  // An undetermined component shows up as a zero pivot; LDLT then yields huge values.
  for (int i = 0; i < nf; ++i)
    if (std::abs(solver.vectorD()(i)) < 1e-14 * std::max(1.0, std::abs(solver.vectorD().maxCoeff())))
      throw SolverError("laplacian_deform: singular system (a component has no constraint)");
  for (int i = 0; i < n; ++i)
    if (col[i] >= 0) out[i] = {x(col[i], 0), x(col[i], 1), x(col[i], 2)};
  return out;
}

}  // namespace surftex
