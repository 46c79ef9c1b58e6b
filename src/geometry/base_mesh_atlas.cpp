// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/base_mesh_atlas.h"

#include <CGAL/Polygon_mesh_processing/compute_normal.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <string>

#include "geometry/disc_chart.h"
#include "geometry/errors.h"
#include "geometry/properties.h"

namespace surftex {

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;
constexpr double kPi = 3.14159265358979323846;

struct Chart {
  std::vector<FaceIndex> faces;
  std::vector<VertexIndex> vertices;   // chart-local vertex -> base vertex
  std::vector<std::array<double, 2>> uv;  // per chart-local vertex
  double min_u = 0, min_v = 0, w = 0, h = 0;  // bounding box after normalisation
  double area3d = 0;
};

// Greedy region growing into disc charts (see header, step 1; the growth is
// geometry/disc_chart.h's, shared with mesh quilting's surface patches).
std::vector<int> grow_charts(const Mesh& mesh, const BaseMeshAtlasOptions& opt, int& num_charts) {
  const double cos_max = std::cos(opt.max_normal_angle_deg * kPi / 180.0);
  std::vector<Vector3> normal(mesh.num_faces());
  for (FaceIndex f : mesh.faces()) normal[f.idx()] = PMP::compute_face_normal(f, mesh);
  std::vector<int> chart_of(mesh.num_faces(), -1);
  DiscGrowthState state(mesh);
  num_charts = 0;
  for (FaceIndex seed : mesh.faces()) {
    if (chart_of[seed.idx()] != -1) continue;
    const int c = num_charts++;
    const Vector3 n0 = normal[seed.idx()];
    auto accept = [&](int f) { return chart_of[static_cast<std::size_t>(f)] == -1 && normal[static_cast<std::size_t>(f)] * n0 >= cos_max; };
    for (int f : grow_disc_chart(mesh, static_cast<int>(seed.idx()), accept, opt.max_chart_faces, state))
      chart_of[static_cast<std::size_t>(f)] = c;
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

// Flattens the chart (geometry/disc_chart.h: disc check, LSCM, oriented and
// scaled to its 3D area) and turns it to its smallest bounding box.
void flatten_chart(const Mesh& mesh, Chart& ch, int chart_id) {
  std::vector<int> faces;
  for (FaceIndex f : ch.faces) faces.push_back(static_cast<int>(f.idx()));
  DiscChartFlattening fl = flatten_disc_chart(mesh, faces);
  const std::string what = "base mesh atlas: chart " + std::to_string(chart_id) + " (" + std::to_string(ch.faces.size()) + " faces): ";
  if (fl.status == DiscChartFlattening::Status::kTopology) throw TopologyError(what + fl.error + " (non-manifold base mesh?)");
  if (fl.status != DiscChartFlattening::Status::kOk) throw SolverError(what + fl.error);
  ch.vertices.clear();
  for (int v : fl.vertices) ch.vertices.push_back(VertexIndex(static_cast<Mesh::size_type>(v)));
  ch.uv = std::move(fl.uv);
  ch.area3d = fl.area3d;
  rotate_to_small_box(ch);
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
  for (int c = 0; c < res.num_charts; ++c) flatten_chart(mesh, charts[c], c);

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
