// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/base_mesh_atlas.h"

#ifndef CGAL_EIGEN3_ENABLED
#define CGAL_EIGEN3_ENABLED  // LSCM's default solver is the Eigen one
#endif

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <string>

#include "geometry/errors.h"
#include "geometry/properties.h"

namespace surftex {

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMP = CGAL::Surface_mesh_parameterization;
constexpr double kPi = 3.14159265358979323846;

struct Chart {
  std::vector<FaceIndex> faces;
  std::vector<VertexIndex> vertices;   // chart-local vertex -> base vertex
  std::vector<std::array<double, 2>> uv;  // per chart-local vertex
  double min_u = 0, min_v = 0, w = 0, h = 0;  // bounding box after normalisation
  double area3d = 0;
};

// Greedy region growing into disc charts (see header, step 1).
std::vector<int> grow_charts(const Mesh& mesh, const BaseMeshAtlasOptions& opt, int& num_charts) {
  const double cos_max = std::cos(opt.max_normal_angle_deg * kPi / 180.0);
  std::vector<Vector3> normal(mesh.num_faces());
  for (FaceIndex f : mesh.faces()) {
    Vector3 n = PMP::compute_face_normal(f, mesh);
    normal[f.idx()] = n;
  }
  std::vector<int> chart_of(mesh.num_faces(), -1);
  std::vector<int> vertex_stamp(mesh.num_vertices(), -1);  // last chart touching the vertex
  num_charts = 0;
  for (FaceIndex seed : mesh.faces()) {
    if (chart_of[seed.idx()] != -1) continue;
    const int c = num_charts++;
    const Vector3 n0 = normal[seed.idx()];
    std::size_t size = 0;
    auto add = [&](FaceIndex f, std::deque<FaceIndex>& q) {
      chart_of[f.idx()] = c;
      ++size;
      for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
        vertex_stamp[mesh.target(h).idx()] = c;
        FaceIndex g = mesh.face(mesh.opposite(h));
        if (g != Mesh::null_face() && chart_of[g.idx()] == -1) q.push_back(g);
      }
    };
    std::deque<FaceIndex> queue;
    add(seed, queue);
    while (!queue.empty() && size < opt.max_chart_faces) {
      FaceIndex f = queue.front();
      queue.pop_front();
      if (chart_of[f.idx()] != -1) continue;
      if (normal[f.idx()] * n0 < cos_max) continue;
      int shared = 0;
      VertexIndex opposite_vertex;
      for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
        FaceIndex g = mesh.face(mesh.opposite(h));
        if (g != Mesh::null_face() && chart_of[g.idx()] == c) {
          ++shared;
          opposite_vertex = mesh.target(mesh.next(h));
        }
      }
      // Disc invariant: one shared edge with a new apex, or two shared edges.
      bool ok = (shared == 2) || (shared == 1 && vertex_stamp[opposite_vertex.idx()] != c);
      if (ok) add(f, queue);
    }
  }
  return chart_of;
}

// Rotation of the chart uvs that minimises the bounding-box area (16 angles).
void rotate_to_small_box(Chart& ch) {
  double best_area = std::numeric_limits<double>::infinity(), best_angle = 0;
  for (int k = 0; k < 16; ++k) {
    const double a = k * (kPi / 2) / 16, c = std::cos(a), s = std::sin(a);
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (auto& p : ch.uv) {
      const double x = c * p[0] - s * p[1], y = s * p[0] + c * p[1];
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    const double area = (x1 - x0) * (y1 - y0);
    if (area < best_area - 1e-12 * std::abs(best_area)) best_area = area, best_angle = a;
  }
  const double c = std::cos(best_angle), s = std::sin(best_angle);
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (auto& p : ch.uv) {
    const double x = c * p[0] - s * p[1], y = s * p[0] + c * p[1];
    p = {x, y};
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  ch.min_u = x0, ch.min_v = y0, ch.w = x1 - x0, ch.h = y1 - y0;
}

double signed_area(const std::array<double, 2>& a, const std::array<double, 2>& b,
                   const std::array<double, 2>& c) {
  return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}

// Copies the chart into its own mesh, checks it is a disc, flattens it with LSCM.
void flatten_chart(const Mesh& mesh, Chart& ch, int chart_id, std::vector<int>& local) {
  Mesh sub;
  for (FaceIndex f : ch.faces) {
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
      if (local[v.idx()] < 0) {
        local[v.idx()] = static_cast<int>(ch.vertices.size());
        ch.vertices.push_back(v);
        sub.add_vertex(mesh.point(v));
      }
    }
  }
  for (FaceIndex f : ch.faces) {
    std::vector<VertexIndex> vs;
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f)))
      vs.push_back(VertexIndex(static_cast<Mesh::size_type>(local[v.idx()])));
    if (sub.add_face(vs) == Mesh::null_face())
      throw TopologyError("base mesh atlas: chart " + std::to_string(chart_id) +
                          " is not a manifold surface (non-manifold base mesh?)");
    ch.area3d += std::sqrt(CGAL::squared_area(mesh.point(mesh.target(mesh.halfedge(f))),
                                              mesh.point(mesh.target(mesh.next(mesh.halfedge(f)))),
                                              mesh.point(mesh.source(mesh.halfedge(f)))));
  }
  // Disc check: Euler characteristic 1 and one border loop.
  std::vector<HalfedgeIndex> borders;
  PMP::extract_boundary_cycles(sub, std::back_inserter(borders));
  const long chi = static_cast<long>(sub.number_of_vertices()) - static_cast<long>(sub.number_of_edges()) +
                   static_cast<long>(sub.number_of_faces());
  if (chi != 1 || borders.size() != 1)
    throw TopologyError("base mesh atlas: chart " + std::to_string(chart_id) + " is not a disc (Euler " +
                        std::to_string(chi) + ", " + std::to_string(borders.size()) + " border loops)");

  auto uvmap = sub.add_property_map<VertexIndex, Point2>("v:lscm_uv", Point2(0, 0)).first;
  using Parameterizer = SMP::LSCM_parameterizer_3<Mesh>;
  SMP::Error_code err = SMP::parameterize(sub, Parameterizer(), borders.front(), uvmap);
  if (err != SMP::OK)
    throw SolverError("base mesh atlas: LSCM failed on chart " + std::to_string(chart_id) + " (" +
                      std::to_string(sub.number_of_faces()) + " faces): " + SMP::get_error_message(err));
  ch.uv.resize(ch.vertices.size());
  for (VertexIndex v : sub.vertices()) {
    const Point2& p = uvmap[v];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
      throw SolverError("base mesh atlas: LSCM gave non-finite uv on chart " + std::to_string(chart_id));
    ch.uv[v.idx()] = {p.x(), p.y()};
  }
  // Orientation and scale: total signed uv area positive and equal to the 3D area.
  double auv = 0;
  for (FaceIndex f : sub.faces()) {
    HalfedgeIndex h = sub.halfedge(f);
    auv += signed_area(ch.uv[sub.source(h).idx()], ch.uv[sub.target(h).idx()],
                       ch.uv[sub.target(sub.next(h)).idx()]);
  }
  if (auv < 0)
    for (auto& p : ch.uv) p[0] = -p[0];
  if (!(std::abs(auv) > 0))
    throw SolverError("base mesh atlas: LSCM gave a degenerate (zero-area) chart " + std::to_string(chart_id));
  const double s = std::sqrt(ch.area3d / std::abs(auv));
  for (auto& p : ch.uv) p = {p[0] * s, p[1] * s};
  rotate_to_small_box(ch);
  for (VertexIndex v : ch.vertices) local[v.idx()] = -1;
}
}  // namespace

BaseMeshAtlasResult compute_base_mesh_atlas(Mesh& mesh, const BaseMeshAtlasOptions& opt) {
  if (!(opt.max_normal_angle_deg > 0 && opt.max_normal_angle_deg <= 180))
    throw InvalidInputError("base mesh atlas: max_normal_angle_deg must be in (0,180], got " +
                            std::to_string(opt.max_normal_angle_deg));
  if (opt.max_chart_faces < 1) throw InvalidInputError("base mesh atlas: max_chart_faces must be >= 1");
  if (!(opt.margin >= 0 && opt.margin < 0.1))
    throw InvalidInputError("base mesh atlas: margin must be in [0,0.1), got " + std::to_string(opt.margin));
  if (mesh.number_of_faces() == 0) throw InvalidInputError("base mesh atlas: mesh has no faces");
  if (mesh.has_garbage())
    throw InvalidInputError("base mesh atlas: mesh has removed elements; call collect_garbage() first");
  for (FaceIndex f : mesh.faces())
    if (mesh.degree(f) != 3)
      throw InvalidInputError("base mesh atlas: face " + std::to_string(f.idx()) + " is not a triangle");

  BaseMeshAtlasResult res;
  std::vector<int> chart_of = grow_charts(mesh, opt, res.num_charts);
  std::vector<Chart> charts(res.num_charts);
  for (FaceIndex f : mesh.faces()) charts[chart_of[f.idx()]].faces.push_back(f);

  std::vector<int> local(mesh.num_vertices(), -1);
  for (int c = 0; c < res.num_charts; ++c) flatten_chart(mesh, charts[c], c, local);

  // Shelf packing (see header, step 3), in 3D length units.
  double box_area = 0, max_w = 0;
  for (auto& ch : charts) box_area += ch.w * ch.h, max_w = std::max(max_w, ch.w);
  const double side_est = std::sqrt(box_area) * 1.15;
  const double gap = opt.margin * side_est;
  const double strip = std::max(side_est, max_w + 2 * gap);
  std::vector<int> order(res.num_charts);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return charts[a].h > charts[b].h; });
  std::vector<std::array<double, 2>> offset(res.num_charts);
  double x = gap, y = gap, shelf_h = 0, used_w = 0;
  for (int c : order) {
    if (x + charts[c].w + gap > strip && x > gap) y += shelf_h + gap, x = gap, shelf_h = 0;
    offset[c] = {x - charts[c].min_u, y - charts[c].min_v};
    x += charts[c].w + gap;
    used_w = std::max(used_w, x);
    shelf_h = std::max(shelf_h, charts[c].h);
  }
  const double side = std::max(used_w, y + shelf_h + gap);
  const double scale = 1.0 / side;
  res.uv_per_length = scale;

  auto uvmap = get_or_add(mesh, kCornerUV, UV{0, 0});
  auto patch = get_or_add(mesh, kFacePatch, -1);
  double weighted = 0, total = 0, uv_total = 0;
  for (int c = 0; c < res.num_charts; ++c) {
    Chart& ch = charts[c];
    res.chart_faces.push_back(ch.faces.size());
    for (std::size_t i = 0; i < ch.vertices.size(); ++i) local[ch.vertices[i].idx()] = static_cast<int>(i);
    for (FaceIndex f : ch.faces) {
      patch[f] = c;
      std::array<std::array<double, 2>, 3> t;
      int k = 0;
      for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
        const auto& p = ch.uv[local[mesh.target(h).idx()]];
        UV q{(p[0] + offset[c][0]) * scale, (p[1] + offset[c][1]) * scale};
        q = {std::clamp(q[0], 0.0, 1.0), std::clamp(q[1], 0.0, 1.0)};
        uvmap[h] = q;
        t[k++] = q;
      }
      const double auv = signed_area(t[0], t[1], t[2]) / (scale * scale);
      HalfedgeIndex h = mesh.halfedge(f);
      const double a3 = std::sqrt(CGAL::squared_area(mesh.point(mesh.source(h)), mesh.point(mesh.target(h)),
                                                     mesh.point(mesh.target(mesh.next(h)))));
      if (!(auv > 0)) ++res.flipped_faces;
      if (auv > 0 && a3 > 0) weighted += a3 * std::max(a3 / auv, auv / a3), total += a3;
      uv_total += std::abs(auv) * scale * scale;
    }
    for (VertexIndex v : ch.vertices) local[v.idx()] = -1;
  }
  res.mean_area_distortion = total > 0 ? weighted / total : 0;
  res.packing_efficiency = uv_total;
  return res;
}

}  // namespace surftex
