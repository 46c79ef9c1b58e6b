// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/element_correspondence.h"

#include <CGAL/intersections.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geometry/mesh.h"
#include "shell/triangle_distance.h"

namespace surftex {
namespace {
using Triangle2 = Kernel::Triangle_2;

double len(const P3& a, const P3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
}  // namespace

bool projections_overlap(const ElementMesh& a, const ElementMesh& b) {
  auto tri2 = [](const ElementMesh& m, const Tri& t) {
    return Triangle2(Point2(m.points[t[0]][0], m.points[t[0]][1]), Point2(m.points[t[1]][0], m.points[t[1]][1]),
                     Point2(m.points[t[2]][0], m.points[t[2]][1]));
  };
  // Bin b's triangles in a uniform grid over the common box.
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const P3& p : b.points)
    for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  if (b.tris.empty() || a.tris.empty()) return false;
  const int g = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(b.tris.size())) / 2));
  const double cw = std::max((hi[0] - lo[0]) / g, 1e-12), ch = std::max((hi[1] - lo[1]) / g, 1e-12);
  std::vector<std::vector<int>> bins(static_cast<std::size_t>(g * g));
  auto cell = [&](double v, double o, double c) { return std::clamp(static_cast<int>((v - o) / c), 0, g - 1); };
  std::vector<Triangle2> bt;
  bt.reserve(b.tris.size());
  for (std::size_t t = 0; t < b.tris.size(); ++t) {
    bt.push_back(tri2(b, b.tris[t]));
    if (bt.back().is_degenerate()) continue;
    const auto bb = bt.back().bbox();
    for (int y = cell(bb.ymin(), lo[1], ch); y <= cell(bb.ymax(), lo[1], ch); ++y)
      for (int x = cell(bb.xmin(), lo[0], cw); x <= cell(bb.xmax(), lo[0], cw); ++x)
        bins[y * g + x].push_back(static_cast<int>(t));
  }
  for (const Tri& t : a.tris) {
    Triangle2 ta = tri2(a, t);
    if (ta.is_degenerate()) continue;
    const auto bb = ta.bbox();
    if (bb.xmax() < lo[0] || bb.xmin() > hi[0] || bb.ymax() < lo[1] || bb.ymin() > hi[1]) continue;
    for (int y = cell(bb.ymin(), lo[1], ch); y <= cell(bb.ymax(), lo[1], ch); ++y)
      for (int x = cell(bb.xmin(), lo[0], cw); x <= cell(bb.xmax(), lo[0], cw); ++x)
        for (int k : bins[y * g + x])
          if (CGAL::do_overlap(bb, bt[k].bbox()) && CGAL::do_intersect(ta, bt[k])) return true;
  }
  return false;
}

ElementCorrespondences find_element_correspondences(const std::vector<ElementMesh>& out,
                                                    const std::vector<int>& out_ids_in,
                                                    const std::vector<ElementMesh>& in,
                                                    const std::function<bool(const P3&)>& in_overlap,
                                                    const CorrespondenceOptions& opt) {
  ElementCorrespondences res;
  std::vector<int> out_ids = out_ids_in;
  if (out_ids.empty())
    for (std::size_t i = 0; i < out.size(); ++i) out_ids.push_back(static_cast<int>(i));
  // One tree over all input elements (M_in(t)).
  ElementMesh all;
  std::vector<int> tri_elem, tri_local;
  for (std::size_t e = 0; e < in.size(); ++e) {
    append(all, in[e]);
    for (std::size_t t = 0; t < in[e].tris.size(); ++t) {
      tri_elem.push_back(static_cast<int>(e));
      tri_local.push_back(static_cast<int>(t));
    }
  }
  if (all.tris.empty()) return res;
  TriangleDistance tree(all);
  const auto fn = face_normals(all);
  // The output vertices in the overlap, then their closest input faces (in
  // parallel: each query is independent), then the pairs in vertex order.
  struct Query {
    int oe, v;
    P3 n;
  };
  std::vector<Query> queries;
  for (int oe : out_ids) {
    const ElementMesh& m = out[oe];
    const auto vn = vertex_normals(m);
    for (std::size_t v = 0; v < m.points.size(); ++v)
      if (in_overlap(m.points[v])) queries.push_back({oe, static_cast<int>(v), vn[v]});
  }
  std::vector<TriangleDistance::Hit> hits(queries.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    int hint = -1;  // consecutive queries are neighbouring vertices (TriangleDistance::closest)
    for (std::size_t k = r.begin(); k < r.end(); ++k)
      hint = (hits[k] = tree.closest(out[queries[k].oe].points[static_cast<std::size_t>(queries[k].v)], hint)).tri;
  });
  std::vector<VertexFacePair> pairs;
  for (std::size_t k = 0; k < queries.size(); ++k) {
    const int oe = queries[k].oe;
    const std::size_t v = static_cast<std::size_t>(queries[k].v);
    const P3& vnv = queries[k].n;
    ++res.candidates;
    const auto& hit = hits[k];
    const P3& nf = fn[hit.tri];
    const double dot = vnv[0] * nf[0] + vnv[1] * nf[1] + vnv[2] * nf[2];
    if (dot < 0) {
      ++res.pruned_normal;
      continue;
    }
    const Tri& t = all.tris[hit.tri];
    const double local =
        (len(all.points[t[0]], all.points[t[1]]) + len(all.points[t[1]], all.points[t[2]]) +
         len(all.points[t[2]], all.points[t[0]])) / 3.0;
    if (hit.distance > opt.prune_factor * local) {
      ++res.pruned_distance;
      continue;
    }
    VertexFacePair p;
    p.out_element = oe;
    p.vertex = static_cast<int>(v);
    p.in_element = tri_elem[hit.tri];
    p.face = tri_local[hit.tri];
    p.bary = hit.bary;
    p.closest = hit.point;
    p.distance = hit.distance;
    const double dn = std::sqrt((vnv[0] - nf[0]) * (vnv[0] - nf[0]) + (vnv[1] - nf[1]) * (vnv[1] - nf[1]) +
                                (vnv[2] - nf[2]) * (vnv[2] - nf[2]));
    p.cost = (1 + opt.lambda * hit.distance) * (1 + dn);
    pairs.push_back(p);
  }
  std::set<std::pair<int, int>> rel;
  for (const auto& p : pairs) rel.insert({p.out_element, p.in_element});
  // The projection test of each related pair (section 2.5), in parallel.
  const std::vector<std::pair<int, int>> rel_list(rel.begin(), rel.end());
  std::vector<char> overlaps(rel_list.size(), 0);
  tbb::parallel_for(std::size_t(0), rel_list.size(), [&](std::size_t k) {
    overlaps[k] = projections_overlap(out[rel_list[k].first], in[rel_list[k].second]) ? 1 : 0;
  });
  std::set<std::pair<int, int>> keep;
  for (std::size_t k = 0; k < rel_list.size(); ++k)
    if (overlaps[k]) keep.insert(rel_list[k]);
  for (const auto& p : pairs) {
    if (keep.count({p.out_element, p.in_element}))
      res.pairs.push_back(p);
    else
      ++res.pruned_projection;
  }
  res.related.assign(keep.begin(), keep.end());
  return res;
}

}  // namespace surftex
