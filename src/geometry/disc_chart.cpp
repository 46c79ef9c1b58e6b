// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/disc_chart.h"

#ifndef CGAL_EIGEN3_ENABLED
#define CGAL_EIGEN3_ENABLED  // LSCM's default solver is the Eigen one
#endif

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>
#include <complex>
#include <deque>
#include <unordered_map>

#include "geometry/mesh.h"

namespace surftex {

double uv_signed_area(const std::array<double, 2>& a, const std::array<double, 2>& b,
                      const std::array<double, 2>& c) {
  return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMP = CGAL::Surface_mesh_parameterization;


Point2 pt(const std::array<double, 2>& p) {
  return Point2(p[0], p[1]);
}

// Pairs of edges of the closed polyline `loop` that touch or cross (exact
// predicates); consecutive edges count only when they fold back onto each
// other. Candidate pairs come from a uniform grid over the loop's box.
std::size_t border_crossings(const std::vector<std::array<double, 2>>& loop) {
  const std::size_t n = loop.size();
  std::size_t count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2 a = pt(loop[i]), b = pt(loop[(i + 1) % n]), c = pt(loop[(i + 2) % n]);
    if (CGAL::orientation(a, b, c) == CGAL::COLLINEAR && (b - a) * (c - b) < 0) ++count;
  }
  if (n < 4) return count;
  double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL, len = 0;
  for (std::size_t i = 0; i < n; ++i) {
    x0 = std::min(x0, loop[i][0]), x1 = std::max(x1, loop[i][0]), y0 = std::min(y0, loop[i][1]),
    y1 = std::max(y1, loop[i][1]);
    len += std::hypot(loop[(i + 1) % n][0] - loop[i][0], loop[(i + 1) % n][1] - loop[i][1]);
  }
  const double cell = std::max({len / static_cast<double>(n), (x1 - x0) / 1024, (y1 - y0) / 1024, 1e-300});
  std::unordered_map<long long, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = loop[i];
    const auto& q = loop[(i + 1) % n];
    const long long i0 = static_cast<long long>((std::min(p[0], q[0]) - x0) / cell),
                    i1 = static_cast<long long>((std::max(p[0], q[0]) - x0) / cell);
    const long long j0 = static_cast<long long>((std::min(p[1], q[1]) - y0) / cell),
                    j1 = static_cast<long long>((std::max(p[1], q[1]) - y0) / cell);
    for (long long j = j0; j <= j1; ++j)
      for (long long k = i0; k <= i1; ++k) grid[j * 2048 + k].push_back(i);
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const auto& [key, edges] : grid)
    for (std::size_t a = 0; a < edges.size(); ++a)
      for (std::size_t b = a + 1; b < edges.size(); ++b) {
        const std::size_t i = std::min(edges[a], edges[b]), j = std::max(edges[a], edges[b]);
        if (j == i + 1 || (i == 0 && j == n - 1)) continue;  // consecutive: share a vertex
        const Kernel::Segment_2 s(pt(loop[i]), pt(loop[(i + 1) % n])), t(pt(loop[j]), pt(loop[(j + 1) % n]));
        if (CGAL::do_intersect(s, t)) pairs.emplace_back(i, j);
      }
  std::sort(pairs.begin(), pairs.end());
  return count + static_cast<std::size_t>(std::unique(pairs.begin(), pairs.end()) - pairs.begin());
}
// The two vertices LSCM pins and their uvs, as CGAL's
// Two_vertices_parameterizer_3 picks them: extreme along the bounding box's
// longest axis (ties: the second longest), at their normalised coordinates
// on those two axes. False when the chart has no extent.
bool pinned_vertices(const Mesh& sub, std::array<int, 2>& pin, std::array<std::array<double, 2>, 2>& uv) {
  std::array<double, 3> lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (VertexIndex v : sub.vertices())
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], sub.point(v)[k]), hi[k] = std::max(hi[k], sub.point(v)[k]);
  const double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
  int first, second;  // CGAL's branches, ties included
  if (dx < dy && dx < dz) first = dy > dz ? 1 : 2, second = dy > dz ? 2 : 1;
  else if (dy < dx && dy < dz) first = dx > dz ? 0 : 2, second = dx > dz ? 2 : 0;
  else first = dx > dy ? 0 : 1, second = dx > dy ? 1 : 0;
  if (!(hi[first] > lo[first]) || !(hi[second] > lo[second])) return false;
  double umin = HUGE_VAL, vmin = HUGE_VAL, umax = -HUGE_VAL, vmax = -HUGE_VAL;
  for (VertexIndex v : sub.vertices()) {
    const double u = (sub.point(v)[first] - lo[first]) / (hi[first] - lo[first]);
    const double w = (sub.point(v)[second] - lo[second]) / (hi[second] - lo[second]);
    if (u < umin || (u == umin && w < vmin)) pin[0] = static_cast<int>(v.idx()), umin = u, vmin = w;
    if (u > umax || (u == umax && w > vmax)) pin[1] = static_cast<int>(v.idx()), umax = u, vmax = w;
  }
  uv = {{{umin, vmin}, {umax, vmax}}};
  return pin[0] != pin[1];
}

// Least-squares conformal map of the triangle chart `sub` (Levy et al.
// 2002) with two pinned vertices: CGAL's LSCM_parameterizer_3 energy (per
// face |(Z1 - Z0)(U2 - U0) - (Z2 - Z0)(U1 - U0)|^2 in the face's local
// frame, U = u + i v), its normal equations in complex form (one Hermitian
// unknown per vertex, a quarter of the real system's entries) factored by
// Eigen's SimplicialLDLT. About 3x faster than CGAL's path (OpenNL rows,
// hash sets, the real 2n x 2n system; decision 210). Empty on failure.
std::vector<std::array<double, 2>> lscm(const Mesh& sub) {
  using C = std::complex<double>;
  const int n = static_cast<int>(sub.number_of_vertices());
  std::array<int, 2> pin{};
  std::array<std::array<double, 2>, 2> pin_uv{};
  if (!pinned_vertices(sub, pin, pin_uv)) return {};
  std::vector<int> free_index(static_cast<std::size_t>(n));  // -1 = pinned
  int m = 0;
  for (int v = 0; v < n; ++v) free_index[v] = v == pin[0] || v == pin[1] ? -1 : m++;
  auto fixed = [&](int v) { return v == pin[0] ? C(pin_uv[0][0], pin_uv[0][1]) : C(pin_uv[1][0], pin_uv[1][1]); };
  std::vector<Eigen::Triplet<C>> hh;
  hh.reserve(sub.number_of_faces() * 6);
  Eigen::VectorXcd rhs = Eigen::VectorXcd::Zero(m);
  for (FaceIndex f : sub.faces()) {
    const HalfedgeIndex h0 = sub.halfedge(f), h1 = sub.next(h0);
    const std::array<int, 3> id{static_cast<int>(sub.target(h0).idx()), static_cast<int>(sub.target(h1).idx()),
                                static_cast<int>(sub.target(sub.next(h1)).idx())};
    // The triangle in its own plane: p0 at the origin, p1 on the x axis.
    const Point3 &p0 = sub.point(sub.target(h0)), &p1 = sub.point(sub.target(h1)),
                 &p2 = sub.point(sub.target(sub.next(h1)));
    Vector3 X = p1 - p0;
    const double xn = std::sqrt(X * X);
    if (xn != 0.0) X = X / xn;
    Vector3 Z = CGAL::cross_product(X, p2 - p0);
    const double zn = std::sqrt(Z * Z);
    if (zn != 0.0) Z = Z / zn;
    const Vector3 Y = CGAL::cross_product(Z, X);
    const double a = std::sqrt((p1 - p0) * (p1 - p0)), c = (p2 - p0) * X, d = (p2 - p0) * Y;
    // The face's residual: w0 U0 + w1 U1 + w2 U2.
    const std::array<C, 3> w{C(c - a, d), C(-c, -d), C(a, 0)};
    C locked = 0;
    for (int k = 0; k < 3; ++k)
      if (free_index[id[k]] < 0) locked += w[k] * fixed(id[k]);
    for (int i = 0; i < 3; ++i) {
      const int fi = free_index[id[i]];
      if (fi < 0) continue;
      rhs[fi] -= std::conj(w[i]) * locked;
      for (int j = 0; j < 3; ++j) {
        const int fj = free_index[id[j]];
        if (fj >= 0 && fj <= fi) hh.emplace_back(fi, fj, std::conj(w[i]) * w[j]);  // lower triangle
      }
    }
  }
  Eigen::SparseMatrix<C> H(m, m);
  H.setFromTriplets(hh.begin(), hh.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<C>, Eigen::Lower> ldlt(H);
  if (ldlt.info() != Eigen::Success) return {};
  const Eigen::VectorXcd x = ldlt.solve(rhs);
  if (ldlt.info() != Eigen::Success) return {};
  std::vector<std::array<double, 2>> uv(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) {
    const C z = free_index[v] < 0 ? fixed(v) : x[free_index[v]];
    uv[v] = {z.real(), z.imag()};
  }
  return uv;
}

// CGAL's LSCM_parameterizer_3 on `sub` from its border halfedge `border`.
// Empty on failure, with `error` set.
std::vector<std::array<double, 2>> cgal_lscm(Mesh& sub, HalfedgeIndex border, std::string& error) {
  auto uvmap = sub.add_property_map<VertexIndex, Point2>("v:disc_uv", Point2(0, 0)).first;
  const SMP::Error_code err = SMP::parameterize(sub, SMP::LSCM_parameterizer_3<Mesh>(), border, uvmap);
  if (err != SMP::OK) {
    error = std::string("LSCM failed: ") + SMP::get_error_message(err);
    return {};
  }
  std::vector<std::array<double, 2>> uv(sub.number_of_vertices());
  for (VertexIndex v : sub.vertices()) uv[v.idx()] = {uvmap[v].x(), uvmap[v].y()};
  return uv;
}
}  // namespace

DiscGrowthState::DiscGrowthState(const Mesh& mesh) : face(mesh.num_faces(), -1), vertex(mesh.num_vertices(), -1) {}

std::vector<int> grow_disc_chart(const Mesh& mesh, int seed_index, const std::function<bool(int)>& accept,
                                 std::size_t max_faces, DiscGrowthState& st) {
  const int id = st.next_id++;
  const FaceIndex seed(static_cast<Mesh::size_type>(seed_index));
  std::vector<int> chart;
  std::deque<FaceIndex> queue;
  auto add = [&](FaceIndex f) {
    st.face[f.idx()] = id;
    chart.push_back(static_cast<int>(f.idx()));
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      st.vertex[mesh.target(h).idx()] = id;
      const FaceIndex g = mesh.face(mesh.opposite(h));
      if (g != Mesh::null_face() && st.face[g.idx()] != id) queue.push_back(g);
    }
  };
  add(seed);
  while (!queue.empty() && chart.size() < max_faces) {
    const FaceIndex f = queue.front();
    queue.pop_front();
    if (st.face[f.idx()] == id || !accept(static_cast<int>(f.idx()))) continue;
    int shared = 0;
    VertexIndex apex;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      const FaceIndex g = mesh.face(mesh.opposite(h));
      if (g != Mesh::null_face() && st.face[g.idx()] == id) {
        ++shared;
        apex = mesh.target(mesh.next(h));
      }
    }
    if (shared == 2 || (shared == 1 && st.vertex[apex.idx()] != id)) add(f);
  }
  return chart;
}

namespace {
// flatten_disc_chart with `local` (mesh vertex -> chart vertex) all -1 on
// entry; on return it is -1 except at the result's `vertices`.
DiscChartFlattening flatten_with_map(const Mesh& mesh, const std::vector<int>& face_indices, LscmSolver solver,
                                     std::vector<int>& local) {
  DiscChartFlattening out;
  auto fail = [&](DiscChartFlattening::Status s, const std::string& why) {
    out.status = s;
    out.error = why;
    return out;
  };
  std::vector<FaceIndex> faces;
  for (int f : face_indices) faces.push_back(FaceIndex(static_cast<Mesh::size_type>(f)));
  Mesh sub;
  for (FaceIndex f : faces)
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f)))
      if (local[v.idx()] < 0) {
        local[v.idx()] = static_cast<int>(out.vertices.size());
        out.vertices.push_back(static_cast<int>(v.idx()));
        sub.add_vertex(mesh.point(v));
      }
  for (FaceIndex f : faces) {
    std::vector<VertexIndex> vs;
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f)))
      vs.push_back(VertexIndex(static_cast<Mesh::size_type>(local[v.idx()])));
    if (sub.add_face(vs) == Mesh::null_face()) return fail(DiscChartFlattening::Status::kTopology, "the chart is not a manifold surface");
    const HalfedgeIndex h = mesh.halfedge(f);
    out.area3d += std::sqrt(CGAL::squared_area(mesh.point(mesh.target(h)), mesh.point(mesh.target(mesh.next(h))),
                                               mesh.point(mesh.source(h))));
  }
  std::vector<HalfedgeIndex> borders;
  PMP::extract_boundary_cycles(sub, std::back_inserter(borders));
  const long chi = static_cast<long>(sub.number_of_vertices()) - static_cast<long>(sub.number_of_edges()) +
                   static_cast<long>(sub.number_of_faces());
  if (chi != 1 || borders.size() != 1)
    return fail(DiscChartFlattening::Status::kTopology, "the chart is not a disc (Euler " + std::to_string(chi) + ", " +
                                                            std::to_string(borders.size()) + " border loops)");
  std::string error = "LSCM failed (no extent, or the solve failed)";
  out.uv = solver == LscmSolver::kCgal ? cgal_lscm(sub, borders.front(), error) : lscm(sub);
  if (out.uv.empty()) return fail(DiscChartFlattening::Status::kSolver, error);
  for (const auto& p : out.uv)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1])) return fail(DiscChartFlattening::Status::kSolver, "LSCM gave a non-finite uv");
  double auv = 0;
  for (FaceIndex f : sub.faces()) {
    const HalfedgeIndex h = sub.halfedge(f);
    auv += uv_signed_area(out.uv[sub.source(h).idx()], out.uv[sub.target(h).idx()], out.uv[sub.target(sub.next(h)).idx()]);
  }
  if (!(std::abs(auv) > 0)) return fail(DiscChartFlattening::Status::kSolver, "LSCM gave a zero-area chart");
  if (auv < 0)
    for (auto& p : out.uv) p[0] = -p[0];
  const double s = std::sqrt(out.area3d / std::abs(auv));
  for (auto& p : out.uv) p = {p[0] * s, p[1] * s};
  double weighted = 0;
  for (FaceIndex f : sub.faces()) {
    const HalfedgeIndex h = sub.halfedge(f);
    const auto &a = out.uv[sub.source(h).idx()], &b = out.uv[sub.target(h).idx()],
               &c = out.uv[sub.target(sub.next(h)).idx()];
    if (CGAL::orientation(pt(a), pt(b), pt(c)) != CGAL::LEFT_TURN) ++out.flipped_faces;
    const double a2 = uv_signed_area(a, b, c);
    const double a3 = std::sqrt(CGAL::squared_area(sub.point(sub.source(h)), sub.point(sub.target(h)),
                                                   sub.point(sub.target(sub.next(h)))));
    if (a2 > 0 && a3 > 0) weighted += a3 * std::max(a3 / a2, a2 / a3);
  }
  out.area_distortion = out.area3d > 0 ? weighted / out.area3d : 0;
  // The border loop in the faces' orientation (opposite of the border halfedges').
  std::vector<std::array<double, 2>> loop;
  for (HalfedgeIndex h : CGAL::halfedges_around_face(borders.front(), sub))
    loop.push_back(out.uv[sub.target(h).idx()]);
  out.border_crossings = border_crossings(loop);
  return out;
}
}  // namespace

DiscChartFlattening flatten_disc_chart(const Mesh& mesh, const std::vector<int>& face_indices, LscmSolver solver) {
  // One map per thread, reset after each chart: a fresh one per chart wrote
  // the whole mesh's vertex count (1.5 MB on subdivided cow) for each of
  // the atlas's flattenings (over 1,400 there), however small the chart.
  thread_local std::vector<int> local;
  if (local.size() < mesh.num_vertices()) local.resize(mesh.num_vertices(), -1);
  DiscChartFlattening out;
  try {
    out = flatten_with_map(mesh, face_indices, solver, local);
  } catch (...) {
    local.clear();
    throw;
  }
  for (int v : out.vertices) local[static_cast<std::size_t>(v)] = -1;
  return out;
}

}  // namespace surftex
