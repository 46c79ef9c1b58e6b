// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/base_mesh_atlas.h"
#include "geometry/constants.h"

#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <set>
#include <string>

#include "geometry/disc_chart.h"
#include "geometry/errors.h"
#include "geometry/properties.h"

namespace surftex {

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;

struct Chart {
  std::vector<FaceIndex> faces;
  std::vector<VertexIndex> vertices;   // chart-local vertex -> base vertex
  std::vector<std::array<double, 2>> uv;  // per chart-local vertex
  double min_u = 0, min_v = 0, w = 0, h = 0;  // bounding box after normalisation
  double area3d = 0;
  double distortion = 1;  // the flattening's area_distortion
  bool alive = true;      // false once merged into another chart
  int version = 0;        // changes when a chart merges into this one
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

// LSCM flattening of `faces` (geometry/disc_chart.h: disc check, oriented,
// scaled to its 3D area, embedding check).
DiscChartFlattening flatten(const Mesh& mesh, const std::vector<FaceIndex>& faces) {
  std::vector<int> idx;
  for (FaceIndex f : faces) idx.push_back(static_cast<int>(f.idx()));
  return flatten_disc_chart(mesh, idx, LscmSolver::kDirect);
}

// A chart from its flattening, turned to its smallest bounding box.
Chart make_chart(std::vector<FaceIndex> faces, DiscChartFlattening&& fl) {
  Chart ch;
  ch.faces = std::move(faces);
  for (int v : fl.vertices) ch.vertices.push_back(VertexIndex(static_cast<Mesh::size_type>(v)));
  ch.uv = std::move(fl.uv);
  ch.area3d = fl.area3d;
  ch.distortion = fl.area_distortion;
  rotate_to_small_box(ch);
  return ch;
}

// Throws for a chart flattening that failed (not for one that folds).
void check_flattening(const DiscChartFlattening& fl, const std::vector<FaceIndex>& faces) {
  const std::string what = "base mesh atlas: chart of " + std::to_string(faces.size()) + " faces from face " +
                           std::to_string(faces.front().idx()) + ": ";
  if (fl.status == DiscChartFlattening::Status::kTopology)
    throw TopologyError(what + fl.error + " (non-manifold base mesh?)");
  if (fl.status != DiscChartFlattening::Status::kOk) throw SolverError(what + fl.error);
}

// The faces of a folded chart regrown into discs of at most half its size.
std::vector<std::vector<FaceIndex>> split_chart(const Mesh& mesh, std::vector<FaceIndex> faces,
                                                DiscGrowthState& state, std::vector<char>& free_face) {
  std::sort(faces.begin(), faces.end());
  for (FaceIndex f : faces) free_face[f.idx()] = 1;
  auto accept = [&](int f) { return free_face[static_cast<std::size_t>(f)] != 0; };
  std::vector<std::vector<FaceIndex>> parts;
  for (FaceIndex seed : faces) {
    if (!free_face[seed.idx()]) continue;
    parts.emplace_back();
    for (int f : grow_disc_chart(mesh, static_cast<int>(seed.idx()), accept, (faces.size() + 1) / 2, state)) {
      free_face[static_cast<std::size_t>(f)] = 0;
      parts.back().push_back(FaceIndex(static_cast<Mesh::size_type>(f)));
    }
  }
  return parts;
}

// Flattens the grown charts (see header, step 2). A flattening that is not
// an embedding (LSCM folded the chart over itself) is split: its faces
// regrown into discs of at most half its size, each flattened the same way.
// Each round's charts are flattened in parallel; the charts come out in the
// depth-first order of a serial recursion (grown chart, then its parts).
std::vector<Chart> flatten_or_split(const Mesh& mesh, std::vector<std::vector<FaceIndex>> grown) {
  struct Pending {
    std::vector<FaceIndex> faces;
    std::vector<int> path;  // grown chart index, then part indices
  };
  std::vector<Pending> round;
  for (std::size_t i = 0; i < grown.size(); ++i) round.push_back({std::move(grown[i]), {static_cast<int>(i)}});
  std::vector<std::pair<std::vector<int>, Chart>> done;
  DiscGrowthState state(mesh);
  std::vector<char> free_face(mesh.num_faces(), 0);
  while (!round.empty()) {
    std::vector<DiscChartFlattening> fl(round.size());
    tbb::parallel_for(std::size_t(0), round.size(), [&](std::size_t i) { fl[i] = flatten(mesh, round[i].faces); });
    std::vector<Pending> next;
    for (std::size_t i = 0; i < round.size(); ++i) {
      check_flattening(fl[i], round[i].faces);
      if (fl[i].embedded() || round[i].faces.size() == 1) {
        done.emplace_back(std::move(round[i].path), make_chart(std::move(round[i].faces), std::move(fl[i])));
        continue;
      }
      int k = 0;
      for (auto& part : split_chart(mesh, std::move(round[i].faces), state, free_face)) {
        next.push_back({std::move(part), round[i].path});
        next.back().path.push_back(k++);
      }
    }
    round = std::move(next);
  }
  std::sort(done.begin(), done.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Chart> charts;
  for (auto& d : done) charts.push_back(std::move(d.second));
  return charts;
}

// The side of the square the chart boxes pack into with a gap of `margin`
// times that side around each (shelf slack 1.15, as in step 3):
// side^2 = 1.15^2 sum (w + g)(h + g), g = margin * side, kept as running sums.
struct PackedSide {
  double margin = 0, n = 0, wh = 0, w_plus_h = 0;
  void add(const Chart& c, double sign) { n += sign, wh += sign * c.w * c.h, w_plus_h += sign * (c.w + c.h); }
  double gap() const {
    const double k = 1.15 * 1.15, a = std::max(0.05, 1 - k * n * margin * margin), b = k * margin * w_plus_h;
    return margin * (b + std::sqrt(b * b + 4 * a * k * wh)) / (2 * a);
  }
};

double padded_box(const Chart& c, double gap) {
  return (c.w + gap) * (c.h + gap);
}

// Charts sharing edges with `c`, longest shared border first (ties: lower id).
std::vector<int> neighbours(const Mesh& mesh, const Chart& c, int id, const std::vector<int>& chart_of) {
  std::map<int, double> shared;
  for (FaceIndex f : c.faces)
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      const FaceIndex g = mesh.face(mesh.opposite(h));
      if (g != Mesh::null_face() && chart_of[g.idx()] != id)
        shared[chart_of[g.idx()]] +=
            std::sqrt(CGAL::squared_distance(mesh.point(mesh.source(h)), mesh.point(mesh.target(h))));
    }
  std::vector<std::pair<double, int>> order;
  for (auto [d, len] : shared) order.emplace_back(-len, d);
  std::sort(order.begin(), order.end());
  std::vector<int> out;
  for (auto [len, d] : order) out.push_back(d);
  return out;
}

// The faces chart c merged into chart d flattens: d's, then c's.
std::vector<FaceIndex> union_faces(const Chart& a, const Chart& b) {
  std::vector<FaceIndex> faces = b.faces;
  faces.insert(faces.end(), a.faces.begin(), a.faces.end());
  return faces;
}

// try_merge's tests before flattening: the union stays within
// max_chart_faces and a box of its area could pack smaller than the two.
bool may_merge(const BaseMeshAtlasOptions& opt, const Chart& a, const Chart& b, double gap) {
  if (a.faces.size() + b.faces.size() > opt.max_chart_faces) return false;
  const double before = padded_box(a, gap) + padded_box(b, gap), area = a.area3d + b.area3d;
  return area + 2 * gap * std::sqrt(area) + gap * gap < before;
}

// Chart c merged into chart d when may_merge holds and the flattening `fl`
// of their union_faces is an embedding, no more distorted than
// max(max_merge_distortion, the parts' area-weighted distortion), whose
// padded box is smaller than the two.
bool try_merge(const BaseMeshAtlasOptions& opt, std::vector<Chart>& charts, int c, int d, DiscChartFlattening&& fl,
               std::vector<int>& chart_of, PackedSide& side) {
  Chart &a = charts[c], &b = charts[d];
  const double gap = side.gap(), before = padded_box(a, gap) + padded_box(b, gap);
  const double area = a.area3d + b.area3d;
  const double parts = (a.distortion * a.area3d + b.distortion * b.area3d) / area;
  if (!fl.embedded() || fl.area_distortion > std::max(opt.max_merge_distortion, parts)) return false;
  Chart u = make_chart(union_faces(a, b), std::move(fl));
  if (padded_box(u, gap) >= before) return false;
  side.add(a, -1), side.add(b, -1), side.add(u, 1);
  for (FaceIndex f : a.faces) chart_of[f.idx()] = d;
  u.version = a.version > b.version ? a.version + 1 : b.version + 1;
  b = std::move(u);
  a = Chart();
  a.alive = false;
  return true;
}

using MergeQueue = std::set<std::pair<double, int>>;  // area, chart: smallest first

// Union flattenings computed ahead of the serial merge loop, which takes
// them in its own order: the same merges as flattening each union when
// tried, in less time when threads are free (2 threads: decision 210).
class UnionFlattenings {
 public:
  /// The flattening of chart c's union with chart d. When it was not computed
  /// ahead, it is computed now in parallel with the unions the next queued
  /// charts would try first (charts not in any union of the batch).
  DiscChartFlattening take(const Mesh& mesh, const BaseMeshAtlasOptions& opt, const std::vector<Chart>& charts,
                           int c, int d, const MergeQueue& queue, const std::vector<int>& chart_of, double gap) {
    auto hit = find(charts, c, d);
    if (hit == entries_.end()) {
      compute(mesh, next_jobs(mesh, opt, charts, c, d, queue, chart_of, gap), charts);
      hit = find(charts, c, d);
    }
    DiscChartFlattening fl = std::move(hit->fl);
    entries_.erase(hit);
    return fl;
  }

 private:
  struct Entry {
    int c, d, vc, vd;  // charts and their versions when flattened
    DiscChartFlattening fl;
  };
  std::vector<Entry> entries_;

  std::vector<Entry>::iterator find(const std::vector<Chart>& charts, int c, int d) {
    return std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) {
      return e.c == c && e.d == d && e.vc == charts[c].version && e.vd == charts[d].version;
    });
  }

  // (c, d), then for the next queued charts (up to 4 per thread looked at)
  // the first neighbour passing may_merge, while both are in no earlier pair.
  std::vector<std::pair<int, int>> next_jobs(const Mesh& mesh, const BaseMeshAtlasOptions& opt,
                                             const std::vector<Chart>& charts, int c, int d, const MergeQueue& queue,
                                             const std::vector<int>& chart_of, double gap) {
    const std::size_t threads = std::min(
        static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency())),
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    std::vector<std::pair<int, int>> jobs{{c, d}};
    std::vector<int> used{c, d};
    auto is_used = [&](int x) { return std::find(used.begin(), used.end(), x) != used.end(); };
    std::size_t looked = 0;
    for (auto it = queue.begin(); it != queue.end() && jobs.size() < threads && looked < 4 * threads; ++it) {
      const int a = it->second;
      if (!charts[a].alive || it->first != charts[a].area3d || is_used(a)) continue;
      ++looked;
      for (int b : neighbours(mesh, charts[a], a, chart_of)) {
        if (!may_merge(opt, charts[a], charts[b], gap)) continue;
        if (!is_used(b) && find(charts, a, b) == entries_.end()) jobs.emplace_back(a, b);
        used.push_back(a), used.push_back(b);
        break;
      }
    }
    return jobs;
  }

  // Flattens the jobs' unions in parallel; drops entries of changed charts.
  void compute(const Mesh& mesh, const std::vector<std::pair<int, int>>& jobs, const std::vector<Chart>& charts) {
    entries_.erase(std::remove_if(entries_.begin(), entries_.end(),
                                  [&](const Entry& e) {
                                    return e.vc != charts[e.c].version || e.vd != charts[e.d].version ||
                                           !charts[e.c].alive || !charts[e.d].alive;
                                  }),
                   entries_.end());
    std::vector<DiscChartFlattening> fl(jobs.size());
    tbb::parallel_for(std::size_t(0), jobs.size(), [&](std::size_t i) {
      fl[i] = flatten(mesh, union_faces(charts[jobs[i].first], charts[jobs[i].second]));
    });
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      const auto [a, b] = jobs[i];
      entries_.push_back({a, b, charts[a].version, charts[b].version, std::move(fl[i])});
    }
  }
};

// Greedy merging (see header, step 2b; Sander et al. 2001, section 4.1):
// the smallest chart (3D area) first, into the neighbour sharing the longest
// border that takes it, until no chart merges.
void merge_charts(const Mesh& mesh, const BaseMeshAtlasOptions& opt, std::vector<Chart>& charts,
                  std::vector<int>& chart_of) {
  PackedSide side;
  side.margin = opt.margin;
  MergeQueue queue;
  for (std::size_t c = 0; c < charts.size(); ++c) {
    side.add(charts[c], 1);
    queue.insert({charts[c].area3d, static_cast<int>(c)});
  }
  UnionFlattenings ahead;
  while (!queue.empty()) {
    const auto [area, c] = *queue.begin();
    queue.erase(queue.begin());
    if (!charts[c].alive || area != charts[c].area3d) continue;  // merged, or queued again since
    for (int d : neighbours(mesh, charts[c], c, chart_of)) {
      if (!may_merge(opt, charts[c], charts[d], side.gap())) continue;
      DiscChartFlattening fl = ahead.take(mesh, opt, charts, c, d, queue, chart_of, side.gap());
      if (try_merge(opt, charts, c, d, std::move(fl), chart_of, side)) {
        queue.insert({charts[d].area3d, d});
        break;
      }
    }
  }
}

// Grown charts flattened (split where LSCM folds them), merged if asked,
// renumbered in order; chart_of follows.
std::vector<Chart> make_charts(const Mesh& mesh, const BaseMeshAtlasOptions& opt, std::vector<int>& chart_of,
                               int num_grown) {
  std::vector<std::vector<FaceIndex>> grown(num_grown);
  for (FaceIndex f : mesh.faces()) grown[chart_of[f.idx()]].push_back(f);
  std::vector<Chart> charts = flatten_or_split(mesh, std::move(grown));
  for (std::size_t c = 0; c < charts.size(); ++c)
    for (FaceIndex f : charts[c].faces) chart_of[f.idx()] = static_cast<int>(c);
  if (opt.merge_charts) merge_charts(mesh, opt, charts, chart_of);
  std::vector<Chart> kept;
  for (Chart& c : charts)
    if (c.alive) {
      for (FaceIndex f : c.faces) chart_of[f.idx()] = static_cast<int>(kept.size());
      kept.push_back(std::move(c));
    }
  return kept;
}
}  // namespace

BaseMeshAtlasResult compute_base_mesh_atlas(Mesh& mesh, const BaseMeshAtlasOptions& opt) {
  if (!(opt.max_normal_angle_deg > 0 && opt.max_normal_angle_deg <= 180))
    throw InvalidInputError("base mesh atlas: max_normal_angle_deg must be in (0,180], got " +
                            std::to_string(opt.max_normal_angle_deg));
  if (opt.max_chart_faces < 1) throw InvalidInputError("base mesh atlas: max_chart_faces must be >= 1");
  if (!(opt.max_merge_distortion >= 1))
    throw InvalidInputError("base mesh atlas: max_merge_distortion must be >= 1, got " +
                            std::to_string(opt.max_merge_distortion));
  if (!(opt.margin >= 0 && opt.margin < 0.1))
    throw InvalidInputError("base mesh atlas: margin must be in [0,0.1), got " + std::to_string(opt.margin));
  if (mesh.number_of_faces() == 0) throw InvalidInputError("base mesh atlas: mesh has no faces");
  if (mesh.has_garbage())
    throw InvalidInputError("base mesh atlas: mesh has removed elements; call collect_garbage() first");
  for (FaceIndex f : mesh.faces())
    if (mesh.degree(f) != 3)
      throw InvalidInputError("base mesh atlas: face " + std::to_string(f.idx()) + " is not a triangle");

  BaseMeshAtlasResult res;
  int grown = 0;
  std::vector<int> chart_of = grow_charts(mesh, opt, grown);
  std::vector<Chart> charts = make_charts(mesh, opt, chart_of, grown);
  res.num_charts = static_cast<int>(charts.size());

  std::vector<int> local(mesh.num_vertices(), -1);

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
      const double auv = uv_signed_area(t[0], t[1], t[2]) / (scale * scale);
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
