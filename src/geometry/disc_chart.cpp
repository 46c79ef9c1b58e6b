// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/disc_chart.h"

#ifndef CGAL_EIGEN3_ENABLED
#define CGAL_EIGEN3_ENABLED  // LSCM's default solver is the Eigen one
#endif

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <unordered_map>

#include "geometry/mesh.h"

namespace surftex {
namespace {
namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMP = CGAL::Surface_mesh_parameterization;

double signed_area(const std::array<double, 2>& a, const std::array<double, 2>& b, const std::array<double, 2>& c) {
  return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

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

DiscChartFlattening flatten_disc_chart(const Mesh& mesh, const std::vector<int>& face_indices) {
  DiscChartFlattening out;
  auto fail = [&](DiscChartFlattening::Status s, const std::string& why) {
    out.status = s;
    out.error = why;
    return out;
  };
  std::vector<FaceIndex> faces;
  for (int f : face_indices) faces.push_back(FaceIndex(static_cast<Mesh::size_type>(f)));
  Mesh sub;
  std::vector<int> local(mesh.num_vertices(), -1);
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
  auto uvmap = sub.add_property_map<VertexIndex, Point2>("v:disc_uv", Point2(0, 0)).first;
  const SMP::Error_code err = SMP::parameterize(sub, SMP::LSCM_parameterizer_3<Mesh>(), borders.front(), uvmap);
  if (err != SMP::OK) return fail(DiscChartFlattening::Status::kSolver, std::string("LSCM failed: ") + SMP::get_error_message(err));
  out.uv.resize(out.vertices.size());
  for (VertexIndex v : sub.vertices()) {
    const Point2& p = uvmap[v];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) return fail(DiscChartFlattening::Status::kSolver, "LSCM gave a non-finite uv");
    out.uv[v.idx()] = {p.x(), p.y()};
  }
  double auv = 0;
  for (FaceIndex f : sub.faces()) {
    const HalfedgeIndex h = sub.halfedge(f);
    auv += signed_area(out.uv[sub.source(h).idx()], out.uv[sub.target(h).idx()], out.uv[sub.target(sub.next(h)).idx()]);
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
    const double a2 = signed_area(a, b, c);
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

}  // namespace surftex
