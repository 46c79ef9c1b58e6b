// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/quilt_step.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>

#include "geometry/errors.h"
#include "geometry/timer.h"
#include "geometry/union_find.h"
#include "shell/quilting/element_correspondence.h"
#include "shell/element_clearance.h"
#include "shell/quilting/element_deformation.h"
#include "shell/quilting/element_merging.h"

namespace surftex {

int QuiltGrid::cell_of(double x, double y) const {
  const double fx = std::floor((x - x0) / cell), fy = std::floor((y - y0) / cell);
  if (!(fx >= 0 && fy >= 0 && fx < nx && fy < ny)) return -1;
  return static_cast<int>(fy) * nx + static_cast<int>(fx);
}

void QuiltStepStats::add(const QuiltStepStats& o) {
  candidates += o.candidates;
  best_cost += o.best_cost;
  pairs += o.pairs;
  related += o.related;
  pruned_normal += o.pruned_normal;
  pruned_distance += o.pruned_distance;
  pruned_projection += o.pruned_projection;
  stitched += o.stitched;
  stitch_refused += o.stitch_refused;
  stitched_trimmed += o.stitched_trimmed;
  refused_infeasible += o.refused_infeasible;
  refused_loops += o.refused_loops;
  refused_border += o.refused_border;
  refused_geometry += o.refused_geometry;
  coincident += o.coincident;
  coincident_cut_added += o.coincident_cut_added;
  for (const auto& [k, n] : o.refused_reasons) refused_reasons[k] += n;
  out_replaced += o.out_replaced;
  in_dropped += o.in_dropped;
  in_added += o.in_added;
  in_cut_added += o.in_cut_added;
  in_cut_components += o.in_cut_components;
  crossing_hits += o.crossing_hits;
  crossing_dropped += o.crossing_dropped;
  crossing_trimmed += o.crossing_trimmed;
  crossing_pieces += o.crossing_pieces;
  crossing_pushed += o.crossing_pushed;
  seconds_resolve += o.seconds_resolve;
  seconds_match += o.seconds_match;
  seconds_correspond += o.seconds_correspond;
  seconds_deform += o.seconds_deform;
  seconds_merge += o.seconds_merge;
}

namespace {
// The kind of a refusal (QuiltStepStats::refused_reasons): the reason up to
// the second ':' (first word group after a ':' kept, e.g. "misaligned loops:
// normals"), digit runs and numbers replaced by N.
std::string reason_kind(const std::string& reason) {
  std::string head = reason;
  const std::size_t c1 = reason.find(':');
  if (c1 != std::string::npos) {
    std::size_t end = reason.find_first_of("0123456789-", c1 + 2);
    if (end == std::string::npos) end = reason.size();
    head = reason.substr(0, end);
    while (!head.empty() && head.back() == ' ') head.pop_back();
  }
  std::string out;
  for (std::size_t i = 0; i < head.size(); ++i) {
    if (std::isdigit(static_cast<unsigned char>(head[i]))) {
      out += 'N';
      while (i + 1 < head.size() && (std::isdigit(static_cast<unsigned char>(head[i + 1])) || head[i + 1] == '.')) ++i;
    } else {
      out += head[i];
    }
  }
  return out;
}
// Keeps the relations (C_out, C_in) that are each other's strongest: the most
// vertex-face pairs among the relations of C_out and among those of C_in (ties:
// smaller summed eq. 1 cost, then lower index). The paper's relation ("there
// exists a pair") also links elements that merely cross (a weave's threads
// over and under each other, neighbouring chain-mail rings), and joins every
// element of the overlap into one group whose merges fail; one strongest
// partner per element is what the merge of section 2.7 can stitch.
std::vector<std::pair<int, int>> strongest_relations(ElementCorrespondences& corr) {
  std::map<std::pair<int, int>, std::pair<std::size_t, double>> strength;  // (out, in) -> (pairs, -cost)
  for (const VertexFacePair& p : corr.pairs) {
    auto& s = strength[{p.out_element, p.in_element}];
    ++s.first;
    s.second -= p.cost;
  }
  std::map<int, std::pair<std::pair<std::size_t, double>, int>> best_out, best_in;
  for (const auto& [r, st] : strength) {
    auto upd = [&](std::map<int, std::pair<std::pair<std::size_t, double>, int>>& m, int key, int other) {
      auto it = m.find(key);
      if (it == m.end() || st > it->second.first) m[key] = {st, other};
    };
    upd(best_out, r.first, r.second);
    upd(best_in, r.second, r.first);
  }
  std::vector<std::pair<int, int>> keep;
  for (const auto& [r, st] : strength)
    if (best_out[r.first].second == r.second && best_in[r.second].second == r.first) keep.push_back(r);
  std::vector<VertexFacePair> pairs;
  for (const VertexFacePair& p : corr.pairs)
    if (std::binary_search(keep.begin(), keep.end(), std::make_pair(p.out_element, p.in_element))) pairs.push_back(p);
  corr.pairs.swap(pairs);
  return keep;
}
// A thread that crosses old elements at about the same height is pushed over
// or under each crossing (issue 17: a weave's threads from two placements
// passing through each other; the paper's elements do not, and a woven thread
// goes over or under the one it crosses). Per connected cluster of hit
// triangles: its centre c (xy mean of their corners) and xy radius rc; the new
// thread's height z_n and half-thickness r_n there (mean and half the z
// extent of its vertices within rc of c), the old ones' z_o and r_o likewise;
// the thread's vertices within `reach` = rc + 3 (r_n + r_o) of c move in z by
// dz (1 - (d / reach)^2)^2, dz taking z_n to z_o +- (r_n + r_o + clearance) on
// the side it already lies on (our simplification of a Laplacian deformation
// with those heights as constraints, section 2.6). Returns false if a
// cluster has no old vertex near it.
bool push_over_under(ElementMesh& m, const std::vector<char>& hit, const std::vector<ElementMesh>& elements,
                     const std::vector<char>& alive, double clearance) {
  std::vector<int> ht;
  for (std::size_t t = 0; t < hit.size(); ++t)
    if (hit[t]) ht.push_back(static_cast<int>(t));
  const ElementMesh hm = extract_triangles(m, ht);
  std::vector<int> comp;
  const int nc = triangle_components(hm, comp);
  std::vector<std::vector<int>> verts(static_cast<std::size_t>(nc));
  for (std::size_t t = 0; t < hm.tris.size(); ++t)
    for (int v : hm.tris[t]) verts[static_cast<std::size_t>(comp[t])].push_back(v);
  std::vector<double> dz(m.points.size(), 0.0);
  for (const std::vector<int>& vs : verts) {
    double cx = 0, cy = 0;
    for (int v : vs) cx += hm.points[static_cast<std::size_t>(v)][0] / static_cast<double>(vs.size()), cy += hm.points[static_cast<std::size_t>(v)][1] / static_cast<double>(vs.size());
    double rc = 0;
    for (int v : vs) rc = std::max(rc, std::hypot(hm.points[static_cast<std::size_t>(v)][0] - cx, hm.points[static_cast<std::size_t>(v)][1] - cy));
    // Mean and half extent in z of points within rc of c.
    auto near_z = [&](const std::vector<P3>& pts, double& sum, double& lo, double& hi, std::size_t& n) {
      for (const P3& q : pts)
        if (std::hypot(q[0] - cx, q[1] - cy) <= rc) sum += q[2], lo = std::min(lo, q[2]), hi = std::max(hi, q[2]), ++n;
    };
    double so = 0, lo_o = 1e300, hi_o = -1e300, sn = 0, lo_n = 1e300, hi_n = -1e300;
    std::size_t no = 0, nn = 0;
    for (std::size_t e = 0; e < elements.size(); ++e)
      if (alive[e]) near_z(elements[e].points, so, lo_o, hi_o, no);
    near_z(m.points, sn, lo_n, hi_n, nn);
    if (no == 0 || nn == 0) return false;
    const double zo = so / static_cast<double>(no), zn = sn / static_cast<double>(nn);
    const double ro = 0.5 * (hi_o - lo_o), rn = 0.5 * (hi_n - lo_n), need = ro + rn + clearance;
    const double side = zn >= zo ? 1.0 : -1.0;
    const double shift = zo + side * need - zn;
    if (side * shift <= 0) continue;  // already clear in height
    const double reach = rc + 3 * (rn + ro);
    for (std::size_t v = 0; v < m.points.size(); ++v) {
      const double d = std::hypot(m.points[v][0] - cx, m.points[v][1] - cy);
      if (d >= reach) continue;
      const double w = 1 - (d / reach) * (d / reach);
      const double add = shift * w * w;
      if (std::abs(add) > std::abs(dz[v])) dz[v] = add;  // the larger push where two bumps meet
    }
  }
  for (std::size_t v = 0; v < m.points.size(); ++v) m.points[v][2] += dz[v];
  return true;
}

// QuiltStepOptions::resolve_crossings: of the elements about to be added,
// those that hit an element already there (or one added before them) are
// dropped or trimmed; returns what is to be added.
std::vector<ElementMesh> resolve_crossings(const std::vector<ElementMesh>& elements, const std::vector<char>& alive,
                                           std::vector<ElementMesh> adds, const QuiltStepOptions& opt,
                                           QuiltStepStats& stats) {
  // Only the old triangles near the new elements can be hit: the collider
  // holds those meeting the new elements' xy box grown by the clearance
  // (unbounded in z: push_over_under moves a thread in z only).
  const double inf = std::numeric_limits<double>::infinity();
  P3 lo{inf, inf, -inf}, hi{-inf, -inf, inf};
  for (const ElementMesh& m : adds)
    for (const P3& p : m.points)
      for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double grow = std::max(0.0, opt.clearance) * (1 + 1e-9) + 1e-12;
  for (int k = 0; k < 2; ++k) lo[k] -= grow, hi[k] += grow;
  ElementCollider old(elements, alive, lo, hi);
  std::vector<ElementMesh> keep;
  for (ElementMesh& m : adds) {
    const std::vector<char> hit = old.hits(m, -1, opt.clearance);
    const std::size_t nhit = static_cast<std::size_t>(std::count(hit.begin(), hit.end(), 1));
    if (nhit == 0) {
      old.add(m, -2);
      keep.push_back(std::move(m));
      continue;
    }
    ++stats.crossing_hits;
    const bool compact = is_compact_element(m);
    if (!compact && opt.push_over_under) {  // over or under the crossing threads, if that clears them
      ElementMesh pushed = m;
      if (push_over_under(pushed, hit, elements, alive, opt.clearance)) {
        if (!old.any_hit(pushed, -1, opt.clearance)) {
          ++stats.crossing_pushed;
          old.add(pushed, -2);
          keep.push_back(std::move(pushed));
          continue;
        }
      }
    }
    std::vector<ElementMesh> pieces;
    if (!compact) pieces = trim_and_cap(m, hit, opt.trim_rings, std::max<std::size_t>(24, m.tris.size() / 10));
    // A piece is kept only if it is clear of the others itself (its cap may reach them).
    std::size_t kept = 0;
    for (ElementMesh& p : pieces) {
      if (old.any_hit(p, -1, opt.clearance)) continue;
      old.add(p, -2);
      keep.push_back(std::move(p));
      ++kept;
    }
    if (kept == 0) {
      ++stats.crossing_dropped;
    } else {
      ++stats.crossing_trimmed;
      stats.crossing_pieces += kept;
    }
  }
  return keep;
}
}  // namespace

QuiltMatch match_swatch_placement(const Swatch& swatch, const TriangleDistance& swatch_tree, const QuiltGrid& grid,
                                  const std::vector<ElementMesh>& elements, const std::vector<char>& alive,
                                  std::mt19937_64& rng, const QuiltStepOptions& opt, const QuiltPlacement* near) {
  if (!std::isfinite(opt.clearance))
    throw InvalidInputError("quilt_step: clearance must be finite (" + std::to_string(opt.clearance) + ")");
  if (opt.trim_rings < 0 || opt.trim_rings > 16)
    throw InvalidInputError("quilt_step: trim_rings must be in [0, 16] (" + std::to_string(opt.trim_rings) + ")");
  if (opt.subcell_levels < 0 || opt.subcell_levels > 8)
    throw InvalidInputError("quilt_step: subcell_levels must be in [0, 8] (" + std::to_string(opt.subcell_levels) + ")");
  if (opt.max_match_vertices < 1)
    throw InvalidInputError("quilt_step: max_match_vertices must be >= 1 (" + std::to_string(opt.max_match_vertices) + ")");
  QuiltMatch res;
  const double c = grid.cell;
  const int sx = std::max(1, static_cast<int>(std::ceil(swatch.length() / c - 1e-9)));
  const int sy = std::max(1, static_cast<int>(std::ceil(swatch.width() / c - 1e-9)));
  int pi0 = grid.nx, pi1 = -1, pj0 = grid.ny, pj1 = -1;
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i)
      if (grid.subpatch[j * grid.nx + i]) pi0 = std::min(pi0, i), pi1 = std::max(pi1, i), pj0 = std::min(pj0, j), pj1 = std::max(pj1, j);
  if (pi1 < 0) throw InvalidInputError("quilt_step: empty output sub-patch");
  if (pi1 - pi0 + 1 > sx || pj1 - pj0 + 1 > sy)
    throw InvalidInputError("quilt_step: the output sub-patch (" + std::to_string(pi1 - pi0 + 1) + "x" +
                            std::to_string(pj1 - pj0 + 1) + " cells) is larger than the swatch (" +
                            std::to_string(sx) + "x" + std::to_string(sy) + " cells)");

  // --- 2.4 Geometry matching: output vertices in P_out, with normals.
  std::vector<P3> mv, mn;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    if (!alive[e]) continue;
    const ElementMesh& m = elements[e];
    std::vector<P3> vn;
    for (std::size_t v = 0; v < m.points.size(); ++v) {
      const int cc = grid.cell_of(m.points[v][0], m.points[v][1]);
      if (cc < 0 || !grid.subpatch[cc]) continue;
      if (vn.empty()) vn = vertex_normals(m);
      mv.push_back(m.points[v]);
      mn.push_back(vn[v]);
    }
  }
  if (static_cast<int>(mv.size()) > opt.max_match_vertices) {
    std::vector<P3> a, b;
    const double step = static_cast<double>(mv.size()) / opt.max_match_vertices;
    for (int k = 0; k < opt.max_match_vertices; ++k) {
      const std::size_t idx = static_cast<std::size_t>(k * step);
      a.push_back(mv[idx]);
      b.push_back(mn[idx]);
    }
    mv.swap(a);
    mn.swap(b);
  }
  const auto fn = face_normals(swatch.mesh);
  std::vector<std::pair<int, int>> cand;
  if (near)  // only the given grid translation (then refined)
    cand.emplace_back(near->oi, near->oj);
  else
    for (int oj = pj1 - sy + 1; oj <= pj0; ++oj)
      for (int oi = pi1 - sx + 1; oi <= pi0; ++oi) cand.emplace_back(oi, oj);
  auto translation = [&](int oi, int oj) {
    return P3{grid.x0 + oi * c - swatch.bbox_min[0], grid.y0 + oj * c - swatch.bbox_min[1], 0.0};
  };
  // E(t) (eq. 3): eq. 1 with the closest face (see element_correspondence.h), eq. 2, summed.
  // Every term is >= 1, so the partial sum only grows: once it passes `bound`
  // the candidate cannot be chosen and the partial sum is returned (a value
  // above the bound; the chosen candidates' costs are exact, the same bytes).
  auto match_cost = [&](const P3& t, double bound) {
    double e = 0;
    int hint = -1;  // consecutive vertices are neighbours: the last hit bounds the next search
    for (std::size_t v = 0; v < mv.size(); ++v) {
      const auto h = swatch_tree.closest({mv[v][0] - t[0], mv[v][1] - t[1], mv[v][2] - t[2]}, hint);
      hint = h.tri;
      const P3& nf = fn[h.tri];
      const double dn = std::sqrt((mn[v][0] - nf[0]) * (mn[v][0] - nf[0]) + (mn[v][1] - nf[1]) * (mn[v][1] - nf[1]) +
                                  (mn[v][2] - nf[2]) * (mn[v][2] - nf[2]));
      e += (1 + opt.lambda * h.distance) * (1 + dn);
      if (e > bound) return e;
    }
    return e;
  };
  // A candidate is eligible when within choice_tolerance of the best; the best
  // cost seen so far (any thread) bounds that from above, so a candidate past
  // it is dropped early whatever order the threads run in.
  std::vector<double> cost(cand.size(), 0.0);
  std::atomic<double> best_seen{std::numeric_limits<double>::infinity()};
  auto eligible_bound = [&](double b) { return b * (1 + opt.choice_tolerance) + 1e-12; };
  if (!mv.empty())
    tbb::parallel_for(std::size_t(0), cand.size(), [&](std::size_t k) {
      const double bound = eligible_bound(best_seen.load(std::memory_order_relaxed));
      const double c = match_cost(translation(cand[k].first, cand[k].second), bound);
      cost[k] = c;
      if (c > bound) return;  // dropped early: above the final bound too
      double prev = best_seen.load(std::memory_order_relaxed);
      while (c < prev && !best_seen.compare_exchange_weak(prev, c, std::memory_order_relaxed)) {
      }
    });
  const double best = *std::min_element(cost.begin(), cost.end());
  std::vector<std::size_t> eligible;
  for (std::size_t k = 0; k < cand.size(); ++k)
    if (cost[k] <= eligible_bound(best)) eligible.push_back(k);
  const std::size_t pick = near ? 0 : eligible[static_cast<std::size_t>(rng() % eligible.size())];
  const int oi = cand[pick].first, oj = cand[pick].second;
  const P3 t = translation(oi, oj);
  double picked_cost = cost[pick];
  // Sub-cell refinement (see QuiltStepOptions::subcell_levels): a 5 x 5
  // pattern search, deterministic (lowest cost, ties: first in row order).
  double dx = 0, dy = 0;
  if (!mv.empty() && opt.subcell_levels > 0) {
    // Level 0: 5 x 5 offsets at steps of c/4 (covers +-c/2); then 3 x 3 at half the step each level.
    double step = c / 4;
    for (int level = 0; level < opt.subcell_levels; ++level, step *= 0.5) {
      const int reach = level == 0 ? 2 : 1;
      std::vector<std::array<double, 2>> offs;
      for (int b = -reach; b <= reach; ++b)
        for (int a = -reach; a <= reach; ++a) {
          const double x = dx + a * step, y = dy + b * step;
          if ((a || b) && std::abs(x) <= 0.5 * c + 1e-12 && std::abs(y) <= 0.5 * c + 1e-12) offs.push_back({x, y});
        }
      std::vector<double> oc(offs.size());
      tbb::parallel_for(std::size_t(0), offs.size(), [&](std::size_t k) {
        oc[k] = match_cost({t[0] + offs[k][0], t[1] + offs[k][1], t[2]}, picked_cost);  // only a lower one wins
      });
      res.candidates += offs.size();
      double bx = dx, by = dy;
      for (std::size_t k = 0; k < offs.size(); ++k)
        if (oc[k] < picked_cost) picked_cost = oc[k], bx = offs[k][0], by = offs[k][1];
      dx = bx;
      dy = by;
    }
  }
  res.candidates += cand.size();
  res.vertices = mv.size();
  res.cost = picked_cost;
  res.placement = {oi, oj, dx, dy};
  return res;

}

namespace {

/// One quilt step's state, stage to stage: the placement, the placed input
/// elements M_in(t), the overlap, the correspondences and their groups, and
/// what the step commits at the end.
struct QuiltStepState {
  QuiltStepState(const Swatch& sw, QuiltGrid& g, std::vector<ElementMesh>& el, std::vector<char>& al,
                 const QuiltStepOptions& o, QuiltStepStats& st)
      : swatch(sw), grid(g), elements(el), alive(al), opt(o), stats(st) {}
  const Swatch& swatch;
  QuiltGrid& grid;
  std::vector<ElementMesh>& elements;  // M_out
  std::vector<char>& alive;
  const QuiltStepOptions& opt;
  QuiltStepStats& stats;
  int sx = 0, sy = 0;  // footprint in cells
  int oi = 0, oj = 0;  // its first cell
  double dx = 0, dy = 0;
  std::vector<ElementMesh> placed;     // M_in(t)
  std::vector<char> processed_before;  // the grid's processed cells before this step
  std::vector<int> near;               // live output elements near the footprint
  ElementCorrespondences corr;
  std::vector<std::pair<int, int>> related;  // (output, input) element pairs
  int no = 0, ni = 0;                        // output and input elements
  UnionFind<int> sets;                       // over outputs, then inputs
  std::vector<int> root_of;                  // per output element: its set's root (-1: unrelated)
  std::map<int, std::pair<std::vector<int>, std::vector<int>>> groups;  // root -> (outs, ins)
  std::vector<char> add_in;                                            // per input: added as is
  std::vector<std::pair<int, ElementMesh>> replacements;               // output elements replaced
  std::vector<ElementMesh> cut_inputs;  // refused inputs' closed kept parts (keep_cut_refused_inputs)
  double t_deform = 0, t_merge = 0;

  bool in_footprint_cell(int cc) const {
    const int i = cc % grid.nx, j = cc / grid.nx;
    return i >= oi && i < oi + sx && j >= oj && j < oj + sy;
  }
  bool in_overlap(const P3& p) const {
    const int cc = grid.cell_of(p[0], p[1]);
    return cc >= 0 && processed_before[cc] && in_footprint_cell(cc);
  }
  Region region(const P3& p) const {
    const int cc = grid.cell_of(p[0], p[1]);
    if (cc < 0) return Region::kNone;
    if (!processed_before[cc]) return Region::kNew;
    return in_footprint_cell(cc) ? Region::kOverlap : Region::kOld;
  }
  bool entirely_in_overlap(const ElementMesh& m) const {
    for (const P3& p : m.points)
      if (!in_overlap(p)) return false;
    return true;
  }
};

/// The placed input elements M_in(t): the swatch's elements moved by t.
void place_input_elements(QuiltStepState& s, const P3& t) {
  const Swatch& swatch = s.swatch;
  std::vector<std::vector<int>> etris(swatch.elements.size());
  for (std::size_t f = 0; f < swatch.face_element.size(); ++f) etris[swatch.face_element[f]].push_back(static_cast<int>(f));
  s.placed.resize(swatch.elements.size());
  for (std::size_t e = 0; e < s.placed.size(); ++e) {
    s.placed[e] = extract_triangles(swatch.mesh, etris[e]);
    for (P3& p : s.placed[e].points)
      for (int d = 0; d < 3; ++d) p[d] += t[d];
  }
  s.processed_before = s.grid.processed;
}

/// Live output elements whose bounding box meets the footprint.
void find_near_outputs(QuiltStepState& s) {
  const double c = s.grid.cell;
  const double fx0 = s.grid.x0 + s.oi * c, fy0 = s.grid.y0 + s.oj * c, fx1 = fx0 + s.sx * c, fy1 = fy0 + s.sy * c;
  for (std::size_t e = 0; e < s.elements.size(); ++e) {
    if (!s.alive[e]) continue;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (const P3& p : s.elements[e].points)
      for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
    if (hi[0] >= fx0 && lo[0] <= fx1 && hi[1] >= fy0 && lo[1] <= fy1) s.near.push_back(static_cast<int>(e));
  }
}

/// Zhou et al. 2006 s.2.5, element correspondences: vertex-face pairs in the
/// overlap between the near output elements and the placed inputs, and the
/// related element pairs (the strongest one per element with one_to_one).
void correspond_elements(QuiltStepState& s) {
  if (!s.near.empty()) {
    CorrespondenceOptions co;
    co.lambda = s.opt.lambda;
    co.prune_factor = s.opt.prune_factor;
    s.corr = find_element_correspondences(s.elements, s.near, s.placed,
                                          [&s](const P3& p) { return s.in_overlap(p); }, co);
    s.related = s.opt.one_to_one ? strongest_relations(s.corr) : s.corr.related;
  }
  s.stats.pairs += s.corr.pairs.size();
  s.stats.related += s.related.size();
  s.stats.pruned_normal += s.corr.pruned_normal;
  s.stats.pruned_distance += s.corr.pruned_distance;
  s.stats.pruned_projection += s.corr.pruned_projection;
}

/// Groups of related elements (connected components of the relation):
/// union-find over the output elements, then the input elements.
void group_related(QuiltStepState& s) {
  s.no = static_cast<int>(s.elements.size());
  s.ni = static_cast<int>(s.placed.size());
  const int no = s.no, ni = s.ni;
  s.sets.reset(no + ni);
  for (auto& r : s.related) s.sets.unite(r.first, no + r.second);
  std::vector<char> in_related(ni, 0), out_related(no, 0);
  for (auto& r : s.related) out_related[r.first] = 1, in_related[r.second] = 1;
  s.root_of.assign(no, -1);
  for (int e = 0; e < no; ++e)
    if (out_related[e]) s.groups[s.root_of[e] = s.sets.find(e)].first.push_back(e);
  for (int e = 0; e < ni; ++e)
    if (in_related[e]) s.groups[s.sets.find(no + e)].second.push_back(e);
}

/// Zhou et al. 2006 s.2.6, element deformation of both sides of a group
/// (equations 5 and 6): each pair pulls its output vertex and input face
/// point to their midpoint; output vertices outside the overlap stay put.
/// Returns the deformed output elements; the inputs are deformed in place.
std::map<int, ElementMesh> deform_group(QuiltStepState& s, int root) {  // (writes s.placed of its inputs only)
  std::map<int, std::vector<DeformConstraint>> cout_, cin_;
  for (const VertexFacePair& p : s.corr.pairs) {
    if (s.root_of[p.out_element] != root) continue;
    const P3& v = s.elements[p.out_element].points[p.vertex];
    const P3 cpt{(v[0] + p.closest[0]) / 2, (v[1] + p.closest[1]) / 2, (v[2] + p.closest[2]) / 2};
    cout_[p.out_element].push_back({{p.vertex, p.vertex, p.vertex}, {1, 0, 0}, cpt});
    const Tri& f = s.placed[p.in_element].tris[p.face];
    cin_[p.in_element].push_back({{f[0], f[1], f[2]}, {p.bary[0], p.bary[1], p.bary[2]}, cpt});
  }
  LaplacianDeformOptions lo;
  lo.mu = s.opt.mu;
  std::map<int, ElementMesh> deformed_out;
  for (auto& [e, cons] : cout_) {
    ElementMesh m = s.elements[e];
    std::vector<char> locked(m.points.size());
    for (std::size_t v = 0; v < m.points.size(); ++v) locked[v] = !s.in_overlap(m.points[v]);
    try {
      m.points = laplacian_deform(m, cons, locked, lo);
    } catch (const SolverError&) {
    }
    deformed_out[e] = std::move(m);
  }
  for (auto& [e, cons] : cin_) {
    try {
      s.placed[e].points = laplacian_deform(s.placed[e], cons, {}, lo);
    } catch (const SolverError&) {
    }
  }
  return deformed_out;
}

/// What merging one group produces, kept apart so that groups can be merged
/// in parallel and their results taken in group order (the same bytes for
/// any thread count).
struct GroupOutcome {
  QuiltStepStats stats;
  std::vector<std::pair<int, ElementMesh>> replacements;  // output elements replaced
  std::vector<ElementMesh> cut_inputs;                    // refused inputs' closed kept parts
  double t_deform = 0, t_merge = 0;                       // thread seconds
};

/// An input element not merged: its closed kept parts are added (counted in
/// `kept`) when asked for and there are any, else it is dropped.
void keep_capped_or_drop(const QuiltStepState& s, MergeResult& r, std::size_t& kept, GroupOutcome& out) {
  if (s.opt.keep_cut_refused_inputs && !r.capped_b.empty()) {
    ++kept;
    out.stats.in_cut_components += r.capped_b.size();
    for (ElementMesh& part : r.capped_b) out.cut_inputs.push_back(std::move(part));
  } else {
    ++out.stats.in_dropped;
  }
}

/// Counts a refused stitch under its reason.
void count_refusal(QuiltStepStats& stats, const std::string& reason) {
  ++stats.stitch_refused;
  ++stats.refused_reasons[reason_kind(reason)];
  if (reason.find("infeasible") != std::string::npos)
    ++stats.refused_infeasible;
  else if (reason.rfind("misaligned", 0) == 0 || reason.rfind("self-intersecting", 0) == 0)
    ++stats.refused_geometry;
  else if (reason.find("loops") != std::string::npos)
    ++stats.refused_loops;
  else
    ++stats.refused_border;
}

/// Zhou et al. 2006 s.2.7, merging one group: the first output element
/// absorbs the group's inputs, then its other outputs, one by one (graph-cut
/// stitching); what could not be stitched is kept, replaced or dropped.
/// Writes s.alive of its outputs and s.add_in of its inputs only, the rest
/// into `out`.
void merge_group(QuiltStepState& s, const std::vector<int>& outs, const std::vector<int>& ins,
                 std::map<int, ElementMesh>& deformed_out, GroupOutcome& out) {
  const QuiltStepOptions& opt = s.opt;
  QuiltStepStats& stats = out.stats;
  const int first = outs.front();
  ElementMesh acc = deformed_out.count(first) ? deformed_out[first] : s.elements[first];
  Side acc_side = Region::kOld;
  std::vector<std::pair<bool, int>> others;  // (is_out, index)
  for (int e : ins) others.emplace_back(false, e);
  for (std::size_t k = 1; k < outs.size(); ++k) others.emplace_back(true, outs[k]);
  for (auto& [is_out, e] : others) {
    const ElementMesh& x = is_out ? (deformed_out.count(e) ? deformed_out[e] : s.elements[e]) : s.placed[e];
    MergeOptions mo = opt.merge;
    mo.mu = opt.mu;
    if (!opt.check_stitch_geometry) {
      mo.max_loop_offset = mo.max_loop_gap = mo.max_loop_radius_ratio = mo.max_loop_angle_deg = 0;
      mo.refuse_self_intersecting = false;
    }
    MergeResult r = merge_elements(acc, acc_side, x, is_out ? Region::kOld : Region::kNew,
                                   [&s](const P3& p) { return s.region(p); }, mo);
    if (r.stitched) {
      acc = std::move(r.merged);
      if (!is_out) acc_side = Region::kOverlap;  // now owns old and new parts
      ++stats.stitched;
      if (r.trimmed) ++stats.stitched_trimmed;
      if (is_out)
        s.alive[e] = 0;
      else
        s.add_in[e] = 0;
    } else if (r.coincident) {  // nothing to stitch: keep the output element whole
      ++stats.coincident;
      if (is_out && deformed_out.count(e)) out.replacements.emplace_back(e, deformed_out[e]);
      if (!is_out && s.add_in[e]) {
        s.add_in[e] = 0;
        keep_capped_or_drop(s, r, stats.coincident_cut_added, out);
      }
    } else {
      count_refusal(stats, r.reason);
      if (is_out && deformed_out.count(e)) out.replacements.emplace_back(e, deformed_out[e]);
      if (!is_out && opt.drop_refused_inputs && s.add_in[e]) {  // keep C_out rather than overlap it
        s.add_in[e] = 0;
        keep_capped_or_drop(s, r, stats.in_cut_added, out);
      }
    }
  }
  out.replacements.emplace_back(first, std::move(acc));
}

/// Each group of related elements (s.2.7): a group whose output side lies
/// entirely within the overlap is replaced by its inputs, one whose input
/// side does keeps its outputs; the others are deformed (s.2.6) and merged.
/// Groups share no element (they are the union-find's sets), so the deformed
/// and merged ones run in parallel, each into its own GroupOutcome, taken in
/// the groups' order.
void merge_groups(QuiltStepState& s) {
  s.add_in.assign(s.ni, 1);
  std::vector<int> work;  // roots to deform and merge
  for (auto& [root, g] : s.groups) {
    auto& [outs, ins] = g;
    bool outs_inside = true, ins_inside = true;
    for (int e : outs) outs_inside = outs_inside && s.entirely_in_overlap(s.elements[e]);
    for (int e : ins) ins_inside = ins_inside && s.entirely_in_overlap(s.placed[e]);
    if (outs_inside) {  // 2.7: C_out entirely within the overlap: C_in instead
      for (int e : outs) s.alive[e] = 0;
      s.stats.out_replaced += outs.size();
      continue;
    }
    if (ins_inside) {  // C_in entirely within the overlap: keep C_out
      for (int e : ins) s.add_in[e] = 0;
      s.stats.in_dropped += ins.size();
      continue;
    }
    work.push_back(root);
  }
  std::vector<GroupOutcome> outcome(work.size());
  Timer wall;
  tbb::parallel_for(std::size_t(0), work.size(), [&](std::size_t k) {
    const auto& [outs, ins] = s.groups.at(work[k]);
    Timer td;
    std::map<int, ElementMesh> deformed_out = deform_group(s, work[k]);
    outcome[k].t_deform = td.seconds();
    Timer tm;
    merge_group(s, outs, ins, deformed_out, outcome[k]);
    outcome[k].t_merge = tm.seconds();
  });
  // Stage seconds: the section's wall time, shared as the thread seconds were.
  double td = 0, tm = 0;
  for (GroupOutcome& o : outcome) {
    s.stats.add(o.stats);
    for (auto& r : o.replacements) s.replacements.push_back(std::move(r));
    for (ElementMesh& m : o.cut_inputs) s.cut_inputs.push_back(std::move(m));
    td += o.t_deform, tm += o.t_merge;
  }
  const double w = wall.seconds();
  s.t_deform += td + tm > 0 ? w * td / (td + tm) : 0.0;
  s.t_merge += td + tm > 0 ? w * tm / (td + tm) : 0.0;
}

/// Commits the step: the replaced output elements, the added inputs (and
/// kept parts of refused ones) after resolving their crossings with the
/// output, and the footprint's cells marked processed.
void commit_step(QuiltStepState& s) {
  QuiltStepStats& stats = s.stats;
  for (auto& [e, m] : s.replacements) s.elements[e] = std::move(m);
  std::vector<ElementMesh> adds;
  for (int e = 0; e < s.ni; ++e)
    if (s.add_in[e]) {
      adds.push_back(std::move(s.placed[e]));
      ++stats.in_added;
    }
  for (ElementMesh& m : s.cut_inputs) adds.push_back(std::move(m));
  if (s.opt.resolve_crossings) {
    Timer tr;
    QuiltStepOptions ro = s.opt;
    if (ro.clearance < 0) ro.clearance = 0.5 * s.swatch.min_gap;
    adds = resolve_crossings(s.elements, s.alive, std::move(adds), ro, stats);
    stats.seconds_resolve += tr.seconds();
  }
  for (ElementMesh& m : adds) {
    s.elements.push_back(std::move(m));
    s.alive.push_back(1);
  }
  QuiltGrid& grid = s.grid;
  for (int j = std::max(0, s.oj); j < std::min(grid.ny, s.oj + s.sy); ++j)
    for (int i = std::max(0, s.oi); i < std::min(grid.nx, s.oi + s.sx); ++i) grid.processed[j * grid.nx + i] = 1;
}

}  // namespace

QuiltPlacement quilt_step(const Swatch& swatch, const TriangleDistance& swatch_tree, QuiltGrid& grid,
                          std::vector<ElementMesh>& elements, std::vector<char>& alive, std::mt19937_64& rng,
                          const QuiltStepOptions& opt, QuiltStepStats& stats, const QuiltMatch* given) {
  Timer timer;
  const QuiltMatch match =
      given ? *given : match_swatch_placement(swatch, swatch_tree, grid, elements, alive, rng, opt);
  QuiltStepState s(swatch, grid, elements, alive, opt, stats);
  const double c = grid.cell;
  s.sx = std::max(1, static_cast<int>(std::ceil(swatch.length() / c - 1e-9)));
  s.sy = std::max(1, static_cast<int>(std::ceil(swatch.width() / c - 1e-9)));
  s.oi = match.placement.oi;
  s.oj = match.placement.oj;
  s.dx = match.placement.dx;
  s.dy = match.placement.dy;
  const P3 t{grid.x0 + s.oi * c - swatch.bbox_min[0] + s.dx, grid.y0 + s.oj * c - swatch.bbox_min[1] + s.dy, 0.0};
  stats.candidates += match.candidates;
  stats.best_cost = match.cost;
  stats.seconds_match += timer.seconds();
  timer.reset();
  place_input_elements(s, t);
  find_near_outputs(s);
  correspond_elements(s);
  stats.seconds_correspond += timer.seconds();
  timer.reset();
  group_related(s);
  merge_groups(s);
  commit_step(s);
  stats.seconds_deform += s.t_deform;
  stats.seconds_merge += s.t_merge;
  return {s.oi, s.oj, s.dx, s.dy};
}

}  // namespace surftex
