// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilt_step.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <numeric>
#include <string>

#include "geometry/errors.h"
#include "geometry/timer.h"
#include "shell/element_correspondence.h"
#include "shell/element_clearance.h"
#include "shell/element_deformation.h"
#include "shell/element_merging.h"

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
int find_root(std::vector<int>& p, int x) {
  while (p[x] != x) x = p[x] = p[p[x]];
  return x;
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
  ElementCollider old(elements, alive);
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
        const std::vector<char> h2 = old.hits(pushed, -1, opt.clearance);
        if (std::find(h2.begin(), h2.end(), 1) == h2.end()) {
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
      const std::vector<char> h2 = old.hits(p, -1, opt.clearance);
      if (std::find(h2.begin(), h2.end(), 1) != h2.end()) continue;
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
  auto match_cost = [&](const P3& t) {
    double e = 0;
    for (std::size_t v = 0; v < mv.size(); ++v) {
      const auto h = swatch_tree.closest({mv[v][0] - t[0], mv[v][1] - t[1], mv[v][2] - t[2]});
      const P3& nf = fn[h.tri];
      const double dn = std::sqrt((mn[v][0] - nf[0]) * (mn[v][0] - nf[0]) + (mn[v][1] - nf[1]) * (mn[v][1] - nf[1]) +
                                  (mn[v][2] - nf[2]) * (mn[v][2] - nf[2]));
      e += (1 + opt.lambda * h.distance) * (1 + dn);
    }
    return e;
  };
  std::vector<double> cost(cand.size(), 0.0);
  if (!mv.empty())
    tbb::parallel_for(std::size_t(0), cand.size(), [&](std::size_t k) {
      cost[k] = match_cost(translation(cand[k].first, cand[k].second));
    });
  const double best = *std::min_element(cost.begin(), cost.end());
  std::vector<std::size_t> eligible;
  for (std::size_t k = 0; k < cand.size(); ++k)
    if (cost[k] <= best * (1 + opt.choice_tolerance) + 1e-12) eligible.push_back(k);
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
        oc[k] = match_cost({t[0] + offs[k][0], t[1] + offs[k][1], t[2]});
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

QuiltPlacement quilt_step(const Swatch& swatch, const TriangleDistance& swatch_tree, QuiltGrid& grid,
                          std::vector<ElementMesh>& elements, std::vector<char>& alive, std::mt19937_64& rng,
                          const QuiltStepOptions& opt, QuiltStepStats& stats, const QuiltMatch* given) {
  Timer timer;
  const QuiltMatch match =
      given ? *given : match_swatch_placement(swatch, swatch_tree, grid, elements, alive, rng, opt);
  const double c = grid.cell;
  const int sx = std::max(1, static_cast<int>(std::ceil(swatch.length() / c - 1e-9)));
  const int sy = std::max(1, static_cast<int>(std::ceil(swatch.width() / c - 1e-9)));
  const int oi = match.placement.oi, oj = match.placement.oj;
  const double dx = match.placement.dx, dy = match.placement.dy;
  const P3 t{grid.x0 + oi * c - swatch.bbox_min[0] + dx, grid.y0 + oj * c - swatch.bbox_min[1] + dy, 0.0};
  stats.candidates += match.candidates;
  stats.best_cost = match.cost;
  stats.seconds_match += timer.seconds();
  timer.reset();

  // Placed input elements M_in(t).
  std::vector<std::vector<int>> etris(swatch.elements.size());
  for (std::size_t f = 0; f < swatch.face_element.size(); ++f) etris[swatch.face_element[f]].push_back(static_cast<int>(f));
  std::vector<ElementMesh> placed(swatch.elements.size());
  for (std::size_t e = 0; e < placed.size(); ++e) {
    placed[e] = extract_triangles(swatch.mesh, etris[e]);
    for (P3& p : placed[e].points)
      for (int d = 0; d < 3; ++d) p[d] += t[d];
  }
  const std::vector<char> processed_before = grid.processed;
  auto in_footprint_cell = [&](int cc) {
    const int i = cc % grid.nx, j = cc / grid.nx;
    return i >= oi && i < oi + sx && j >= oj && j < oj + sy;
  };
  auto in_overlap = [&](const P3& p) {
    const int cc = grid.cell_of(p[0], p[1]);
    return cc >= 0 && processed_before[cc] && in_footprint_cell(cc);
  };
  auto region = [&](const P3& p) {
    const int cc = grid.cell_of(p[0], p[1]);
    if (cc < 0) return Region::kNone;
    if (!processed_before[cc]) return Region::kNew;
    return in_footprint_cell(cc) ? Region::kOverlap : Region::kOld;
  };
  auto entirely_in_overlap = [&](const ElementMesh& m) {
    for (const P3& p : m.points)
      if (!in_overlap(p)) return false;
    return true;
  };
  // Output elements near the footprint.
  const double fx0 = grid.x0 + oi * c, fy0 = grid.y0 + oj * c, fx1 = fx0 + sx * c, fy1 = fy0 + sy * c;
  std::vector<int> near;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    if (!alive[e]) continue;
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (const P3& p : elements[e].points)
      for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
    if (hi[0] >= fx0 && lo[0] <= fx1 && hi[1] >= fy0 && lo[1] <= fy1) near.push_back(static_cast<int>(e));
  }

  // --- 2.5 Element correspondences.
  std::vector<std::pair<int, int>> related;
  ElementCorrespondences corr;
  if (!near.empty()) {
    CorrespondenceOptions co;
    co.lambda = opt.lambda;
    co.prune_factor = opt.prune_factor;
    corr = find_element_correspondences(elements, near, placed, in_overlap, co);
    related = opt.one_to_one ? strongest_relations(corr) : corr.related;
  }
  stats.pairs += corr.pairs.size();
  stats.related += related.size();
  stats.pruned_normal += corr.pruned_normal;
  stats.pruned_distance += corr.pruned_distance;
  stats.pruned_projection += corr.pruned_projection;
  stats.seconds_correspond += timer.seconds();
  timer.reset();

  // Groups of related elements: nodes = output elements, then input elements.
  const int no = static_cast<int>(elements.size()), ni = static_cast<int>(placed.size());
  std::vector<int> parent(no + ni);
  std::iota(parent.begin(), parent.end(), 0);
  for (auto& r : related) {
    int a = find_root(parent, r.first), b = find_root(parent, no + r.second);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::map<int, std::pair<std::vector<int>, std::vector<int>>> groups;  // root -> (outs, ins)
  std::vector<char> in_related(ni, 0), out_related(no, 0);
  for (auto& r : related) out_related[r.first] = 1, in_related[r.second] = 1;
  for (int e = 0; e < no; ++e)
    if (out_related[e]) groups[find_root(parent, e)].first.push_back(e);
  for (int e = 0; e < ni; ++e)
    if (in_related[e]) groups[find_root(parent, no + e)].second.push_back(e);

  std::vector<char> add_in(ni, 1);
  std::vector<std::pair<int, ElementMesh>> replacements;
  std::vector<ElementMesh> cut_inputs;  // refused inputs' closed kept parts (keep_cut_refused_inputs)
  // An input element not merged: its closed kept parts are added (counted in
  // `kept`) when asked for and there are any, else it is dropped.
  auto keep_capped_or_drop = [&](MergeResult& r, std::size_t& kept) {
    if (opt.keep_cut_refused_inputs && !r.capped_b.empty()) {
      ++kept;
      stats.in_cut_components += r.capped_b.size();
      for (ElementMesh& part : r.capped_b) cut_inputs.push_back(std::move(part));
    } else {
      ++stats.in_dropped;
    }
  };
  double t_deform = 0, t_merge = 0;
  for (auto& [root, g] : groups) {
    auto& [outs, ins] = g;
    bool outs_inside = true, ins_inside = true;
    for (int e : outs) outs_inside = outs_inside && entirely_in_overlap(elements[e]);
    for (int e : ins) ins_inside = ins_inside && entirely_in_overlap(placed[e]);
    if (outs_inside) {  // 2.7: C_out entirely within the overlap: C_in instead
      for (int e : outs) alive[e] = 0;
      stats.out_replaced += outs.size();
      continue;
    }
    if (ins_inside) {  // C_in entirely within the overlap: keep C_out
      for (int e : ins) add_in[e] = 0;
      stats.in_dropped += ins.size();
      continue;
    }
    // --- 2.6 Element deformation of both sides (eq. 5 and 6).
    Timer td;
    std::map<int, std::vector<DeformConstraint>> cout_, cin_;
    for (const VertexFacePair& p : corr.pairs) {
      if (find_root(parent, p.out_element) != root) continue;
      const P3& v = elements[p.out_element].points[p.vertex];
      const P3 cpt{(v[0] + p.closest[0]) / 2, (v[1] + p.closest[1]) / 2, (v[2] + p.closest[2]) / 2};
      cout_[p.out_element].push_back({{p.vertex, p.vertex, p.vertex}, {1, 0, 0}, cpt});
      const Tri& f = placed[p.in_element].tris[p.face];
      cin_[p.in_element].push_back({{f[0], f[1], f[2]}, {p.bary[0], p.bary[1], p.bary[2]}, cpt});
    }
    LaplacianDeformOptions lo;
    lo.mu = opt.mu;
    std::map<int, ElementMesh> deformed_out;
    for (auto& [e, cons] : cout_) {
      ElementMesh m = elements[e];
      std::vector<char> locked(m.points.size());
      for (std::size_t v = 0; v < m.points.size(); ++v) locked[v] = !in_overlap(m.points[v]);
      try {
        m.points = laplacian_deform(m, cons, locked, lo);
      } catch (const SolverError&) {
      }
      deformed_out[e] = std::move(m);
    }
    for (auto& [e, cons] : cin_) {
      try {
        placed[e].points = laplacian_deform(placed[e], cons, {}, lo);
      } catch (const SolverError&) {
      }
    }
    t_deform += td.seconds();
    // --- 2.7 Merging: the first output element absorbs the others one by one.
    Timer tm;
    const int first = outs.front();
    ElementMesh acc = deformed_out.count(first) ? deformed_out[first] : elements[first];
    Side acc_side = Region::kOld;
    std::vector<std::pair<bool, int>> others;  // (is_out, index)
    for (int e : ins) others.emplace_back(false, e);
    for (std::size_t k = 1; k < outs.size(); ++k) others.emplace_back(true, outs[k]);
    for (auto& [is_out, e] : others) {
      const ElementMesh& x = is_out ? (deformed_out.count(e) ? deformed_out[e] : elements[e]) : placed[e];
      MergeOptions mo = opt.merge;
      mo.mu = opt.mu;
      if (!opt.check_stitch_geometry) {
        mo.max_loop_offset = mo.max_loop_radius_ratio = mo.max_loop_angle_deg = 0;
        mo.refuse_self_intersecting = false;
      }
      MergeResult r = merge_elements(acc, acc_side, x, is_out ? Region::kOld : Region::kNew, region, mo);
      if (r.stitched) {
        acc = std::move(r.merged);
        if (!is_out) acc_side = Region::kOverlap;  // now owns old and new parts
        ++stats.stitched;
        if (r.trimmed) ++stats.stitched_trimmed;
        if (is_out)
          alive[e] = 0;
        else
          add_in[e] = 0;
      } else if (r.coincident) {  // nothing to stitch: keep the output element whole
        ++stats.coincident;
        if (is_out && deformed_out.count(e)) replacements.emplace_back(e, deformed_out[e]);
        if (!is_out && add_in[e]) {
          add_in[e] = 0;
          keep_capped_or_drop(r, stats.coincident_cut_added);
        }
      } else {
        ++stats.stitch_refused;
        ++stats.refused_reasons[reason_kind(r.reason)];
        if (r.reason.find("infeasible") != std::string::npos)
          ++stats.refused_infeasible;
        else if (r.reason.rfind("misaligned", 0) == 0 || r.reason.rfind("self-intersecting", 0) == 0)
          ++stats.refused_geometry;
        else if (r.reason.find("loops") != std::string::npos)
          ++stats.refused_loops;
        else
          ++stats.refused_border;
        if (is_out && deformed_out.count(e)) replacements.emplace_back(e, deformed_out[e]);
        if (!is_out && opt.drop_refused_inputs && add_in[e]) {  // keep C_out rather than overlap it
          add_in[e] = 0;
          keep_capped_or_drop(r, stats.in_cut_added);
        }
      }
    }
    replacements.emplace_back(first, std::move(acc));
    t_merge += tm.seconds();
  }
  for (auto& [e, m] : replacements) elements[e] = std::move(m);
  std::vector<ElementMesh> adds;
  for (int e = 0; e < ni; ++e)
    if (add_in[e]) {
      adds.push_back(std::move(placed[e]));
      ++stats.in_added;
    }
  for (ElementMesh& m : cut_inputs) adds.push_back(std::move(m));
  if (opt.resolve_crossings) {
    Timer tr;
    QuiltStepOptions ro = opt;
    if (ro.clearance < 0) ro.clearance = 0.5 * swatch.min_gap;
    adds = resolve_crossings(elements, alive, std::move(adds), ro, stats);
    stats.seconds_resolve += tr.seconds();
  }
  for (ElementMesh& m : adds) {
    elements.push_back(std::move(m));
    alive.push_back(1);
  }
  for (int j = std::max(0, oj); j < std::min(grid.ny, oj + sy); ++j)
    for (int i = std::max(0, oi); i < std::min(grid.nx, oi + sx); ++i) grid.processed[j * grid.nx + i] = 1;
  stats.seconds_deform += t_deform;
  stats.seconds_merge += t_merge;
  return {oi, oj, dx, dy};
}

}  // namespace surftex
