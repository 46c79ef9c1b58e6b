// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/element_merging.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <tuple>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "geometry/errors.h"
#include "geometry/graph_cut.h"
#include "geometry/mesh.h"
#include "geometry/newell.h"
#include "geometry/self_intersections.h"
#include "shell/quilting/element_deformation.h"
#include "shell/triangle_distance.h"

namespace surftex {
namespace {
double dist(const P3& a, const P3& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}
P3 centroid(const ElementMesh& m, const Tri& t) {
  P3 c;
  for (int d = 0; d < 3; ++d) c[d] = (m.points[t[0]][d] + m.points[t[1]][d] + m.points[t[2]][d]) / 3.0;
  return c;
}
std::uint64_t ukey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}
double mean_edge(const ElementMesh& m) {
  double s = 0;
  std::size_t n = 0;
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) s += dist(m.points[t[k]], m.points[t[(k + 1) % 3]]), ++n;
  return n ? s / static_cast<double>(n) : 0;
}
/// Interior edges: (tri1, tri2, v_i, v_j) for every edge shared by two triangles.
struct DualEdge {
  int t1, t2, vi, vj;
};
std::vector<DualEdge> dual_edges(const ElementMesh& m) {
  std::unordered_map<std::uint64_t, int> first;
  std::vector<DualEdge> out;
  for (std::size_t t = 0; t < m.tris.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = m.tris[t][k], b = m.tris[t][(k + 1) % 3];
      auto [it, inserted] = first.emplace(ukey(a, b), static_cast<int>(t));
      if (!inserted && it->second >= 0) {
        out.push_back({it->second, static_cast<int>(t), a, b});
        it->second = -1;
      }
    }
  return out;
}
double auto_match(const ElementMesh& a, const ElementMesh& b, const MergeOptions& opt) {
  return opt.match_distance > 0 ? opt.match_distance : 1.5 * (mean_edge(a) + mean_edge(b));
}
}  // namespace

double cut_cost(const ElementMesh& a, const ElementMesh& b, const std::vector<char>& keep) {
  TriangleDistance tb(b);
  std::vector<double> d(a.points.size());
  int hint = -1;  // (TriangleDistance::closest: the previous vertex's hit bounds the search)
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    const auto h = tb.closest(a.points[i], hint);
    d[i] = h.distance;
    hint = h.tri;
  }
  double c = 0;
  for (const DualEdge& e : dual_edges(a))
    if (keep[e.t1] != keep[e.t2]) c += (1 + dist(a.points[e.vi], a.points[e.vj])) * (1 + d[e.vi] + d[e.vj]);
  return c;
}

namespace {
bool owns(Side side, Region r) {
  return side == Region::kOverlap ? (r == Region::kOld || r == Region::kNew) : r == side;
}
}  // namespace

namespace {
// cut_element with the closest-point trees of A and B built by the caller
// (merge_elements cuts A against B and B against A with the same two trees).
ElementCut cut_with_trees(const ElementMesh& a, const TriangleDistance& ta, Side side_a, const ElementMesh& b,
                          const TriangleDistance& tb, Side side_b, const RegionFn& region, const MergeOptions& opt,
                          const std::vector<char>* b_keep) {
  ElementCut res;
  const double match = auto_match(a, b, opt);
  const int nt = static_cast<int>(a.tris.size());
  std::vector<char> force_keep(nt, 0), force_del(nt, 0);
  for (int t = 0; t < nt; ++t)
    if (owns(side_a, region(centroid(a, a.tris[t])))) force_keep[t] = 1;
  // The SINK rule's vertices (see below): the paper applies it in the overlap
  // region; with MergeOptions::delete_past_overlap also where A pokes past it
  // into the other side (not A's own outside, not off the grid).
  std::vector<char> sink_rule(a.points.size(), 0);
  for (std::size_t v = 0; v < a.points.size(); ++v) {
    const Region rv = region(a.points[v]);
    sink_rule[v] = !(opt.delete_past_overlap ? owns(side_a, rv) || rv == Region::kNone : rv != Region::kOverlap);
  }
  // A's closest points on B, queried (in parallel) where a rule or a weight
  // reads them: an edge between two kept-by-force triangles is never cut
  // (GraphCut drops it), so without a guide (whose scale, wmax, reads every
  // weight) a long element's far part needs no query.
  const auto edges = dual_edges(a);
  std::vector<char> need(a.points.size(), b_keep ? 1 : 0);
  for (const DualEdge& e : edges)
    if (!(force_keep[e.t1] && force_keep[e.t2])) need[e.vi] = need[e.vj] = 1;
  for (std::size_t v = 0; v < a.points.size(); ++v) need[v] = need[v] || sink_rule[v];
  std::vector<TriangleDistance::Hit> hit(a.points.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, a.points.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    int hint = -1;
    for (std::size_t v = r.begin(); v < r.end(); ++v)
      if (need[v]) hint = (hit[v] = tb.closest(a.points[v], hint)).tri;
  });
  // B's faces farther from A's bounding box than `match` are not covered
  // (the closest point of A is farther still); a margin of 1e-9 relative
  // keeps rounding from deciding a face the query would call covered.
  const double far2 = match * (1 + 1e-9) * match * (1 + 1e-9) + 1e-300;
  // Faces of B "with a corresponding vertex in A" (see the header): the point
  // q of A closest to the face's centroid c must be within `match` and must
  // itself have its closest point of B at c (within opt.round_trip_edges mean
  // edges of B), i.e.
  // A reaches this face, not merely passes near it. Past the end of A (e.g.
  // beyond the end cap of a thread, whose closest points of A all lie on the
  // cap rim) the round trip lands back at the cap, so B's faces there are
  // uncovered and the A vertices next to them are deleted.
  const double round_trip = opt.round_trip_edges * mean_edge(b);
  std::vector<char> covered(b.tris.size());
  std::vector<char> b_in(b.tris.size());
  for (std::size_t g = 0; g < b.tris.size(); ++g) b_in[g] = !owns(side_b, region(centroid(b, b.tris[g])));  // not in B's own outside
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, b.tris.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
    int ha = -1, hb = -1;
    for (std::size_t g = r.begin(); g < r.end(); ++g) {
      const P3 c = centroid(b, b.tris[g]);
      if (ta.box_squared_distance(c) > far2) continue;
      // (Only a hit within `match` counts; B's closest point to q is no
      // farther from q than c, a point of B, is.)
      const auto q = ta.closest_within(c, match, ha);
      if (q.tri >= 0) ha = q.tri;
      if (!(q.distance <= match)) continue;
      const auto back = tb.closest_within(q.point, q.distance, hb);
      hb = back.tri;
      covered[g] = dist(back.point, c) <= round_trip;
    }
  });
  // Edge-neighbours of B's faces.
  std::vector<std::vector<int>> b_nb(b.tris.size());
  for (const DualEdge& e : dual_edges(b)) b_nb[e.t1].push_back(e.t2), b_nb[e.t2].push_back(e.t1);
  // MergeOptions::uncovered_must_escape: an uncovered face counts only if its
  // connected uncovered region reaches B's own outside (B runs on past A
  // there), not if it is a patch of B that ends beside A (B's own end cap
  // lying along A: A continues there, and must not be deleted).
  std::vector<char> escapes(b.tris.size(), 1);
  if (opt.uncovered_must_escape) {
    std::vector<int> comp(b.tris.size(), -1);
    std::vector<char> comp_escapes;
    for (std::size_t g0 = 0; g0 < b.tris.size(); ++g0) {
      if (covered[g0] || comp[g0] >= 0) continue;
      const int id = static_cast<int>(comp_escapes.size());
      comp_escapes.push_back(0);
      std::vector<int> stack{static_cast<int>(g0)};
      comp[g0] = id;
      while (!stack.empty()) {
        const int g = stack.back();
        stack.pop_back();
        if (!b_in[g]) comp_escapes[id] = 1;
        for (int n : b_nb[g])
          if (!covered[n] && comp[n] < 0) comp[n] = id, stack.push_back(n);
      }
    }
    for (std::size_t g = 0; g < b.tris.size(); ++g) escapes[g] = comp[g] < 0 || comp_escapes[comp[g]];
  }

  GraphCut gc(nt);
  auto weight = [&](const DualEdge& e) {
    return (1 + dist(a.points[e.vi], a.points[e.vj])) * (1 + hit[e.vi].distance + hit[e.vj].distance);
  };
  double wmax = 0;
  for (const DualEdge& e : edges) {
    if (!b_keep && force_keep[e.t1] && force_keep[e.t2]) continue;  // never cut (above)
    const double w = weight(e);
    wmax = std::max(wmax, w);
    gc.add_edge(e.t1, e.t2, w, w);
  }
  std::vector<std::vector<int>> vtris(a.points.size());
  for (int t = 0; t < nt; ++t)
    for (int v : a.tris[t]) vtris[v].push_back(t);
  for (std::size_t v = 0; v < a.points.size(); ++v) {
    if (!sink_rule[v]) continue;
    const auto& h = hit[v];
    if (h.tri < 0 || h.distance > match) continue;
    bool del = !b_in[h.tri];
    for (int g : b_nb[h.tri]) del = del || (!covered[g] && escapes[g]);
    // Keep wins over delete where both rules hit one triangle (at the rim of
    // the overlap region an element can reach just past it): the paper's two
    // infinite rules would otherwise make every cut infinite.
    if (del)
      for (int t : vtris[v]) force_del[t] = !force_keep[t];
  }
  res.terminal.assign(nt, 0);
  for (int t = 0; t < nt; ++t) {
    res.terminal[t] = force_keep[t] && force_del[t] ? 2 : force_keep[t] ? 1 : force_del[t] ? -1 : 0;
    if (force_keep[t]) gc.add_terminal(t, GraphCut::kInfinity, 0), ++res.forced_keep;
    if (force_del[t]) gc.add_terminal(t, 0, GraphCut::kInfinity), ++res.forced_delete;
  }
  if (b_keep) {
    const double g = opt.guide_factor * std::max(wmax, 1.0);
    std::vector<TriangleDistance::Hit> ch(static_cast<std::size_t>(nt));
    tbb::parallel_for(tbb::blocked_range<int>(0, nt, 64), [&](const tbb::blocked_range<int>& r) {
      int hint = -1;
      for (int t = r.begin(); t < r.end(); ++t)
        if (!force_keep[t] && !force_del[t])
          if (const auto h = (ch[static_cast<std::size_t>(t)] = tb.closest_within(centroid(a, a.tris[t]), match, hint)); h.tri >= 0)
            hint = h.tri;
    });
    for (int t = 0; t < nt; ++t) {
      if (force_keep[t] || force_del[t]) continue;
      const auto& h = ch[static_cast<std::size_t>(t)];
      if (h.tri < 0 || h.distance > match) continue;
      bool behind = (*b_keep)[h.tri];
      if (opt.guide_by_vertices)
        for (int v : a.tris[t]) {
          const auto& hv = hit[v];
          behind = behind || (hv.tri >= 0 && hv.distance <= match && (*b_keep)[hv.tri]);
        }
      if (behind)
        gc.add_terminal(t, 0, g);
      else
        gc.add_terminal(t, g, 0);
    }
  }
  const double flow = gc.solve();
  res.feasible = flow < GraphCut::kInfinity * 0.5;
  res.keep.resize(nt);
  for (int t = 0; t < nt; ++t) res.keep[t] = gc.is_source_side(t) ? 1 : 0;
  res.cost = 0;
  for (const DualEdge& e : edges)
    if (res.keep[e.t1] != res.keep[e.t2]) res.cost += weight(e);
  return res;
}
}  // namespace

namespace {
void check_options(const MergeOptions& opt) {
  if (!(opt.round_trip_edges > 0) || !std::isfinite(opt.round_trip_edges))
    throw InvalidInputError("merge_elements: round_trip_edges must be > 0 (" + std::to_string(opt.round_trip_edges) + ")");
  if (!(opt.match_distance >= 0))
    throw InvalidInputError("merge_elements: match_distance must be >= 0 (" + std::to_string(opt.match_distance) + ")");
}
}  // namespace

ElementCut cut_element(const ElementMesh& a, Side side_a, const ElementMesh& b, Side side_b, const RegionFn& region,
                       const MergeOptions& opt, const std::vector<char>* b_keep) {
  check_options(opt);
  const TriangleDistance ta(a), tb(b);
  return cut_with_trees(a, ta, side_a, b, tb, side_b, region, opt, b_keep);
}

namespace {
/// Connected components (across edges, `nb` = the dual graph's neighbours) of
/// the triangles labelled `side` in `keep`: comp[t] = component id (-1 for
/// the other triangles), members[id] = its triangles in flood order.
struct TriangleComponents {
  std::vector<int> comp;
  std::vector<std::vector<int>> members;
};
TriangleComponents triangle_components(const std::vector<std::vector<int>>& nb, const std::vector<char>& keep,
                                       char side) {
  const int nt = static_cast<int>(keep.size());
  TriangleComponents r;
  r.comp.assign(static_cast<std::size_t>(nt), -1);
  for (int t = 0; t < nt; ++t) {
    if (keep[t] != side || r.comp[t] >= 0) continue;
    const int id = static_cast<int>(r.members.size());
    r.members.emplace_back();
    std::vector<int> stack{t};
    r.comp[t] = id;
    while (!stack.empty()) {
      const int x = stack.back();
      stack.pop_back();
      r.members[id].push_back(x);
      for (int y : nb[x])
        if (keep[y] == side && r.comp[y] < 0) r.comp[y] = id, stack.push_back(y);
    }
  }
  return r;
}

/// Removes the islands a graph cut can leave (section 2.7 wants "a cut path",
/// one seam per crossing): connected components (across edges) of kept
/// triangles that hold no triangle forced to SOURCE are deleted, then
/// components of deleted triangles that hold no triangle forced to SINK are
/// kept again. Where no triangle is forced to a side, its largest component
/// stays. Without this, the guide links of B's cut (one per triangle, much
/// stronger than the n-links) copy the noise of A's labels where the two
/// elements do not coincide exactly, and B's cut opens several small loops
/// around islands while A's opens one: the merge is refused ("cuts opened 1
/// and 3 loops"), the usual refusal on finely tessellated weaves.
void remove_cut_islands(const ElementMesh& m, const std::vector<signed char>& terminal, std::vector<char>& keep) {
  const int nt = static_cast<int>(m.tris.size());
  std::vector<std::vector<int>> nb(static_cast<std::size_t>(nt));
  for (const DualEdge& e : dual_edges(m)) nb[e.t1].push_back(e.t2), nb[e.t2].push_back(e.t1);
  for (const char side : {char(1), char(0)}) {
    const signed char forced = side ? 1 : -1;
    const TriangleComponents tc = triangle_components(nb, keep, side);
    const std::vector<std::vector<int>>& comps = tc.members;
    std::vector<char> anchored(comps.size(), 0);
    for (std::size_t k = 0; k < comps.size(); ++k)
      for (int x : comps[k])
        if (terminal[x] == forced || terminal[x] == 2) anchored[k] = 1;
    if (comps.empty()) continue;
    bool any = false;
    for (char a : anchored) any = any || a;
    if (!any) {  // keep the largest component (first on ties)
      std::size_t big = 0;
      for (std::size_t k = 1; k < comps.size(); ++k)
        if (comps[k].size() > comps[big].size()) big = k;
      anchored[big] = 1;
    }
    for (std::size_t k = 0; k < comps.size(); ++k)
      if (!anchored[k])
        for (int t : comps[k]) keep[t] = side ? 0 : 1;
  }
}

// True if every directed edge is used at most once, no triangle repeats a
// vertex and the triangles around every vertex form one fan (connected across
// edges at the vertex): what a Surface_mesh can hold. A zip can break this
// where the kept parts have borders of their own (then the closedness test
// below does not apply).
bool is_manifold_oriented(const ElementMesh& m) {
  std::unordered_set<std::uint64_t> directed;
  std::vector<std::vector<int>> vt(m.points.size());
  for (std::size_t t = 0; t < m.tris.size(); ++t) {
    const Tri& tr = m.tris[t];
    for (int k = 0; k < 3; ++k) {
      const int a = tr[k], b = tr[(k + 1) % 3];
      if (a == b) return false;
      const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
      if (!directed.insert(key).second) return false;
      vt[a].push_back(static_cast<int>(t));
    }
  }
  for (std::size_t v = 0; v < vt.size(); ++v) {
    const auto& ts = vt[v];
    if (ts.size() < 2) continue;
    std::vector<char> seen(ts.size(), 0);
    std::vector<std::size_t> stack{0};
    seen[0] = 1;
    std::size_t reached = 1;
    while (!stack.empty()) {
      const std::size_t x = stack.back();
      stack.pop_back();
      for (std::size_t j = 0; j < ts.size(); ++j) {
        if (seen[j]) continue;
        bool adj = false;
        for (int a : m.tris[ts[x]])
          for (int b : m.tris[ts[j]]) adj = adj || (a == b && a != static_cast<int>(v));
        if (adj) seen[j] = 1, ++reached, stack.push_back(j);
      }
    }
    if (reached != ts.size()) return false;
  }
  return true;
}

// Deleted components (across edges) of a labelling and, per component, the
// mean midpoint of its cut edges (edges between a kept and a deleted
// triangle); components without a cut edge are left out.
void deleted_components(const ElementMesh& m, const std::vector<char>& keep, std::vector<std::vector<int>>& comps,
                        std::vector<P3>& centres) {
  const int nt = static_cast<int>(m.tris.size());
  std::vector<std::vector<int>> nb(static_cast<std::size_t>(nt));
  std::vector<std::pair<int, P3>> cut;  // (deleted triangle, edge midpoint)
  for (const DualEdge& e : dual_edges(m)) {
    nb[e.t1].push_back(e.t2), nb[e.t2].push_back(e.t1);
    if (keep[e.t1] != keep[e.t2]) {
      const P3& p = m.points[e.vi];
      const P3& q = m.points[e.vj];
      cut.emplace_back(keep[e.t1] ? e.t2 : e.t1, P3{(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2});
    }
  }
  TriangleComponents tc = triangle_components(nb, keep, 0);
  const std::vector<int>& comp = tc.comp;
  std::vector<std::vector<int>>& all = tc.members;
  std::vector<P3> sum(all.size(), P3{0, 0, 0});
  std::vector<int> cnt(all.size(), 0);
  for (const auto& [t, p] : cut) {
    const int id = comp[t];
    for (int d = 0; d < 3; ++d) sum[id][d] += p[d];
    ++cnt[id];
  }
  comps.clear();
  centres.clear();
  for (std::size_t k = 0; k < all.size(); ++k)
    if (cnt[k] > 0) {
      comps.push_back(std::move(all[k]));
      centres.push_back({sum[k][0] / cnt[k], sum[k][1] / cnt[k], sum[k][2] / cnt[k]});
    }
}

// Where the cuts of A and B open different numbers of seams (for example B,
// pulled to SINK by the infinite rule at a vertex whose closest face of A lies
// just across the overlap rim, gets a hole in the side of its tube that no
// seam of A faces), the seams are paired greedily by distance and every
// deleted component behind an unpaired seam is restored: a seam with no
// partner cannot be stitched, and the paper's merge always yields one
// connected element. (Our reading; the paper does not discuss the case.)
// Returns the number of components restored.
int restore_unpaired_cuts(const ElementMesh& a, std::vector<char>& keep_a, const ElementMesh& b,
                          std::vector<char>& keep_b) {
  std::vector<std::vector<int>> ca, cb;
  std::vector<P3> pa, pb;
  deleted_components(a, keep_a, ca, pa);
  deleted_components(b, keep_b, cb, pb);
  if (ca.size() == cb.size() || ca.empty() || cb.empty()) return 0;
  std::vector<std::tuple<double, int, int>> cand;
  for (std::size_t i = 0; i < pa.size(); ++i)
    for (std::size_t j = 0; j < pb.size(); ++j)
      cand.emplace_back(dist(pa[i], pb[j]), static_cast<int>(i), static_cast<int>(j));
  std::sort(cand.begin(), cand.end());
  std::vector<char> used_a(ca.size(), 0), used_b(cb.size(), 0);
  for (const auto& [d, i, j] : cand)
    if (!used_a[i] && !used_b[j]) used_a[i] = used_b[j] = 1;
  int restored = 0;
  for (std::size_t i = 0; i < ca.size(); ++i)
    if (!used_a[i]) {
      for (int t : ca[i]) keep_a[t] = 1;
      ++restored;
    }
  for (std::size_t j = 0; j < cb.size(); ++j)
    if (!used_b[j]) {
      for (int t : cb[j]) keep_b[t] = 1;
      ++restored;
    }
  return restored;
}

/// Kept part of `m` and the loops opened by the cut (loops made of edges that
/// were interior in `m`), in the kept part's vertex numbering.
void kept_part(const ElementMesh& m, const std::vector<char>& keep, ElementMesh& part,
               std::vector<std::vector<int>>& cut_loops, bool& ok) {
  std::vector<int> tris;
  for (std::size_t t = 0; t < m.tris.size(); ++t)
    if (keep[t]) tris.push_back(static_cast<int>(t));
  part = extract_triangles(m, tris);
  // Original border edges (directed, in the original numbering) mapped by position.
  std::unordered_set<std::uint64_t> orig_border;
  {
    std::unordered_map<std::uint64_t, int> cnt;
    for (const Tri& t : m.tris)
      for (int k = 0; k < 3; ++k) ++cnt[ukey(t[k], t[(k + 1) % 3])];
    for (auto& e : cnt)
      if (e.second == 1) orig_border.insert(e.first);
  }
  // Map part vertices back to original ids (extract_triangles numbers in first-use order).
  std::vector<int> back(part.points.size(), -1);
  {
    std::unordered_map<int, int> seen;
    int n = 0;
    for (int t : tris)
      for (int v : m.tris[t])
        if (!seen.count(v)) seen[v] = n, back[n++] = v;
  }
  std::vector<std::vector<int>> loops;
  ok = boundary_loops(part, loops);
  cut_loops.clear();
  for (auto& l : loops) {
    const bool original = orig_border.count(ukey(back[l[0]], back[l[1 % l.size()]])) > 0;
    if (!original) cut_loops.push_back(l);
  }
}

P3 loop_centroid(const ElementMesh& m, const std::vector<int>& l) {
  P3 c{0, 0, 0};
  for (int v : l)
    for (int d = 0; d < 3; ++d) c[d] += m.points[v][d] / static_cast<double>(l.size());
  return c;
}
// Mean distance of a loop's vertices from its centroid.
double loop_radius(const ElementMesh& m, const std::vector<int>& l, const P3& c) {
  double r = 0;
  for (int v : l) r += dist(m.points[v], c);
  return l.empty() ? 0 : r / static_cast<double>(l.size());
}
// Newell area vector of a loop (twice its vector area; right-hand rule along
// the loop's order).
P3 loop_area_vector(const ElementMesh& m, const std::vector<int>& l) {
  return newell_normal(l.size(), [&](std::size_t k) -> const P3& { return m.points[l[k]]; });
}
// Why loop i of A and loop j of B (as cut, before B is reversed) cannot be
// zipped, or "" if they can (see MergeOptions::max_loop_offset). A's loop runs
// with A's kept part on its left, so its area vector points back into A; B's
// points back into B: facing cuts have opposite area vectors, and the axis
// n = (nb - na)/|..| points from A's cut towards B's kept part. The offset is
// split along n: sideways it must stay under max_loop_offset x r; along n
// (a gap between the cuts, or an overlap when negative) under twice that.
std::string loop_pair_mismatch(const ElementMesh& pa, const std::vector<int>& la, const ElementMesh& pb,
                               const std::vector<int>& lb, const MergeOptions& opt) {
  const double kPi = 3.14159265358979323846;
  const P3 ca = loop_centroid(pa, la), cb = loop_centroid(pb, lb);
  const double ra = loop_radius(pa, la, ca), rb = loop_radius(pb, lb, cb), r = std::max(ra, rb);
  if (opt.max_loop_radius_ratio > 0 && std::min(ra, rb) * opt.max_loop_radius_ratio < r)
    return "misaligned loops: radii " + std::to_string(ra) + " and " + std::to_string(rb);
  const P3 na = loop_area_vector(pa, la), nb = loop_area_vector(pb, lb);
  const double len_a = dist(na, P3{0, 0, 0}), len_b = dist(nb, P3{0, 0, 0});
  P3 axis{0, 0, 0};
  if (len_a > 0 && len_b > 0) {
    const double cosang = -(na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2]) / (len_a * len_b);
    if (opt.max_loop_angle_deg > 0 && cosang < std::cos(opt.max_loop_angle_deg * kPi / 180.0))
      return "misaligned loops: normals " + std::to_string(std::acos(std::clamp(cosang, -1.0, 1.0)) * 180.0 / kPi) +
             " degrees apart";
    for (int d = 0; d < 3; ++d) axis[d] = nb[d] / len_b - na[d] / len_a;
    const double l = dist(axis, P3{0, 0, 0});
    if (l > 0)
      for (double& x : axis) x /= l;
  }
  if (opt.max_loop_offset > 0 || opt.max_loop_gap > 0) {
    const P3 off{cb[0] - ca[0], cb[1] - ca[1], cb[2] - ca[2]};
    const double along = off[0] * axis[0] + off[1] * axis[1] + off[2] * axis[2];
    const double side = dist(off, P3{along * axis[0], along * axis[1], along * axis[2]});
    if ((opt.max_loop_offset > 0 && side > opt.max_loop_offset * r) ||
        (opt.max_loop_gap > 0 && std::abs(along) > opt.max_loop_gap * r))
      return "misaligned loops: centroids " + std::to_string(side) + " apart sideways and " + std::to_string(along) +
             " along the cut normal, loop radius " + std::to_string(r);
  }
  return "";
}
std::size_t element_self_intersections(const ElementMesh& m) {
  if (m.tris.empty()) return 0;
  Mesh mesh;
  mesh_from_elements({m}, mesh);
  SelfIntersectionOptions so;
  so.parallel = false;  // called from parallel quilting work; the count is the same
  return count_self_intersections(mesh, so);
}
}  // namespace

namespace {
// Where a stitch crossed itself because the two cut ends overlap (A's kept
// part reaches past B's cut into B's kept part: the loops face each other but
// lie a little behind one another along the thread, and the end rings of
// the two tubes run through each other), B's kept triangles near each such
// loop pair that lie behind A's cut plane (centroid less than half a mean
// edge of B in front of A's loop, along the axis from A's cut towards B's
// kept part, and within two loop radii of that axis) are deleted, so that the
// two ends abut and the zip bridges a gap instead of folding back. Writes the
// trimmed labelling of B into `out` (a copy of keep_b) and returns the
// number of triangles deleted. Our addition (issue #8): the paper's cut paths
// are only "close to each other".
std::size_t trim_overlapping_ends(const ElementMesh& pa, const std::vector<std::vector<int>>& la, const ElementMesh& pb,
                                  const std::vector<std::vector<int>>& lb, const std::vector<int>& pair_of,
                                  const ElementMesh& b, const std::vector<char>& keep_b, std::vector<char>& out) {
  out = keep_b;
  const double margin = 0.5 * mean_edge(b);
  std::size_t deleted = 0;
  for (std::size_t i = 0; i < la.size(); ++i) {
    const std::vector<int>& l2 = lb[static_cast<std::size_t>(pair_of[i])];
    const P3 ca = loop_centroid(pa, la[i]), cb = loop_centroid(pb, l2);
    const double r = std::max(loop_radius(pa, la[i], ca), loop_radius(pb, l2, cb));
    const P3 na = loop_area_vector(pa, la[i]), nb = loop_area_vector(pb, l2);
    const double len_a = dist(na, P3{0, 0, 0}), len_b = dist(nb, P3{0, 0, 0});
    if (!(len_a > 0 && len_b > 0 && r > 0)) continue;
    P3 axis;
    for (int d = 0; d < 3; ++d) axis[d] = nb[d] / len_b - na[d] / len_a;
    const double l = dist(axis, P3{0, 0, 0});
    if (!(l > 0)) continue;
    for (double& x : axis) x /= l;
    for (std::size_t t = 0; t < b.tris.size(); ++t) {
      if (!out[t]) continue;
      const P3 c = centroid(b, b.tris[t]);
      const P3 off{c[0] - ca[0], c[1] - ca[1], c[2] - ca[2]};
      const double along = off[0] * axis[0] + off[1] * axis[1] + off[2] * axis[2];
      const double side = dist(off, P3{along * axis[0], along * axis[1], along * axis[2]});
      if (along < margin && along > -4 * r && side < 2 * r) out[t] = 0, ++deleted;
    }
  }
  return deleted;
}

/// Pairs the cut loops of A with those of B greedily by centroid distance:
/// pair_of[i] = the loop of B zipped to loop i of A.
std::vector<int> pair_loops(const ElementMesh& pa, const std::vector<std::vector<int>>& la, const ElementMesh& pb,
                            const std::vector<std::vector<int>>& lb) {
  std::vector<std::tuple<double, int, int>> cand;
  for (std::size_t i = 0; i < la.size(); ++i)
    for (std::size_t j = 0; j < lb.size(); ++j)
      cand.emplace_back(dist(loop_centroid(pa, la[i]), loop_centroid(pb, lb[j])), static_cast<int>(i),
                        static_cast<int>(j));
  std::sort(cand.begin(), cand.end());
  std::vector<int> pair_of(la.size(), -1);
  std::vector<char> bused(lb.size(), 0);
  for (auto& [d, i, j] : cand)
    if (pair_of[i] < 0 && !bused[j]) pair_of[i] = j, bused[j] = 1;
  return pair_of;
}

/// Zips loop A to loop B (both as vertex indices of `merged`, B reversed)
/// with a strip of triangles, from B's vertex nearest A's first, always
/// advancing on the side whose next vertex is nearer the other's current one.
void zip_loops(ElementMesh& merged, const std::vector<int>& A, const std::vector<int>& B) {
  const int na = static_cast<int>(A.size()), nb = static_cast<int>(B.size());
  auto P = [&](int v) { return merged.points[v]; };
  int j0 = 0;
  for (int j = 1; j < nb; ++j)
    if (dist(P(A[0]), P(B[j])) < dist(P(A[0]), P(B[j0]))) j0 = j;
  int ia = 0, ib = 0;
  auto a_at = [&](int k) { return A[k % na]; };
  auto b_at = [&](int k) { return B[(j0 + k) % nb]; };
  while (ia < na || ib < nb) {
    bool adv_a;
    if (ia == na)
      adv_a = false;
    else if (ib == nb)
      adv_a = true;
    else
      adv_a = dist(P(a_at(ia + 1)), P(b_at(ib))) <= dist(P(a_at(ia)), P(b_at(ib + 1)));
    if (adv_a) {
      merged.tris.push_back({a_at(ia + 1), a_at(ia), b_at(ib)});
      ++ia;
    } else {
      merged.tris.push_back({b_at(ib), b_at(ib + 1), a_at(ia)});
      ++ib;
    }
  }
}

/// The axis of a loop pair (difference of their unit area vectors) when
/// MergeOptions::average_across_axis_only, else zero.
P3 loop_pair_axis(const ElementMesh& pa, const std::vector<int>& la, const ElementMesh& pb,
                  const std::vector<int>& lb, const MergeOptions& opt) {
  P3 axis{0, 0, 0};
  if (opt.average_across_axis_only) {
    const P3 na = loop_area_vector(pa, la), nb = loop_area_vector(pb, lb);
    const double len_a = dist(na, P3{0, 0, 0}), len_b = dist(nb, P3{0, 0, 0});
    if (len_a > 0 && len_b > 0) {
      for (int d = 0; d < 3; ++d) axis[d] = nb[d] / len_b - na[d] / len_a;
      const double l = dist(axis, P3{0, 0, 0});
      for (double& x : axis) x = l > 0 ? x / l : 0.0;
    }
  }
  return axis;
}

/// "Average boundary points" as position constraints (eq. 5): each loop
/// vertex pulled to the midpoint with its nearest vertex on the other loop,
/// less the midpoint's component along `axis`.
void average_boundary_constraints(const ElementMesh& merged, const std::vector<int>& A, const std::vector<int>& B,
                                  const P3& axis, std::vector<DeformConstraint>& cons) {
  auto P = [&](int v) { return merged.points[v]; };
  auto nearest = [&](int v, const std::vector<int>& L) {
    int best = L[0];
    for (int u : L)
      if (dist(P(v), P(u)) < dist(P(v), P(best))) best = u;
    return best;
  };
  auto target = [&](const P3& p, const P3& q) {
    P3 h{(q[0] - p[0]) / 2, (q[1] - p[1]) / 2, (q[2] - p[2]) / 2};
    const double al = h[0] * axis[0] + h[1] * axis[1] + h[2] * axis[2];
    for (int d = 0; d < 3; ++d) h[d] -= al * axis[d];
    return P3{p[0] + h[0], p[1] + h[1], p[2] + h[2]};
  };
  for (int v : A) cons.push_back({{v, v, v}, {1, 0, 0}, target(P(v), P(nearest(v, B)))});
  for (int v : B) cons.push_back({{v, v, v}, {1, 0, 0}, target(P(v), P(nearest(v, A)))});
}

/// Why the zipped element is refused on topology ("" if it is not): new
/// borders, a non-manifold border, or an opened closed element.
std::string zip_topology_refusal(const ElementMesh& a, const ElementMesh& b, const ElementMesh& merged) {
  const std::size_t border_before = count_border_edges(a) + count_border_edges(b);
  if (count_border_edges(merged) > border_before) return "stitching would open new borders";
  if (!is_manifold_oriented(merged)) return "stitched element is not manifold (border)";
  if (border_before == 0 && !is_closed_oriented(merged))
    return "stitched element is not closed and consistently oriented";
  return "";
}

// Zips the kept parts of A and B (labellings keep_a, keep_b) into `r` (see
// merge_elements; Zhou et al. 2006 s.2.7): their cut loops paired and
// checked, zipped, the zip deformed towards the averaged boundary points
// (eq. 5) with the points outside the overlap locked. If `trimmed` is given
// and the stitch is refused for crossing itself, the trimmed labelling of B
// is written there (see trim_overlapping_ends).
void stitch_kept_parts(const ElementMesh& a, const std::vector<char>& keep_a, const ElementMesh& b,
                       const std::vector<char>& keep_b, const RegionFn& region, const MergeOptions& opt,
                       MergeResult& r, std::vector<char>* trimmed) {
  ElementMesh pa, pb;
  std::vector<std::vector<int>> la, lb;
  bool oka = false, okb = false;
  kept_part(a, keep_a, pa, la, oka);
  kept_part(b, keep_b, pb, lb, okb);
  if (!oka || !okb) {
    r.reason = "cut border is not a set of simple loops";
    return;
  }
  if (la.empty() || la.size() != lb.size()) {
    r.coincident = la.empty() && lb.empty();
    r.reason = "cuts opened " + std::to_string(la.size()) + " and " + std::to_string(lb.size()) + " loops";
    return;
  }
  const std::vector<int> pair_of = pair_loops(pa, la, pb, lb);
  for (std::size_t i = 0; i < la.size(); ++i) {
    const std::string why = loop_pair_mismatch(pa, la[i], pb, lb[pair_of[i]], opt);
    if (!why.empty()) {
      r.reason = why;
      return;
    }
  }
  ElementMesh merged = pa;
  const int off = static_cast<int>(pa.points.size());
  append(merged, pb);
  std::vector<DeformConstraint> cons;
  for (std::size_t i = 0; i < la.size(); ++i) {
    const std::vector<int>& A = la[i];
    std::vector<int> B(lb[pair_of[i]].rbegin(), lb[pair_of[i]].rend());
    for (int& v : B) v += off;
    zip_loops(merged, A, B);
    const P3 axis = loop_pair_axis(pa, la[i], pb, lb[pair_of[i]], opt);
    average_boundary_constraints(merged, A, B, axis, cons);
  }
  const std::string refusal = zip_topology_refusal(a, b, merged);
  if (!refusal.empty()) {
    r.reason = refusal;
    return;
  }
  auto in_overlap = [&](const P3& p) { return region(p) == Region::kOverlap; };
  std::vector<char> locked(merged.points.size(), 0);
  for (std::size_t v = 0; v < merged.points.size(); ++v) locked[v] = !in_overlap(merged.points[v]);
  try {
    LaplacianDeformOptions lo;
    lo.mu = opt.mu;
    merged.points = laplacian_deform(merged, cons, locked, lo);
  } catch (const SolverError&) {
    // A component without constraint or lock: keep the undeformed zip.
  }
  if (opt.refuse_self_intersecting) {
    const std::size_t after = element_self_intersections(merged);
    if (after > 0) {
      const std::size_t before = element_self_intersections(pa) + element_self_intersections(pb);
      if (after > before) {
        r.reason = "self-intersecting stitch: " + std::to_string(after) + " crossing face pairs, parts had " +
                   std::to_string(before);
        if (trimmed) trim_overlapping_ends(pa, la, pb, lb, pair_of, b, keep_b, *trimmed);
        return;
      }
    }
  }
  r.stitched = true;
  r.loops = static_cast<int>(la.size());
  r.merged = std::move(merged);
}
}  // namespace

namespace {
// The kept part of closed `m` split into components, each cut loop closed by
// by cap_loop (see MergeResult::capped_b).
std::vector<ElementMesh> capped_kept_components(const ElementMesh& m, const std::vector<char>& keep) {
  std::vector<ElementMesh> out;
  std::size_t kept = 0;
  for (char k : keep) kept += k ? 1 : 0;
  if (kept == 0 || kept == m.tris.size() || count_border_edges(m) != 0) return out;
  std::vector<int> tris;
  for (std::size_t t = 0; t < m.tris.size(); ++t)
    if (keep[t]) tris.push_back(static_cast<int>(t));
  const ElementMesh part = extract_triangles(m, tris);
  std::vector<int> comp;
  const int nc = triangle_components(part, comp);
  for (int c = 0; c < nc; ++c) {
    std::vector<int> ct;
    for (std::size_t t = 0; t < part.tris.size(); ++t)
      if (comp[t] == c) ct.push_back(static_cast<int>(t));
    if (10 * ct.size() < m.tris.size()) continue;
    ElementMesh e = extract_triangles(part, ct);
    std::vector<std::vector<int>> loops;
    if (!boundary_loops(e, loops) || loops.size() != 1) continue;
    for (const std::vector<int>& l : loops) {
      cap_loop(e, l);
    }
    if (is_closed_oriented(e)) out.push_back(std::move(e));
  }
  return out;
}
}  // namespace

MergeResult merge_elements(const ElementMesh& a, Side side_a, const ElementMesh& b, Side side_b, const RegionFn& region,
                           const MergeOptions& opt) {
  check_options(opt);
  MergeResult r;
  const TriangleDistance ta(a), tb(b);
  ElementCut ca = cut_with_trees(a, ta, side_a, b, tb, side_b, region, opt, nullptr);
  r.cost_a = ca.cost;
  if (!ca.feasible) {
    r.reason = "cut of A infeasible";
    return r;
  }
  ElementCut cb = cut_with_trees(b, tb, side_b, a, ta, side_a, region, opt, &ca.keep);
  r.cost_b = cb.cost;
  if (!cb.feasible) {
    r.reason = "cut of B infeasible";
    return r;
  }
  remove_cut_islands(a, ca.terminal, ca.keep);
  remove_cut_islands(b, cb.terminal, cb.keep);
  restore_unpaired_cuts(a, ca.keep, b, cb.keep);
  std::vector<char> trimmed;
  stitch_kept_parts(a, ca.keep, b, cb.keep, region, opt, r, opt.trim_overlapping_ends ? &trimmed : nullptr);
  if (!r.stitched && !trimmed.empty() && trimmed != cb.keep) {
    MergeResult again;
    again.cost_a = r.cost_a;
    again.cost_b = r.cost_b;
    stitch_kept_parts(a, ca.keep, b, trimmed, region, opt, again, nullptr);
    if (again.stitched) {
      again.trimmed = true;
      return again;
    }
  }
  if (!r.stitched) {
    // B's kept part on its own side only (see MergeResult::capped_b).
    std::vector<char> own = trimmed.empty() ? cb.keep : trimmed;
    for (std::size_t t = 0; t < b.tris.size(); ++t)
      if (own[t] && region(centroid(b, b.tris[t])) != side_b) own[t] = 0;
    r.capped_b = capped_kept_components(b, own);
    if (r.coincident) {
      // Only parts that run on past A (at most a quarter of their vertices
      // within the match distance of A): not a second copy of a ring A
      // already completes.
      const double d = auto_match(a, b, opt);
      std::vector<ElementMesh> away;
      for (ElementMesh& e : r.capped_b) {
        std::size_t near = 0;
        for (const P3& p : e.points)
          if (ta.closest_within(p, d).distance <= d) ++near;
        if (4 * near <= e.points.size()) away.push_back(std::move(e));
      }
      r.capped_b = std::move(away);
    }
  }
  return r;
}

}  // namespace surftex
