// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/scalar_field_interpolation.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

#include "geometry/effect_area.h"
#include "geometry/errors.h"
#include "geometry/properties.h"
#include "geometry/mesh_util.h"

namespace surftex {

ScalarFieldOptions material_field_options() {
  ScalarFieldOptions o;
  o.value_map = kVertexMaterial;
  o.min_value = 0;
  o.max_value = 1;
  o.default_value = 0;
  return o;
}

ScalarFieldOptions scale_field_options(double epsilon, double default_scale) {
  if (!(epsilon > 0))
    throw InvalidInputError("scale_field_options: epsilon must be > 0, got " + std::to_string(epsilon));
  ScalarFieldOptions o;
  o.value_map = kVertexScale;
  o.min_value = epsilon;
  o.default_value = std::max(default_scale, epsilon);
  return o;
}

ScalarFieldResult interpolate_scalar_field(Mesh& mesh, const std::vector<ScalarConstraint>& constraints,
                                           const ScalarFieldOptions& opt) {
  if (!(opt.min_value <= opt.max_value))
    throw InvalidInputError("interpolate_scalar_field: min_value > max_value");
  require_triangle_mesh(mesh, "interpolate_scalar_field");
  const std::size_t nv = mesh.num_vertices();
  if (opt.area && opt.area->vertex_free.size() != nv)
    throw InvalidInputError("interpolate_scalar_field: effect area does not match the mesh");
  auto val = get_or_add(mesh, opt.value_map, opt.default_value);
  auto is_free = [&](VertexIndex v) { return !opt.area || opt.area->vertex_free[v.idx()]; };

  std::vector<char> locked(nv, 0);
  std::vector<double> x(nv, 0.0);
  for (VertexIndex v : mesh.vertices())
    if (!is_free(v)) {
      locked[v.idx()] = 1;
      x[v.idx()] = val[v];
    }
  for (const ScalarConstraint& c : constraints) {
    if (c.vertex >= nv || mesh.is_removed(VertexIndex(c.vertex)))
      throw InvalidInputError("interpolate_scalar_field(" + std::string(opt.value_map.name) + "): constraint vertex " +
                              std::to_string(c.vertex) + " out of range (" + std::to_string(nv) +
                              " vertices)");
    if (!std::isfinite(c.value))
      throw InvalidInputError("interpolate_scalar_field(" + std::string(opt.value_map.name) +
                              "): non-finite value at vertex " + std::to_string(c.vertex));
    if (!is_free(VertexIndex(c.vertex))) continue;
    locked[c.vertex] = 1;
    x[c.vertex] = std::clamp(c.value, opt.min_value, opt.max_value);
  }

  // Free vertices connected (through free vertices) to a locked one.
  std::vector<int> var(nv, -1);
  std::vector<char> reach(nv, 0);
  std::deque<VertexIndex> queue;
  for (VertexIndex v : mesh.vertices())
    if (locked[v.idx()]) {
      reach[v.idx()] = 1;
      queue.push_back(v);
    }
  int n_var = 0;
  while (!queue.empty()) {
    const VertexIndex v = queue.front();
    queue.pop_front();
    if (mesh.halfedge(v) == Mesh::null_halfedge()) continue;
    for (VertexIndex w : CGAL::vertices_around_target(mesh.halfedge(v), mesh)) {
      if (reach[w.idx()]) continue;
      reach[w.idx()] = 1;
      var[w.idx()] = n_var++;
      queue.push_back(w);
    }
  }
  ScalarFieldResult res;
  // Cotangent weights per edge, clamped below.
  std::vector<double> weight(mesh.num_edges(), 0.0);
  double mean = 0;
  std::size_t count = 0;
  for (EdgeIndex e : mesh.edges()) {
    const HalfedgeIndex h = mesh.halfedge(e, 0);
    const double w = 0.5 * (cotan_opposite(mesh, h) + cotan_opposite(mesh, mesh.opposite(h)));
    weight[e.idx()] = w;
    if (w > 0) {
      mean += w;
      ++count;
    }
  }
  const double floor_w = 1e-6 * (count ? mean / count : 1.0);
  for (double& w : weight) w = std::max(w, floor_w);

  if (n_var > 0) {
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(static_cast<std::size_t>(n_var) * 7);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n_var);
    for (EdgeIndex e : mesh.edges()) {
      const HalfedgeIndex h = mesh.halfedge(e, 0);
      const std::size_t a = mesh.source(h).idx(), b = mesh.target(h).idx();
      const double w = weight[e.idx()];
      const int va = var[a], vb = var[b];
      if (va >= 0) trip.emplace_back(va, va, w);
      if (vb >= 0) trip.emplace_back(vb, vb, w);
      if (va >= 0 && vb >= 0) {
        trip.emplace_back(va, vb, -w);
        trip.emplace_back(vb, va, -w);
      } else if (va >= 0 && locked[b]) {
        rhs[va] += w * x[b];
      } else if (vb >= 0 && locked[a]) {
        rhs[vb] += w * x[a];
      }
    }
    Eigen::SparseMatrix<double> A(n_var, n_var);
    A.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
    if (solver.info() != Eigen::Success)
      throw SolverError("interpolate_scalar_field(" + std::string(opt.value_map.name) + "): factorisation failed");
    const Eigen::VectorXd sol = solver.solve(rhs);
    if (solver.info() != Eigen::Success)
      throw SolverError("interpolate_scalar_field(" + std::string(opt.value_map.name) + "): solve failed");
    for (VertexIndex v : mesh.vertices())
      if (var[v.idx()] >= 0) x[v.idx()] = sol[var[v.idx()]];
  }
  for (VertexIndex v : mesh.vertices()) {
    if (!is_free(v)) continue;  // bit for bit unchanged outside the area
    double value = x[v.idx()];
    if (!locked[v.idx()] && var[v.idx()] < 0) {
      value = opt.default_value;
      ++res.defaulted_vertices;
    }
    if (!std::isfinite(value)) value = opt.default_value;
    const double c = std::clamp(value, opt.min_value, opt.max_value);
    if (c != value) ++res.clamped_vertices;
    val[v] = c;
  }
  res.solved_vertices = static_cast<std::size_t>(n_var);
  return res;
}

}  // namespace surftex
