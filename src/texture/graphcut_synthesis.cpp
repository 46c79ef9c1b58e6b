// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/graphcut_synthesis.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <string>

#include "geometry/errors.h"
#include "geometry/graph_cut.h"
#include "texture/masked_ssd_fft.h"
#include "texture/wrap_seam_ratio.h"

namespace surftex {

namespace {
constexpr int kDirs[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
}  // namespace

// ---------------------------------------------------------------------------
// GraphcutCanvas

GraphcutCanvas::GraphcutCanvas(const Image& exemplar, int width, int height, bool periodic,
                               bool gradient_normalized)
    : ex_(exemplar), w_(width), h_(height), periodic_(periodic),
      gradient_normalized_(gradient_normalized) {
  if (exemplar.empty()) throw InvalidInputError("graph-cut synthesis: the exemplar is empty");
  if (width <= 0 || height <= 0)
    throw InvalidInputError("graph-cut synthesis: output size must be positive, got " +
                            std::to_string(width) + "x" + std::to_string(height));
  sx_.assign(static_cast<std::size_t>(w_) * h_, -1);
  sy_.assign(sx_.size(), -1);
}

bool GraphcutCanvas::complete() const {
  return std::all_of(sx_.begin(), sx_.end(), [](int v) { return v >= 0; });
}

bool GraphcutCanvas::neighbour(int x, int y, int dx, int dy, int& nx, int& ny) const {
  nx = x + dx;
  ny = y + dy;
  if (periodic_) {
    nx = (nx % w_ + w_) % w_;
    ny = (ny % h_ + h_) % h_;
    return !(nx == x && ny == y);
  }
  return nx >= 0 && ny >= 0 && nx < w_ && ny < h_;
}

double GraphcutCanvas::pair_cost(int sx, int sy, int tx, int ty, int dx, int dy) const {
  // s has label A (source (sx,sy)), its neighbour t = s + d has label B
  // (source (tx,ty)). Same translation: no seam.
  if (tx == sx + dx && ty == sy + dy) return 0.0;
  auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < ex_.width && y < ex_.height; };
  auto dist = [&](int ax, int ay, int bx, int by) {
    const float* a = ex_.pixel(ax, ay);
    const float* b = ex_.pixel(bx, by);
    double s = 0.0;
    for (int c = 0; c < ex_.channels; ++c) {
      double d = static_cast<double>(a[c]) - b[c];
      s += d * d;
    }
    return std::sqrt(s);
  };
  const bool bs_ok = inside(tx - dx, ty - dy);  // B(s)
  const bool at_ok = inside(sx + dx, sy + dy);  // A(t)
  double m;
  if (bs_ok && at_ok)
    m = dist(sx, sy, tx - dx, ty - dy) + dist(sx + dx, sy + dy, tx, ty);
  else if (bs_ok)
    m = 2.0 * dist(sx, sy, tx - dx, ty - dy);
  else if (at_ok)
    m = 2.0 * dist(sx + dx, sy + dy, tx, ty);
  else
    m = 2.0 * dist(sx, sy, tx, ty);
  if (gradient_normalized_) {
    double ga = at_ok ? dist(sx, sy, sx + dx, sy + dy) : -1.0;
    double gb = bs_ok ? dist(tx - dx, ty - dy, tx, ty) : -1.0;
    if (ga < 0) ga = gb >= 0 ? gb : 0.0;
    if (gb < 0) gb = ga;
    m /= ga + gb + 1e-3;
  }
  return m;
}

void GraphcutCanvas::check_placement(const PatchPlacement& p) const {
  if (p.width <= 0 || p.height <= 0 || p.ex_x < 0 || p.ex_y < 0 ||
      p.ex_x + p.width > ex_.width || p.ex_y + p.height > ex_.height)
    throw InvalidInputError("graph-cut synthesis: patch window (" + std::to_string(p.ex_x) + "," +
                            std::to_string(p.ex_y) + ") size " + std::to_string(p.width) + "x" +
                            std::to_string(p.height) + " is not inside the " +
                            std::to_string(ex_.width) + "x" + std::to_string(ex_.height) +
                            " exemplar");
  if (periodic_ && (p.width > w_ - 1 || p.height > h_ - 1))
    throw InvalidInputError("graph-cut synthesis: a periodic patch must be smaller than the output (" +
                            std::to_string(p.width) + "x" + std::to_string(p.height) + " vs " +
                            std::to_string(w_) + "x" + std::to_string(h_) + ")");
}

namespace {
// Clips a non-periodic placement to the output; returns false if nothing is left.
bool clip_placement(PatchPlacement& p, int w, int h) {
  if (p.out_x < 0) { p.ex_x -= p.out_x; p.width += p.out_x; p.out_x = 0; }
  if (p.out_y < 0) { p.ex_y -= p.out_y; p.height += p.out_y; p.out_y = 0; }
  p.width = std::min(p.width, w - p.out_x);
  p.height = std::min(p.height, h - p.out_y);
  return p.width > 0 && p.height > 0;
}

// Footprint of a placement: local (i,j) <-> output (x,y).
struct Footprint {
  PatchPlacement p;
  int w, h;
  bool periodic;
  int ox(int i) const { return periodic ? (p.out_x + i) % w : p.out_x + i; }
  int oy(int j) const { return periodic ? (p.out_y + j) % h : p.out_y + j; }
  int local(int x, int y) const {
    int i = x - p.out_x, j = y - p.out_y;
    if (periodic) {
      i = (i % w + w) % w;
      j = (j % h + h) % h;
    }
    if (i < 0 || j < 0 || i >= p.width || j >= p.height) return -1;
    return j * p.width + i;
  }
};
}  // namespace

int GraphcutCanvas::place_graphcut(const PatchPlacement& placement,
                                   const std::vector<std::pair<int, int>>& forced) {
  PatchPlacement p = placement;
  if (periodic_) {
    p.out_x = (p.out_x % w_ + w_) % w_;
    p.out_y = (p.out_y % h_ + h_) % h_;
  }
  check_placement(p);
  if (!periodic_ && !clip_placement(p, w_, h_)) return 0;
  const Footprint fp{p, w_, h_, periodic_};
  const int n = p.width * p.height;
  std::vector<char> force(static_cast<std::size_t>(n), 0);
  for (const auto& f : forced) {
    if (f.first < 0 || f.second < 0 || f.first >= w_ || f.second >= h_) continue;
    int l = fp.local(f.first, f.second);
    if (l >= 0) force[static_cast<std::size_t>(l)] = 1;
  }
  struct Term { int u, v; double cuv, cvu; };
  struct SeamNode { int q, r; double cq, cr, old; };
  std::vector<Term> edges;
  std::vector<SeamNode> seams;
  std::vector<double> tsrc(static_cast<std::size_t>(n), 0.0), tsink(static_cast<std::size_t>(n), 0.0);
  edges.reserve(static_cast<std::size_t>(2 * n));
  for (int j = 0; j < p.height; ++j)
    for (int i = 0; i < p.width; ++i) {
      const int q = j * p.width + i;
      const int x = fp.ox(i), y = fp.oy(j);
      const bool cq = covered(x, y);
      const int ax = sx_[idx(x, y)], ay = sy_[idx(x, y)];
      const int bx = p.ex_x + i, by = p.ex_y + j;
      if (!cq || force[static_cast<std::size_t>(q)]) tsink[static_cast<std::size_t>(q)] = GraphCut::kInfinity;
      for (const auto& d : kDirs) {
        int rx, ry;
        if (!neighbour(x, y, d[0], d[1], rx, ry)) continue;
        const int r = fp.local(rx, ry);
        const bool cr = covered(rx, ry);
        const int arx = sx_[idx(rx, ry)], ary = sy_[idx(rx, ry)];
        if (r >= 0) {
          if (d[0] < 0 || d[1] < 0) continue;  // internal pairs once (right, down)
          const int brx = bx + d[0], bry = by + d[1];
          if (cq && cr && !(arx == ax + d[0] && ary == ay + d[1])) {
            // Old seam between two earlier patches: seam node (section 3.3).
            seams.push_back({q, r, pair_cost(ax, ay, brx, bry, d[0], d[1]),
                             pair_cost(bx, by, arx, ary, d[0], d[1]),
                             pair_cost(ax, ay, arx, ary, d[0], d[1])});
          } else {
            double c_qr = cq ? pair_cost(ax, ay, brx, bry, d[0], d[1]) : 0.0;  // q old, r new
            double c_rq = cr ? pair_cost(bx, by, arx, ary, d[0], d[1]) : 0.0;  // q new, r old
            if (c_qr > 0.0 || c_rq > 0.0) edges.push_back({q, r, c_qr, c_rq});
          }
        } else if (cr) {
          // Neighbour outside the footprint keeps its source: terminal costs.
          double keep = cq ? pair_cost(ax, ay, arx, ary, d[0], d[1]) : 0.0;
          double take = pair_cost(bx, by, arx, ary, d[0], d[1]);
          tsink[static_cast<std::size_t>(q)] += keep;   // paid when q stays old (source side)
          tsrc[static_cast<std::size_t>(q)] += take;    // paid when q takes the patch (sink side)
        }
      }
    }
  // Pixels that must take the new patch (uncovered or forced) are not graph
  // nodes: their links become terminal costs of their free neighbours, so
  // the graph only spans the overlap.
  std::vector<int> node(static_cast<std::size_t>(n) + seams.size(), -1);
  int nodes = 0;
  for (int q = 0; q < n; ++q)
    if (tsink[static_cast<std::size_t>(q)] < GraphCut::kInfinity) node[static_cast<std::size_t>(q)] = nodes++;
  for (std::size_t k = 0; k < seams.size(); ++k) node[static_cast<std::size_t>(n) + k] = nodes++;
  GraphCut gc(nodes);
  std::vector<double> extra_sink(static_cast<std::size_t>(nodes), 0.0);
  // Link u-v: c_uv is paid when u keeps the old label and v takes the new one.
  auto link = [&](int u, int v, double c_uv, double c_vu) {
    const int nu = node[static_cast<std::size_t>(u)], nv = node[static_cast<std::size_t>(v)];
    if (nu >= 0 && nv >= 0) {
      if (c_uv > 0.0 || c_vu > 0.0) gc.add_edge(nu, nv, c_uv, c_vu);
    } else if (nu >= 0) {
      extra_sink[static_cast<std::size_t>(nu)] += c_uv;  // v is new: paid if u stays old
    } else if (nv >= 0) {
      extra_sink[static_cast<std::size_t>(nv)] += c_vu;
    }
  };
  for (const Term& e : edges) link(e.u, e.v, e.cuv, e.cvu);
  for (std::size_t k = 0; k < seams.size(); ++k) {
    const int sn = n + static_cast<int>(k);
    link(seams[k].q, sn, seams[k].cq, seams[k].cq);
    link(sn, seams[k].r, seams[k].cr, seams[k].cr);
    gc.add_terminal(node[static_cast<std::size_t>(sn)], 0.0, seams[k].old);
  }
  for (int q = 0; q < n; ++q) {
    const int nq = node[static_cast<std::size_t>(q)];
    if (nq < 0) continue;
    const double src = tsrc[static_cast<std::size_t>(q)];
    const double snk = tsink[static_cast<std::size_t>(q)] + extra_sink[static_cast<std::size_t>(nq)];
    if (src > 0.0 || snk > 0.0) gc.add_terminal(nq, src, snk);
  }
  for (std::size_t k = 0; k < seams.size(); ++k) {
    const int nq = node[static_cast<std::size_t>(n) + k];
    if (extra_sink[static_cast<std::size_t>(nq)] > 0.0) gc.add_terminal(nq, 0.0, extra_sink[static_cast<std::size_t>(nq)]);
  }
  if (nodes > 0) gc.solve();
  int changed = 0;
  for (int j = 0; j < p.height; ++j)
    for (int i = 0; i < p.width; ++i) {
      const int nq = node[static_cast<std::size_t>(j) * p.width + i];
      if (nq >= 0 && gc.is_source_side(nq)) continue;
      const std::size_t o = idx(fp.ox(i), fp.oy(j));
      const int bx = p.ex_x + i, by = p.ex_y + j;
      if (sx_[o] != bx || sy_[o] != by) ++changed;
      sx_[o] = bx;
      sy_[o] = by;
    }
  return changed;
}

void GraphcutCanvas::place_straight(const PatchPlacement& placement) {
  PatchPlacement p = placement;
  if (periodic_) {
    p.out_x = (p.out_x % w_ + w_) % w_;
    p.out_y = (p.out_y % h_ + h_) % h_;
  }
  check_placement(p);
  if (!periodic_ && !clip_placement(p, w_, h_)) return;
  const Footprint fp{p, w_, h_, periodic_};
  for (int j = 0; j < p.height; ++j)
    for (int i = 0; i < p.width; ++i) {
      const std::size_t o = idx(fp.ox(i), fp.oy(j));
      sx_[o] = p.ex_x + i;
      sy_[o] = p.ex_y + j;
    }
}

double GraphcutCanvas::seam_cost() const {
  double total = 0.0;
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x) {
      if (!covered(x, y)) continue;
      for (int k = 0; k < 2; ++k) {
        int rx, ry;
        if (!neighbour(x, y, kDirs[k][0], kDirs[k][1], rx, ry) || !covered(rx, ry)) continue;
        total += pair_cost(sx_[idx(x, y)], sy_[idx(x, y)], sx_[idx(rx, ry)], sy_[idx(rx, ry)],
                           kDirs[k][0], kDirs[k][1]);
      }
    }
  return total;
}

double GraphcutCanvas::pixel_seam_error(int x, int y) const {
  if (!covered(x, y)) return 0.0;
  double e = 0.0;
  for (const auto& d : kDirs) {
    int rx, ry;
    if (!neighbour(x, y, d[0], d[1], rx, ry) || !covered(rx, ry)) continue;
    e += pair_cost(sx_[idx(x, y)], sy_[idx(x, y)], sx_[idx(rx, ry)], sy_[idx(rx, ry)], d[0], d[1]);
  }
  return e;
}

std::vector<double> GraphcutCanvas::seam_error_map() const {
  std::vector<double> e(static_cast<std::size_t>(w_) * h_, 0.0);
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x) e[idx(x, y)] = pixel_seam_error(x, y);
  return e;
}

GraphcutCanvas::ErrorRegion GraphcutCanvas::worst_error_region(const std::vector<double>& err, int side,
                                                               const std::vector<char>& skip) const {
  if (side < 1) throw InvalidInputError("worst_error_region: side must be >= 1, got " + std::to_string(side));
  const std::size_t n = static_cast<std::size_t>(w_) * h_;
  if (err.size() != n || (!skip.empty() && skip.size() != n))
    throw InvalidInputError("worst_error_region: the error map (" + std::to_string(err.size()) +
                            ") and skip mask (" + std::to_string(skip.size()) + ") must have " +
                            std::to_string(n) + " entries");
  side = std::min({side, w_, h_});
  const int sx = side, sy = side;
  // Window origins: every pixel on the torus, else those keeping the window inside.
  const int nx = periodic_ ? w_ : w_ - sx + 1, ny = periodic_ ? h_ : h_ - sy + 1;
  // Row sums of sx consecutive pixels, then column sums of sy rows.
  std::vector<double> rows(static_cast<std::size_t>(nx) * h_, 0.0);
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < nx; ++x) {
      double t = 0.0;
      for (int i = 0; i < sx; ++i) t += err[idx((x + i) % w_, y)];
      rows[static_cast<std::size_t>(y) * nx + x] = t;
    }
  ErrorRegion best;
  best.side = side;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x) {
      const int cx = (x + sx / 2) % w_, cy = (y + sy / 2) % h_;
      if (!skip.empty() && skip[idx(cx, cy)]) continue;
      double t = 0.0;
      for (int j = 0; j < sy; ++j) t += rows[static_cast<std::size_t>((y + j) % h_) * nx + x];
      if (t > best.cost) {
        best.cost = t;
        best.x = x;
        best.y = y;
      }
    }
  return best;
}

double GraphcutCanvas::footprint_cost(const PatchPlacement& placement) const {
  PatchPlacement p = placement;
  if (!periodic_ && !clip_placement(p, w_, h_)) return 0.0;
  const Footprint fp{p, w_, h_, periodic_};
  double total = 0.0;
  for (int j = 0; j < p.height; ++j)
    for (int i = 0; i < p.width; ++i) {
      const int x = fp.ox(i), y = fp.oy(j);
      if (!covered(x, y)) continue;
      for (const auto& d : kDirs) {
        int rx, ry;
        if (!neighbour(x, y, d[0], d[1], rx, ry) || !covered(rx, ry)) continue;
        if (fp.local(rx, ry) >= 0 && (d[0] < 0 || d[1] < 0)) continue;
        total += pair_cost(sx_[idx(x, y)], sy_[idx(x, y)], sx_[idx(rx, ry)], sy_[idx(rx, ry)],
                           d[0], d[1]);
      }
    }
  return total;
}

Image GraphcutCanvas::render() const {
  Image out(w_, h_, ex_.channels, 0.f);
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x) {
      if (!covered(x, y)) continue;
      const float* s = ex_.pixel(sx_[idx(x, y)], sy_[idx(x, y)]);
      std::copy(s, s + ex_.channels, out.pixel(x, y));
    }
  return out;
}

// ---------------------------------------------------------------------------
// The placement loop.

class GraphcutSynthesizer {
 public:
  GraphcutSynthesizer(const Image& ex, int w, int h, const GraphcutOptions& o)
      : ex_(ex), opt_(o), canvas_(ex, w, h, o.periodic_output, o.gradient_normalized),
        rng_(o.seed) {
    const int lim_w = o.periodic_output ? std::max(1, w - 1) : w;
    const int lim_h = o.periodic_output ? std::max(1, h - 1) : h;
    if (o.placement == PlacementMode::EntirePatch) {
      pw_ = std::min(ex.width, lim_w);
      ph_ = std::min(ex.height, lim_h);
    } else {
      const int min_side = std::min(ex.width, ex.height);
      // Large patches (section 4.1: with FFT matching their size costs
      // nothing): 3/4 of the exemplar side, so that several offsets remain
      // to choose from, but at most 192 (a 256 output still gets seams to
      // mix exemplar regions) and at least 64 (or the whole exemplar).
      const int auto_ps = std::min(min_side, std::clamp(min_side * 3 / 4, 64, 192));
      int ps = o.patch_size > 0 ? o.patch_size : auto_ps;
      pw_ = std::min({ps, ex.width, lim_w});
      ph_ = std::min({ps, ex.height, lim_h});
      if (o.patch_size == 0 && o.overlap == 0 && !o.periodic_output) {
        pw_ = fit_to_grid(pw_, w);
        ph_ = fit_to_grid(ph_, h);
      }
    }
    int ov = o.overlap > 0 ? o.overlap : std::max(2, std::min(pw_, ph_) / 3);
    ov_ = std::min(ov, std::min(pw_, ph_) - 1);
    error_side_ = std::min({o.error_region > 0 ? o.error_region : std::max(3, ov_ / 4), pw_, ph_});
    match_side_ = std::min({3 * error_side_, pw_, ph_});
    // sigma^2: summed per-channel variance of the exemplar.
    const std::size_t np = static_cast<std::size_t>(ex.width) * ex.height;
    for (int c = 0; c < ex.channels; ++c) {
      double s = 0, s2 = 0;
      for (std::size_t i = 0; i < np; ++i) {
        double v = ex.data[i * ex.channels + c];
        s += v;
        s2 += v * v;
      }
      double mean = s / np;
      sigma2_ += std::max(0.0, s2 / np - mean * mean);
    }
    sigma2_ = std::max(sigma2_, 1e-8);
  }

  // The largest side <= `patch` whose fill grid (overlap side/3) covers
  // `size` exactly: n patches of side p overlapping by p/3 span
  // p + (n-1) 2p/3 = (2n+1) p/3, so p = 3 size / (2n+1) for the smallest n
  // that brings p under `patch`. Without it the last patch of a row is
  // pushed back to the border: 192-pixel patches on a 256 output overlapped
  // by 128 pixels instead of 64, which doubled the graph of every cut
  // (measured: fabric_brown_256 1.18 -> 0.32 CPU s, same similarity).
  static int fit_to_grid(int patch, int size) {
    if (patch >= size) return patch;
    for (int n = 1;; ++n) {
      const int p = (3 * size + 2 * n) / (2 * n + 1);  // rounded up
      if (p <= patch) return std::max(std::min(4, patch), p);
    }
  }

  GraphcutResult run() {
    GraphcutResult res;
    if (opt_.placement == PlacementMode::EntirePatch)
      fill_entire();
    else
      fill_grid();
    res.patch_width = pw_;
    res.patch_height = ph_;
    res.fill_patches = fill_patches_;
    res.seam_cost_after_fill = canvas_.seam_cost();
    refine(res);
    res.seam_cost_before_straight = canvas_.seam_cost();
    repair_straight_seams(res);
    res.seam_cost_final = canvas_.seam_cost();
    res.image = canvas_.render();
    res.source_x = canvas_.sx_;
    res.source_y = canvas_.sy_;
    report_progress(opt_.progress, "graphcut", 1.0);
    return res;
  }

 private:
  double uniform01() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  int uniform_int(int lo, int hi) {  // inclusive
    return lo + static_cast<int>(uniform01() * (hi - lo + 1)) % (hi - lo + 1);
  }

  // Draws an index with probability exp(-(C_i - C_min)/(k sigma^2)).
  int draw(const std::vector<std::pair<int, double>>& cand) {
    double cmin = cand.front().second;
    for (const auto& c : cand) cmin = std::min(cmin, c.second);
    const double t = opt_.k * sigma2_;
    std::vector<double> w(cand.size());
    double total = 0.0;
    for (std::size_t i = 0; i < cand.size(); ++i) total += w[i] = std::exp(-(cand[i].second - cmin) / t);
    double r = uniform01() * total;
    for (std::size_t i = 0; i < cand.size(); ++i) {
      r -= w[i];
      if (r < 0.0) return cand[i].first;
    }
    return cand.back().first;
  }

  // The output window at (x0, y0), wrapped or clipped, and its covered mask.
  void window(int x0, int y0, int ww, int wh, Image& img, std::vector<float>& mask) const {
    img = Image(ww, wh, ex_.channels, 0.f);
    mask.assign(static_cast<std::size_t>(ww) * wh, 0.f);
    const int W = canvas_.w_, H = canvas_.h_;
    for (int j = 0; j < wh; ++j)
      for (int i = 0; i < ww; ++i) {
        int x = x0 + i, y = y0 + j;
        if (canvas_.periodic_) {
          x = (x % W + W) % W;
          y = (y % H + H) % H;
        } else if (x < 0 || y < 0 || x >= W || y >= H) {
          continue;
        }
        if (!canvas_.covered(x, y)) continue;
        mask[static_cast<std::size_t>(j) * ww + i] = 1.f;
        const float* s = ex_.pixel(canvas_.source_x(x, y), canvas_.source_y(x, y));
        std::copy(s, s + ex_.channels, img.pixel(i, j));
      }
  }

  // Exemplar offset for a tw x th template (an output window) at output
  // (x0, y0): the exemplar position whose content matches the covered part
  // of the window best (sub-patch matching).
  // `fill`: skip offsets that merely continue a patch already in the window
  // (within overlap/2 pixels of its translation) when any other offset
  // exists; otherwise a large exemplar is copied verbatim.
  // `hole` (window coordinates x, y, side): pixels left out of the match
  // (weight 0), e.g. the error region a refinement patch must replace.
  std::pair<int, int> choose_offset(int x0, int y0, bool fill, const int* hole = nullptr) {
    return choose_offset(x0, y0, pw_, ph_, fill, hole);
  }
  std::pair<int, int> choose_offset(int x0, int y0, int tw, int th, bool fill, const int* hole) {
    const int mx = ex_.width - tw, my = ex_.height - th;
    if (opt_.placement == PlacementMode::Random) return {uniform_int(0, mx), uniform_int(0, my)};
    Image win;
    std::vector<float> mask;
    window(x0, y0, tw, th, win, mask);
    if (hole)
      for (int j = std::max(0, hole[1]); j < std::min(th, hole[1] + hole[2]); ++j)
        for (int i = std::max(0, hole[0]); i < std::min(tw, hole[0] + hole[2]); ++i)
          mask[static_cast<std::size_t>(j) * tw + i] = 0.f;
    double area = std::accumulate(mask.begin(), mask.end(), 0.0);
    if (area <= 0.0) return {uniform_int(0, mx), uniform_int(0, my)};
    if (!matcher_) matcher_ = std::make_unique<MaskedSsdMatcher>(ex_, std::vector<float>{}, false);
    SsdMap m = matcher_->match(win, mask);
    std::vector<std::pair<int, int>> continued;  // exemplar offsets of patches in the window
    if (fill) {
      for (int j = 0; j < th; ++j)
        for (int i = 0; i < tw; ++i) {
          if (mask[static_cast<std::size_t>(j) * tw + i] == 0.f) continue;
          int x = x0 + i, y = y0 + j;
          if (canvas_.periodic_) {
            x = (x % canvas_.w_ + canvas_.w_) % canvas_.w_;
            y = (y % canvas_.h_ + canvas_.h_) % canvas_.h_;
          }
          std::pair<int, int> e{canvas_.source_x(x, y) - i, canvas_.source_y(x, y) - j};
          if (std::find(continued.begin(), continued.end(), e) == continued.end()) continued.push_back(e);
        }
    }
    const int r = std::max(1, ov_ / 2);
    const std::vector<double> rep = repetition(x0, y0, tw, th, m.nx, m.ny);
    std::vector<std::pair<int, double>> cand, excluded;
    cand.reserve(m.ssd.size());
    for (std::size_t i = 0; i < m.ssd.size(); ++i) {
      const int ex = static_cast<int>(i) % m.nx, ey = static_cast<int>(i) / m.nx;
      bool cont = false;
      for (const auto& e : continued)
        if (std::abs(ex - e.first) <= r && std::abs(ey - e.second) <= r) cont = true;
      const double c = m.ssd[i] / area + (rep.empty() ? 0.0 : opt_.repetition_penalty * sigma2_ * rep[i]);
      (cont ? excluded : cand).emplace_back(static_cast<int>(i), c);
    }
    int best = draw(cand.empty() ? excluded : cand);
    return {best % m.nx, best / m.nx};
  }

  // Repetition term of every offset (nx x ny, row-major; empty when the
  // penalty is off): the mean over the exemplar window [u, u + patch) of the
  // number of output pixels outside the target window at (x0, y0) that show
  // each exemplar pixel, divided by max(1, output area / exemplar area).
  std::vector<double> repetition(int x0, int y0, int tw, int th, int nx, int ny) const {
    if (!(opt_.repetition_penalty > 0.0)) return {};
    const int W = canvas_.w_, H = canvas_.h_, EW = ex_.width, EH = ex_.height;
    std::vector<double> occ(static_cast<std::size_t>(EW + 1) * (EH + 1), 0.0);  // integral image
    auto inside_window = [&](int x, int y) {
      int i = x - x0, j = y - y0;
      if (canvas_.periodic_) {
        i = (i % W + W) % W;
        j = (j % H + H) % H;
      }
      return i >= 0 && j >= 0 && i < tw && j < th;
    };
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        if (!canvas_.covered(x, y) || inside_window(x, y)) continue;
        occ[static_cast<std::size_t>(canvas_.source_y(x, y) + 1) * (EW + 1) + canvas_.source_x(x, y) + 1] += 1.0;
      }
    for (int y = 1; y <= EH; ++y)
      for (int x = 1; x <= EW; ++x) {
        const std::size_t k = static_cast<std::size_t>(y) * (EW + 1) + x;
        occ[k] += occ[k - 1] + occ[k - EW - 1] - occ[k - EW - 2];
      }
    const double expected = std::max(1.0, static_cast<double>(W) * H / (static_cast<double>(EW) * EH));
    const double norm = 1.0 / (expected * tw * th);
    std::vector<double> rep(static_cast<std::size_t>(nx) * ny);
    for (int v = 0; v < ny; ++v)
      for (int u = 0; u < nx; ++u) {
        auto at = [&](int x, int y) { return occ[static_cast<std::size_t>(y) * (EW + 1) + x]; };
        const double sum = at(u + tw, v + th) - at(u, v + th) - at(u + tw, v) + at(u, v);
        rep[static_cast<std::size_t>(v) * nx + u] = sum * norm;
      }
    return rep;
  }

  std::vector<int> grid(int size, int patch) const {
    const int step = std::max(1, patch - ov_);
    std::vector<int> g;
    if (opt_.periodic_output) {
      int n = (size + step - 1) / step;
      for (int i = 0; i < n; ++i) g.push_back(static_cast<int>(static_cast<long long>(i) * size / n));
    } else {
      for (int x = 0;; x += step) {
        if (x + patch >= size) {
          g.push_back(std::max(0, size - patch));
          break;
        }
        g.push_back(x);
      }
    }
    return g;
  }

  void fill_grid() {
    std::vector<int> gx = grid(canvas_.w_, pw_), gy = grid(canvas_.h_, ph_);
    const std::size_t total = gx.size() * gy.size();
    std::size_t done = 0;
    for (int y0 : gy)
      for (int x0 : gx) {
        auto [ex, ey] = choose_offset(x0, y0, true);
        canvas_.place_graphcut({x0, y0, ex, ey, pw_, ph_});
        ++fill_patches_;
        report_progress(opt_.progress, "graphcut fill", static_cast<double>(++done) / total);
      }
  }

  // Entire-patch matching: the translation of the exemplar window [0,pw_)x[0,ph_)
  // over the output that covers `target`, matched against everything covered.
  PatchPlacement entire_patch_placement(int tx, int ty) {
    const int W = canvas_.w_, H = canvas_.h_;
    const bool wrap = canvas_.periodic_;
    const int padx = wrap ? 0 : pw_ - 1, pady = wrap ? 0 : ph_ - 1;
    Image big(W + 2 * padx, H + 2 * pady, ex_.channels, 0.f);
    std::vector<float> bmask(static_cast<std::size_t>(big.width) * big.height, 0.f);
    bool any = false;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        if (!canvas_.covered(x, y)) continue;
        any = true;
        bmask[static_cast<std::size_t>(y + pady) * big.width + x + padx] = 1.f;
        const float* s = ex_.pixel(canvas_.source_x(x, y), canvas_.source_y(x, y));
        std::copy(s, s + ex_.channels, big.pixel(x + padx, y + pady));
      }
    Image tmpl(pw_, ph_, ex_.channels);
    for (int j = 0; j < ph_; ++j)
      for (int i = 0; i < pw_; ++i) std::copy(ex_.pixel(i, j), ex_.pixel(i, j) + ex_.channels, tmpl.pixel(i, j));
    if (!any) return {tx, ty, 0, 0, pw_, ph_};
    MaskedSsdMatcher matcher(big, std::move(bmask), wrap);
    SsdMap m = matcher.match(tmpl, {});
    // Candidates: top-left x0 in [tx-pw_+1, tx], overlap >= 10% of the patch.
    std::vector<std::pair<int, double>> cand;
    const double min_overlap = 0.1 * pw_ * ph_;
    for (int dy = 0; dy < ph_; ++dy)
      for (int dx = 0; dx < pw_; ++dx) {
        int x0 = tx - dx, y0 = ty - dy;
        int ux = wrap ? ((x0 % W) + W) % W : x0 + padx;
        int uy = wrap ? ((y0 % H) + H) % H : y0 + pady;
        if (ux < 0 || uy < 0 || ux >= m.nx || uy >= m.ny) continue;
        double ov = m.overlap_at(ux, uy);
        if (ov < min_overlap) continue;
        cand.emplace_back(dy * pw_ + dx, m.ssd_at(ux, uy) / ov);
      }
    if (cand.empty()) return {tx, ty, 0, 0, pw_, ph_};
    int c = draw(cand);
    return {tx - c % pw_, ty - c / pw_, 0, 0, pw_, ph_};
  }

  void fill_entire() {
    const int W = canvas_.w_, H = canvas_.h_;
    const std::size_t total = static_cast<std::size_t>(W) * H;
    std::size_t scan = 0;
    while (true) {
      while (scan < total && canvas_.covered(static_cast<int>(scan % W), static_cast<int>(scan / W))) ++scan;
      if (scan >= total) break;
      const int tx = static_cast<int>(scan % W), ty = static_cast<int>(scan / W);
      canvas_.place_graphcut(entire_patch_placement(tx, ty));
      ++fill_patches_;
      report_progress(opt_.progress, "graphcut fill", static_cast<double>(scan) / total);
    }
  }

  // Refinement (Kwatra et al. 2003 section 4: once the output is full,
  // "we then iterate over regions of high seam cost"). Each step takes the
  // error region -- the error_side_ x error_side_ window with the highest
  // summed pixel seam error, recomputed after every accepted patch -- and
  // centres a patch on it; its offset comes from sub-patch matching of the
  // output window around the region, the region itself left out of the
  // match (its pixels are what is replaced); the region is forced to take the
  // new patch and the cut keeps old seams (section 3.3). The patch is kept if
  // the total seam cost does not increase. Within a pass, regions centred in
  // the central half of an earlier refinement patch of that pass are skipped,
  // so a pass spreads over the worst seams instead of retrying one.
  // The refinement patch for `region`: sub-patch matching of a tm x tm
  // output window centred on it (the region itself left out of the match);
  // the patch pasted is the exemplar around the match, up to pw_ x ph_ (the
  // cut decides how much of it is used).
  PatchPlacement refinement_placement(const GraphcutCanvas::ErrorRegion& region, int tm) {
    const int W = canvas_.w_, H = canvas_.h_;
    const int cx = (region.x + region.side / 2) % W, cy = (region.y + region.side / 2) % H;
    PatchPlacement p;
    if (opt_.placement == PlacementMode::EntirePatch) {
      p = entire_patch_placement(cx, cy);
    } else {
      tm = std::min({tm, pw_, ph_});
      int x0 = cx - tm / 2, y0 = cy - tm / 2;
      if (!canvas_.periodic_) {
        x0 = std::clamp(x0, 0, W - tm);
        y0 = std::clamp(y0, 0, H - tm);
      }
      // The region in window coordinates (x0 may have wrapped below 0).
      int hx = region.x - x0, hy = region.y - y0;
      if (canvas_.periodic_) {
        hx = (hx % W + W) % W;
        hy = (hy % H + H) % H;
      }
      const int hole[3] = {hx, hy, region.side};
      auto [ux, uy] = choose_offset(x0, y0, tm, tm, false, hole);
      const int left = std::min((pw_ - tm) / 2, ux), top = std::min((ph_ - tm) / 2, uy);
      const int right = std::min(pw_ - tm - (pw_ - tm) / 2, ex_.width - ux - tm);
      const int bottom = std::min(ph_ - tm - (ph_ - tm) / 2, ex_.height - uy - tm);
      p = {x0 - left, y0 - top, ux - left, uy - top, left + tm + right, top + tm + bottom};
    }
    if (canvas_.periodic_) {
      p.out_x = (p.out_x % W + W) % W;
      p.out_y = (p.out_y % H + H) % H;
    }
    return p;
  }

  void refine(GraphcutResult& res) {
    const int W = canvas_.w_, H = canvas_.h_;
    const int per_pass = std::max(1, fill_patches_);
    if (opt_.refinement_passes == 0) return;
    std::vector<double> err = canvas_.seam_error_map();
    // Template sides: the sub-patch around the region, then the whole patch.
    std::vector<int> templates = {match_side_};
    if (opt_.placement != PlacementMode::EntirePatch && match_side_ < std::max(pw_, ph_))
      templates.push_back(std::max(pw_, ph_));
    auto wrap_mark = [&](std::vector<char>& m, int x, int y) {
      if (canvas_.periodic_) {
        x = (x % W + W) % W;
        y = (y % H + H) % H;
      }
      if (x >= 0 && y >= 0 && x < W && y < H) m[static_cast<std::size_t>(y) * W + x] = 1;
    };
    for (int pass = 0; pass < opt_.refinement_passes; ++pass) {
      std::vector<char> visited(static_cast<std::size_t>(W) * H, 0);
      for (int placed = 0; placed < per_pass; ++placed) {
        const GraphcutCanvas::ErrorRegion region = canvas_.worst_error_region(err, error_side_, visited);
        if (!(region.cost > 0.0)) break;
        for (int j = 0; j < region.side; ++j)
          for (int i = 0; i < region.side; ++i) wrap_mark(visited, region.x + i, region.y + j);
        for (int tm : templates) {
          const PatchPlacement p = refinement_placement(region, tm);
          // Mark the central half of the footprint as handled for this pass.
          for (int j = p.height / 4; j < p.height - p.height / 4; ++j)
            for (int i = p.width / 4; i < p.width - p.width / 4; ++i) wrap_mark(visited, p.out_x + i, p.out_y + j);
          const std::vector<int> keep_x = canvas_.sx_, keep_y = canvas_.sy_;
          const double before = canvas_.footprint_cost(p);
          const int changed = canvas_.place_graphcut(p);
          ++res.refinement_tried;
          if (changed == 0) continue;  // the cut kept every old pixel: try the next template
          if (canvas_.footprint_cost(p) > before) {  // rounding only: the free cut cannot lose
            canvas_.sx_ = keep_x;
            canvas_.sy_ = keep_y;
            continue;
          }
          ++res.refinement_accepted;
          update_error(err, p);
          break;
        }
        report_progress(opt_.progress, "graphcut refine",
                        (pass + static_cast<double>(placed + 1) / per_pass) / opt_.refinement_passes);
      }
    }
  }

  // ------------------------------------------------------------------------
  // Straight-seam repair of a periodic output (GraphcutOptions::
  // straight_seam_steps; the header documents the rule).

  struct LineScore {
    double penalty = 0.0;  // sum over lines above the threshold of (ratio - threshold)^2
    double worst = 0.0;    // highest line ratio
  };
  SourceMatchedLineProfile line_profile() const {
    return source_matched_line_profile(canvas_.render(), ex_, canvas_.sx_, canvas_.sy_);
  }
  LineScore line_score(const SourceMatchedLineProfile& p) const {
    LineScore s;
    s.worst = p.worst_ratio;
    const double t = opt_.straight_seam_ratio;
    for (const std::vector<double>* v : {&p.column, &p.row})
      for (double r : *v)
        if (r > t) s.penalty += std::isfinite(r) ? (r - t) * (r - t) : 1e30;
    return s;
  }
  // Jump of the output pair (x, y) -> (x + dx, y + dy) (wrapped) minus the
  // exemplar's own jump at the same sources (as source_matched_line_profile).
  double pair_excess(int x, int y, int dx, int dy) const {
    const int W = canvas_.w_, H = canvas_.h_;
    const int x1 = (x + dx + W) % W, y1 = (y + dy + H) % H;
    const int ax = canvas_.source_x(x, y), ay = canvas_.source_y(x, y);
    const int bx = canvas_.source_x(x1, y1), by = canvas_.source_y(x1, y1);
    if (bx == ax + dx && by == ay + dy) return 0.0;
    const double j = colour_jump(ex_, ax, ay, bx, by);
    return j - source_natural_jump(ex_, ax, ay, bx, by, dx, dy, j);  // 0 when no exemplar neighbour
  }

  // The straight-seam repair's sizes: the footprint's side, the stretch of
  // line replaced, the forced band's half-width and the exclusion radius of
  // candidate offsets.
  struct SeamRepairSizes {
    int side, seg, band, radius;
  };
  SeamRepairSizes seam_repair_sizes() const {
    const int W = canvas_.w_, H = canvas_.h_;
    const int side = std::min({pw_, ph_, std::max(16, std::min(W, H) / 4)});
    return {side, std::max(2, side / 2),  // stretch of the line replaced
            std::max(1, side / 8),        // forced pixels on each side of the line
            std::max(2, side / 8)};       // offsets this close to a patch in the footprint are skipped
  }

  // A stretch of an output line: a column (x = line) or a row (y = line),
  // `seg` pixels from `start` along it (wrapping); start -1 = none.
  struct Stretch {
    bool column = true;
    int line = -1, start = -1;
  };
  // tried[orientation][line * length + start]: stretches already attempted.
  struct TriedStretches {
    std::vector<char> col, row;
  };

  // The worst untried stretch: over the lines above the threshold, worst
  // first (ties: columns, lower index), the untried start of largest summed
  // pair excess of the first line that has one.
  Stretch worst_untried_stretch(const SourceMatchedLineProfile& prof, int seg,
                                const TriedStretches& tried) const {
    const int W = canvas_.w_, H = canvas_.h_;
    std::vector<std::pair<double, int>> lines;  // (ratio, code): code < W column x, else row code - W
    for (int x = 0; x < W; ++x)
      if (prof.column[static_cast<std::size_t>(x)] > opt_.straight_seam_ratio)
        lines.emplace_back(prof.column[static_cast<std::size_t>(x)], x);
    for (int y = 0; y < H; ++y)
      if (prof.row[static_cast<std::size_t>(y)] > opt_.straight_seam_ratio)
        lines.emplace_back(prof.row[static_cast<std::size_t>(y)], W + y);
    std::stable_sort(lines.begin(), lines.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    Stretch s;
    for (const auto& l : lines) {
      s.column = l.second < W;
      s.line = s.column ? l.second : l.second - W;
      const int len = s.column ? H : W;
      const std::vector<char>& t = s.column ? tried.col : tried.row;
      // Excess of each pair of the line, then the best untried stretch.
      std::vector<double> ex(static_cast<std::size_t>(len));
      for (int k = 0; k < len; ++k)
        ex[static_cast<std::size_t>(k)] = s.column ? pair_excess((s.line + W - 1) % W, k, 1, 0)
                                                   : pair_excess(k, (s.line + H - 1) % H, 0, 1);
      double best = 0.0;
      s.start = -1;
      for (int k = 0; k < len; ++k) {
        if (t[static_cast<std::size_t>(s.line) * len + k]) continue;
        double sum = 0.0;
        for (int i = 0; i < seg; ++i) sum += ex[static_cast<std::size_t>((k + i) % len)];
        if (sum > best) {
          best = sum;
          s.start = k;
        }
      }
      if (s.start >= 0) break;
    }
    return s;
  }

  // The footprint of a stretch's repair: a side x side window centred on
  // the stretch, straddling the line, with the band of the line there
  // forced (mask 0; window coordinates i, j).
  struct SeamFootprint {
    int x0 = 0, y0 = 0;
    Image win;
    std::vector<float> mask;
    std::vector<std::pair<int, int>> forced;  // output pixels
  };
  SeamFootprint seam_footprint(const Stretch& st, const SeamRepairSizes& z) const {
    const int W = canvas_.w_, H = canvas_.h_;
    const int side = z.side, seg = z.seg, band = z.band;
    SeamFootprint f;
    const int along0 = st.start + seg / 2 - side / 2, across0 = st.line - side / 2;
    f.x0 = st.column ? across0 : along0;
    f.y0 = st.column ? along0 : across0;
    window(f.x0, f.y0, side, side, f.win, f.mask);
    const int b0 = side / 2 - band, b1 = side / 2 + band;  // across the line
    const int s0 = side / 2 - seg / 2, s1 = s0 + seg;      // along it
    // Lens-shaped band: `band` pixels each side at the middle of the
    // stretch, 1 at its ends, so that its own border is not a straight
    // line parallel to the one being repaired (measured on the 7 tiles with
    // straight seams: a rectangular band fixed as many, 6/7, at a higher
    // eq.-1 cost, 482.7 vs 468.2, with higher worst lines).
    for (int a = s0; a < s1; ++a)
      for (int c = b0; c < b1; ++c) {
        const double t = std::abs((a - s0) + 0.5 - seg / 2.0) / (seg / 2.0);
        const int hw = 1 + static_cast<int>((band - 1) * (1.0 - t) + 0.5);
        if (c < side / 2 - hw || c >= side / 2 + hw) continue;
        const int i = st.column ? c : a, j = st.column ? a : c;
        f.mask[static_cast<std::size_t>(j) * side + i] = 0.f;
        f.forced.emplace_back(((f.x0 + i) % W + W) % W, ((f.y0 + j) % H + H) % H);
      }
    return f;
  }

  // Up to 8 exemplar offsets for the footprint (codes uy * nx + ux): the
  // best by masked SSD per unmasked pixel, none within `radius` of a
  // translation already present in the footprint or of one already chosen.
  std::vector<int> seam_candidates(const SeamFootprint& f, const SeamRepairSizes& z, int& nx) {
    constexpr int kCandidates = 8;
    const int W = canvas_.w_, H = canvas_.h_;
    const int side = z.side, radius = z.radius;
    if (!matcher_) matcher_ = std::make_unique<MaskedSsdMatcher>(ex_, std::vector<float>{}, false);
    const double area = std::accumulate(f.mask.begin(), f.mask.end(), 0.0);
    const SsdMap m = matcher_->match(f.win, f.mask);
    nx = m.nx;
    std::vector<std::pair<int, int>> present;  // exemplar translations of the footprint's pixels
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) {
        const int x = ((f.x0 + i) % W + W) % W, y = ((f.y0 + j) % H + H) % H;
        const std::pair<int, int> e{canvas_.source_x(x, y) - i, canvas_.source_y(x, y) - j};
        if (std::find(present.begin(), present.end(), e) == present.end()) present.push_back(e);
      }
    std::vector<std::pair<double, int>> ranked;
    ranked.reserve(m.ssd.size());
    for (std::size_t k = 0; k < m.ssd.size(); ++k) {
      const int ux = static_cast<int>(k) % m.nx, uy = static_cast<int>(k) / m.nx;
      bool near = false;
      for (const auto& e : present)
        if (std::abs(ux - e.first) <= radius && std::abs(uy - e.second) <= radius) {
          near = true;
          break;
        }
      if (!near) ranked.emplace_back(m.ssd[k] / std::max(area, 1.0), static_cast<int>(k));
    }
    std::sort(ranked.begin(), ranked.end());
    std::vector<int> chosen;
    for (const auto& r : ranked) {
      if (static_cast<int>(chosen.size()) >= kCandidates) break;
      const int ux = r.second % m.nx, uy = r.second / m.nx;
      bool close = false;
      for (int c : chosen)
        if (std::abs(ux - c % m.nx) <= radius && std::abs(uy - c / m.nx) <= radius) close = true;
      if (!close) chosen.push_back(r.second);
    }
    return chosen;
  }

  // The limits a repair paste must keep: the eq.-1 cost budget, the initial
  // cost, and the wrap lines' roughness.
  struct SeamRepairLimits {
    double budget, cost0, wrap0;
  };

  // Pastes each candidate with a gradient-normalised cut (eq. 5) that keeps
  // the forced band, and keeps the most efficient one (line penalty removed
  // per unit of eq.-1 cost added) that stays within the budget, lowers the
  // penalty without raising the worst line, and does not roughen the wrap
  // lines; the sources are restored otherwise. Returns whether one was kept
  // (then `prof` and `score` are its).
  bool paste_best_candidate(const SeamFootprint& f, const std::vector<int>& chosen, int nx, int side,
                            const SeamRepairLimits& lim, SourceMatchedLineProfile& prof, LineScore& score) {
    const std::vector<int> keep_x = canvas_.sx_, keep_y = canvas_.sy_;
    std::vector<int> best_x, best_y;
    LineScore best_score = score;
    SourceMatchedLineProfile best_prof;
    double best_eff = 0.0;
    const double cost_now = canvas_.seam_cost();
    for (int c : chosen) {
      const PatchPlacement p{f.x0, f.y0, c % nx, c / nx, side, side};
      const bool gn = canvas_.gradient_normalized_;
      canvas_.gradient_normalized_ = true;  // eq. 5 for this cut only
      canvas_.place_graphcut(p, f.forced);
      canvas_.gradient_normalized_ = gn;
      const double cost = canvas_.seam_cost();
      SourceMatchedLineProfile np = line_profile();
      const LineScore ns = line_score(np);
      // Efficiency: penalty removed per unit of eq.-1 cost added (a paste
      // that lowers the cost counts as if it added 0.1% of the initial cost).
      const double eff = (score.penalty - ns.penalty) / std::max(cost - cost_now, 1e-3 * lim.cost0 + 1e-9);
      const bool better = best_x.empty() || eff > best_eff;
      if (cost <= lim.budget && ns.worst <= score.worst && ns.penalty < score.penalty && better &&
          wrap_seam_ratio(canvas_.render()) <= lim.wrap0) {
        best_eff = eff;
        best_x = canvas_.sx_;
        best_y = canvas_.sy_;
        best_score = ns;
        best_prof = std::move(np);
      }
      canvas_.sx_ = keep_x;
      canvas_.sy_ = keep_y;
    }
    if (best_x.empty()) return false;
    canvas_.sx_ = std::move(best_x);
    canvas_.sy_ = std::move(best_y);
    prof = std::move(best_prof);
    score = best_score;
    return true;
  }

  // Up to straight_seam_steps repairs: each takes the worst untried stretch
  // of a line above the threshold and pastes the best candidate over it
  // with the line's band forced; stops when no line is above the threshold
  // or every stretch of every bad line was tried.
  void repair_straight_seams(GraphcutResult& res) {
    if (!canvas_.periodic_ || opt_.straight_seam_steps <= 0) return;
    const int W = canvas_.w_, H = canvas_.h_;
    const double budget = canvas_.seam_cost() * (1.0 + opt_.straight_seam_cost_tolerance);
    const SeamRepairSizes z = seam_repair_sizes();
    const double cost0 = canvas_.seam_cost();
    // The output's own wrap lines (its border when it is not rolled) may not
    // get rougher than they were, or than the threshold if they were smoother.
    const double wrap0 = std::max(wrap_seam_ratio(canvas_.render()), opt_.straight_seam_ratio);
    TriedStretches tried{std::vector<char>(static_cast<std::size_t>(W) * H, 0),
                         std::vector<char>(static_cast<std::size_t>(W) * H, 0)};
    SourceMatchedLineProfile prof = line_profile();
    LineScore score = line_score(prof);
    for (int step = 0; step < opt_.straight_seam_steps; ++step) {
      if (!(score.worst > opt_.straight_seam_ratio)) break;
      const Stretch st = worst_untried_stretch(prof, z.seg, tried);
      if (st.start < 0) break;  // every stretch of every bad line tried
      ++res.straight_seam_tried;
      const int len = st.column ? H : W;
      std::vector<char>& t = st.column ? tried.col : tried.row;
      for (int d = -z.seg / 2; d <= z.seg / 2; ++d)
        t[static_cast<std::size_t>(st.line) * len +
          static_cast<std::size_t>(((st.start + d) % len + len) % len)] = 1;
      const SeamFootprint f = seam_footprint(st, z);
      int nx = 0;
      const std::vector<int> chosen = seam_candidates(f, z, nx);
      if (paste_best_candidate(f, chosen, nx, z.side, {budget, cost0, wrap0}, prof, score))
        ++res.straight_seam_accepted;
      report_progress(opt_.progress, "graphcut straight seams",
                      static_cast<double>(step + 1) / opt_.straight_seam_steps);
    }
  }

  // Recomputes the pixel seam error of the footprint of `p` and the ring of
  // pixels around it (the only pixels whose pairs a placement can change).
  void update_error(std::vector<double>& err, const PatchPlacement& p) const {
    const int W = canvas_.w_, H = canvas_.h_;
    PatchPlacement q = p;
    if (!canvas_.periodic_ && !clip_placement(q, W, H)) return;
    for (int j = -1; j <= q.height; ++j)
      for (int i = -1; i <= q.width; ++i) {
        int x = q.out_x + i, y = q.out_y + j;
        if (canvas_.periodic_) {
          x = (x % W + W) % W;
          y = (y % H + H) % H;
        } else if (x < 0 || y < 0 || x >= W || y >= H) {
          continue;
        }
        err[static_cast<std::size_t>(y) * W + x] = canvas_.pixel_seam_error(x, y);
      }
  }

  const Image& ex_;
  const GraphcutOptions& opt_;
  GraphcutCanvas canvas_;
  std::mt19937_64 rng_;
  int pw_ = 0, ph_ = 0, ov_ = 0, error_side_ = 0, match_side_ = 0;
  double sigma2_ = 0.0;
  int fill_patches_ = 0;
  std::unique_ptr<MaskedSsdMatcher> matcher_;
};

namespace {
void validate(const Image& exemplar, int width, int height, const GraphcutOptions& o) {
  if (exemplar.empty()) throw InvalidInputError("graphcut_synthesize: the exemplar is empty");
  for (float v : exemplar.data)
    if (!std::isfinite(v)) throw InvalidInputError("graphcut_synthesize: the exemplar holds a non-finite value");
  if (width <= 0 || height <= 0)
    throw InvalidInputError("graphcut_synthesize: width and height must be positive, got " +
                            std::to_string(width) + "x" + std::to_string(height));
  if (o.periodic_output && (width < 4 || height < 4))
    throw InvalidInputError("graphcut_synthesize: periodic_output needs width and height >= 4, got " +
                            std::to_string(width) + "x" + std::to_string(height));
  if (o.patch_size != 0 && o.patch_size < 4)
    throw InvalidInputError("graphcut_synthesize: patch_size must be 0 (auto) or >= 4, got " +
                            std::to_string(o.patch_size));
  if (o.overlap < 0)
    throw InvalidInputError("graphcut_synthesize: overlap must be >= 0, got " + std::to_string(o.overlap));
  if (o.patch_size > 0 && o.overlap >= o.patch_size)
    throw InvalidInputError("graphcut_synthesize: overlap (" + std::to_string(o.overlap) +
                            ") must be smaller than patch_size (" + std::to_string(o.patch_size) + ")");
  if (o.error_region < 0)
    throw InvalidInputError("graphcut_synthesize: error_region must be >= 0, got " +
                            std::to_string(o.error_region));
  if (o.refinement_passes < 0)
    throw InvalidInputError("graphcut_synthesize: refinement_passes must be >= 0, got " +
                            std::to_string(o.refinement_passes));
  if (!(o.repetition_penalty >= 0.0) || !std::isfinite(o.repetition_penalty))
    throw InvalidInputError("graphcut_synthesize: repetition_penalty must be >= 0, got " +
                            std::to_string(o.repetition_penalty));
  if (o.straight_seam_steps < 0)
    throw InvalidInputError("graphcut_synthesize: straight_seam_steps must be >= 0, got " +
                            std::to_string(o.straight_seam_steps));
  if (!(o.straight_seam_ratio > 1.0) || !std::isfinite(o.straight_seam_ratio))
    throw InvalidInputError("graphcut_synthesize: straight_seam_ratio must be > 1, got " +
                            std::to_string(o.straight_seam_ratio));
  if (!(o.straight_seam_cost_tolerance >= 0.0) || !std::isfinite(o.straight_seam_cost_tolerance))
    throw InvalidInputError("graphcut_synthesize: straight_seam_cost_tolerance must be >= 0, got " +
                            std::to_string(o.straight_seam_cost_tolerance));
  if (!(o.k > 0.0) || !std::isfinite(o.k))
    throw InvalidInputError("graphcut_synthesize: k (temperature) must be > 0, got " + std::to_string(o.k));
}
}  // namespace

GraphcutResult graphcut_synthesize_detailed(const Image& exemplar, int width, int height,
                                            const GraphcutOptions& options) {
  validate(exemplar, width, height, options);
  GraphcutSynthesizer s(exemplar, width, height, options);
  return s.run();
}

Image graphcut_synthesize(const Image& exemplar, int width, int height, const GraphcutOptions& options) {
  return graphcut_synthesize_detailed(exemplar, width, height, options).image;
}

}  // namespace surftex
