// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/wrap_seam_ratio.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "geometry/errors.h"

namespace surftex {

double colour_jump(const Image& img, int x0, int y0, int x1, int y1) {
  const float* a = img.pixel(x0, y0);
  const float* b = img.pixel(x1, y1);
  double s = 0.0;
  for (int c = 0; c < img.channels; ++c) {
    const double d = static_cast<double>(a[c]) - b[c];
    s += d * d;
  }
  return std::sqrt(s);
}

double source_natural_jump(const Image& ex, int ax, int ay, int bx, int by, int dx, int dy, double fallback) {
  auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < ex.width && y < ex.height; };
  double nat = 0.0;
  int terms = 0;
  if (inside(ax + dx, ay + dy)) {
    nat += colour_jump(ex, ax, ay, ax + dx, ay + dy);
    ++terms;
  }
  if (inside(bx - dx, by - dy)) {
    nat += colour_jump(ex, bx - dx, by - dy, bx, by);
    ++terms;
  }
  return terms > 0 ? nat / terms : fallback;
}

WrapSeamStats wrap_seam_stats(const Image& img) {
  if (img.empty() || img.width < 2 || img.height < 2)
    throw InvalidInputError("wrap_seam_ratio: the image must be at least 2x2, got " +
                            std::to_string(img.width) + "x" + std::to_string(img.height));
  const int W = img.width, H = img.height;
  double inside = 0.0, wrap = 0.0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (x + 1 < W) inside += colour_jump(img, x, y, x + 1, y);
      if (y + 1 < H) inside += colour_jump(img, x, y, x, y + 1);
    }
  for (int y = 0; y < H; ++y) wrap += colour_jump(img, W - 1, y, 0, y);
  for (int x = 0; x < W; ++x) wrap += colour_jump(img, x, H - 1, x, 0);
  WrapSeamStats s;
  s.inside_mean = inside / (static_cast<double>(W - 1) * H + static_cast<double>(W) * (H - 1));
  s.wrap_mean = wrap / static_cast<double>(W + H);
  if (s.inside_mean > 0.0)
    s.ratio = s.wrap_mean / s.inside_mean;
  else
    s.ratio = s.wrap_mean > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
  return s;
}

double wrap_seam_ratio(const Image& img) { return wrap_seam_stats(img).ratio; }

namespace {

// The n x n window of `img` whose top-left pixel is (x0, y0), read wrapping.
std::vector<float> wrapped_window(const Image& img, int x0, int y0, int n) {
  const int W = img.width, H = img.height, C = img.channels;
  std::vector<float> w(static_cast<std::size_t>(n) * n * C);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const float* p = img.pixel(((x0 + i) % W + W) % W, ((y0 + j) % H + H) % H);
      std::copy(p, p + C, w.begin() + (static_cast<std::ptrdiff_t>(j) * n + i) * C);
    }
  return w;
}

// The mean squared difference (per pixel, summed over channels) between the
// window `q` at (qx, qy) and its nearest window lying wholly inside `img`,
// leaving out the windows that overlap (qx, qy) on the torus. Candidates on
// every pixel up to 128 px a side, else on every (side / 128)-th (the
// verdict runs on the input exemplar: a 4096 px one would otherwise cost
// minutes; the wrap and the interior windows are searched alike).
double nearest_interior_window(const Image& img, const std::vector<float>& q, int qx, int qy, int n) {
  const int W = img.width, H = img.height, C = img.channels;
  const int step = std::max(1, std::min(W, H) / 128);
  qx = (qx % W + W) % W, qy = (qy % H + H) % H;
  double best = std::numeric_limits<double>::infinity();
  for (int y = 0; y + n <= H; y += step) {
    const int dy = std::min(std::abs(y - qy), H - std::abs(y - qy));
    for (int x = 0; x + n <= W; x += step) {
      const int dx = std::min(std::abs(x - qx), W - std::abs(x - qx));
      if (dx < n && dy < n) continue;
      double d = 0.0;
      for (int j = 0; j < n && d < best; ++j) {
        const float* r = img.pixel(x, y + j);
        const float* a = q.data() + static_cast<std::ptrdiff_t>(j) * n * C;
        for (int k = 0; k < n * C; ++k) d += double(r[k] - a[k]) * double(r[k] - a[k]);
      }
      best = std::min(best, d);
    }
  }
  return best / (static_cast<double>(n) * n);
}

double window_nn(const Image& img, int x0, int y0, int n) {
  return nearest_interior_window(img, wrapped_window(img, x0, y0, n), x0, y0, n);
}

}  // namespace

WrapWindowStats wrap_window_stats(const Image& img, int n, int per_line) {
  if (n < 1 || per_line < 1)
    throw InvalidInputError("wrap_window_stats: window and windows_per_line must be >= 1 (got " +
                            std::to_string(n) + ", " + std::to_string(per_line) + ")");
  if (img.empty() || img.width < 2 * n + 1 || img.height < 2 * n + 1)
    throw InvalidInputError("wrap_window_stats: the image must be at least " + std::to_string(2 * n + 1) +
                            " pixels on a side for " + std::to_string(n) + "-pixel windows, got " +
                            std::to_string(img.width) + "x" + std::to_string(img.height));
  const int W = img.width, H = img.height, h = n / 2;
  WrapWindowStats s;
  // Wrap windows: the seam between their columns (rows) h and h + 1.
  for (int i = 0; i < per_line; ++i) {
    s.wrap_nn += window_nn(img, W - h - 1, (2 * i + 1) * H / (2 * per_line) - h, n);
    s.wrap_nn += window_nn(img, (2 * i + 1) * W / (2 * per_line) - h, H - h - 1, n);
  }
  s.wrap_nn /= 2.0 * per_line;
  constexpr int kGrid = 8;  // interior windows: an 8 x 8 grid, borders included
  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i < kGrid; ++i)
      s.interior_nn += window_nn(img, i * (W - n) / (kGrid - 1), j * (H - n) / (kGrid - 1), n);
  s.interior_nn /= kGrid * kGrid;
  if (s.interior_nn > 0.0)
    s.ratio = s.wrap_nn / s.interior_nn;
  else
    s.ratio = s.wrap_nn > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
  return s;
}

namespace {

// Check 1 of wrap_verdict: each wrap line jumps no more than the most
// contrasted interior line of its orientation.
bool wrap_lines_within_interior(const Image& img) {
  if (img.width < 3 || img.height < 3) return false;
  const LineJumpProfile torus = line_jump_profile(img, true), inside = line_jump_profile(img, false);
  const double col = *std::max_element(inside.column.begin() + 1, inside.column.end());
  const double row = *std::max_element(inside.row.begin() + 1, inside.row.end());
  return torus.column[0] <= col && torus.row[0] <= row;
}

}  // namespace

WrapVerdict wrap_verdict(const Image& img, double threshold, int window) {
  if (!(threshold > 0.0))
    throw InvalidInputError("wrap_verdict: threshold must be > 0 (got " + std::to_string(threshold) + ")");
  WrapVerdict v;
  v.seam_ratio = wrap_seam_ratio(img);
  v.seamless = v.seam_ratio <= threshold;
  if (v.seamless) return v;
  v.lines_within_interior = wrap_lines_within_interior(img);
  if (!v.lines_within_interior || window < 1 || img.width < 2 * window + 1 || img.height < 2 * window + 1)
    return v;
  v.window_ratio = wrap_window_stats(img, window).ratio;
  v.seamless = v.window_ratio <= threshold;
  return v;
}

LineJumpProfile line_jump_profile(const Image& img, bool periodic) {
  const int min_side = periodic ? 2 : 3;
  if (img.empty() || img.width < min_side || img.height < min_side)
    throw InvalidInputError(std::string("line_jump_profile: the image must be at least ") +
                            (periodic ? "2x2" : "3x3") + ", got " + std::to_string(img.width) + "x" +
                            std::to_string(img.height));
  const int W = img.width, H = img.height;
  LineJumpProfile p;
  p.periodic = periodic;
  p.column.assign(static_cast<std::size_t>(W), 0.0);
  p.row.assign(static_cast<std::size_t>(H), 0.0);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (periodic || x > 0) p.column[static_cast<std::size_t>(x)] += colour_jump(img, (x + W - 1) % W, y, x, y);
      if (periodic || y > 0) p.row[static_cast<std::size_t>(y)] += colour_jump(img, x, (y + H - 1) % H, x, y);
    }
  const int first = periodic ? 0 : 1;
  for (double& c : p.column) c /= H;
  for (double& r : p.row) r /= W;
  for (int x = first; x < W; ++x) p.column_mean += p.column[static_cast<std::size_t>(x)];
  for (int y = first; y < H; ++y) p.row_mean += p.row[static_cast<std::size_t>(y)];
  p.column_mean /= W - first;
  p.row_mean /= H - first;
  auto ratio = [](double v, double mean) {
    if (mean > 0.0) return v / mean;
    return v > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
  };
  p.worst_ratio = -1.0;
  p.worst_column_ratio = p.worst_row_ratio = -1.0;
  for (int x = first; x < W; ++x) {
    const double r = ratio(p.column[static_cast<std::size_t>(x)], p.column_mean);
    p.worst_column_ratio = std::max(p.worst_column_ratio, r);
    if (r > p.worst_ratio) {
      p.worst_ratio = r;
      p.worst_is_column = true;
      p.worst_index = x;
    }
  }
  for (int y = first; y < H; ++y) {
    const double r = ratio(p.row[static_cast<std::size_t>(y)], p.row_mean);
    p.worst_row_ratio = std::max(p.worst_row_ratio, r);
    if (r > p.worst_ratio) {
      p.worst_ratio = r;
      p.worst_is_column = false;
      p.worst_index = y;
    }
  }
  if (periodic) {
    p.wrap_column_ratio = ratio(p.column[0], p.column_mean);
    p.wrap_row_ratio = ratio(p.row[0], p.row_mean);
  }
  return p;
}

double worst_line_ratio(const Image& img) { return line_jump_profile(img, true).worst_ratio; }

double rolled_wrap_seam_ratio(const LineJumpProfile& p, int x, int y) {
  const int W = static_cast<int>(p.column.size()), H = static_cast<int>(p.row.size());
  if (!p.periodic || W < 2 || H < 2)
    throw InvalidInputError("rolled_wrap_seam_ratio: needs the profile of a periodic image (line_jump_profile(img, true))");
  if (x < 0 || x >= W || y < 0 || y >= H)
    throw InvalidInputError("rolled_wrap_seam_ratio: line (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") outside the " + std::to_string(W) + "x" + std::to_string(H) + " torus");
  // Summed jumps: every horizontal pair lies on one column line (H per line),
  // every vertical pair on one row line (W per line).
  const double h_all = p.column_mean * W * H, v_all = p.row_mean * W * H;
  const double h_wrap = p.column[static_cast<std::size_t>(x)] * H, v_wrap = p.row[static_cast<std::size_t>(y)] * W;
  const double wrap_mean = (h_wrap + v_wrap) / (W + H);
  const double inside_mean =
      (h_all - h_wrap + v_all - v_wrap) / (static_cast<double>(W - 1) * H + static_cast<double>(W) * (H - 1));
  if (inside_mean > 0.0) return wrap_mean / inside_mean;
  return wrap_mean > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
}

SourceMatchedLineProfile source_matched_line_profile(const Image& img, const Image& ex,
                                                     const std::vector<int>& sx, const std::vector<int>& sy) {
  if (img.empty() || img.width < 2 || img.height < 2)
    throw InvalidInputError("source_matched_line_profile: the image must be at least 2x2, got " +
                            std::to_string(img.width) + "x" + std::to_string(img.height));
  const int W = img.width, H = img.height;
  const std::size_t n = static_cast<std::size_t>(W) * H;
  if (sx.size() != n || sy.size() != n)
    throw InvalidInputError("source_matched_line_profile: source maps have " + std::to_string(sx.size()) + " and " +
                            std::to_string(sy.size()) + " entries, the image " + std::to_string(n));
  if (ex.channels != img.channels)
    throw InvalidInputError("source_matched_line_profile: exemplar has " + std::to_string(ex.channels) +
                            " channels, the image " + std::to_string(img.channels));
  for (std::size_t i = 0; i < n; ++i)
    if (sx[i] < 0 || sy[i] < 0 || sx[i] >= ex.width || sy[i] >= ex.height)
      throw InvalidInputError("source_matched_line_profile: source (" + std::to_string(sx[i]) + ", " +
                              std::to_string(sy[i]) + ") of pixel " + std::to_string(i) + " is outside the " +
                              std::to_string(ex.width) + "x" + std::to_string(ex.height) + " exemplar");
  SourceMatchedLineProfile p;
  std::vector<double> cj(static_cast<std::size_t>(W), 0.0), cn(cj), rj(static_cast<std::size_t>(H), 0.0), rn(rj);
  // One pair: s = (x0, y0), t = s + (dx, dy) on the torus (t = (x1, y1)).
  auto pair = [&](int x0, int y0, int x1, int y1, int dx, int dy, double& sum_jump, double& sum_natural) {
    const std::size_t a = static_cast<std::size_t>(y0) * W + x0, b = static_cast<std::size_t>(y1) * W + x1;
    const double j = colour_jump(img, x0, y0, x1, y1);
    const int ax = sx[a], ay = sy[a], bx = sx[b], by = sy[b];
    if (!(bx == ax + dx && by == ay + dy)) ++p.seam_pairs;
    sum_jump += j;
    sum_natural += source_natural_jump(ex, ax, ay, bx, by, dx, dy, j);
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      pair((x + W - 1) % W, y, x, y, 1, 0, cj[static_cast<std::size_t>(x)], cn[static_cast<std::size_t>(x)]);
      pair(x, (y + H - 1) % H, x, y, 0, 1, rj[static_cast<std::size_t>(y)], rn[static_cast<std::size_t>(y)]);
    }
  auto ratio = [](double j, double nat) {
    if (nat > 0.0) return j / nat;
    return j > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
  };
  p.column.resize(cj.size());
  p.row.resize(rj.size());
  p.worst_ratio = -1.0;
  for (int x = 0; x < W; ++x) {
    p.column[static_cast<std::size_t>(x)] = ratio(cj[static_cast<std::size_t>(x)], cn[static_cast<std::size_t>(x)]);
    if (p.column[static_cast<std::size_t>(x)] > p.worst_ratio) {
      p.worst_ratio = p.column[static_cast<std::size_t>(x)];
      p.worst_is_column = true;
      p.worst_index = x;
    }
  }
  for (int y = 0; y < H; ++y) {
    p.row[static_cast<std::size_t>(y)] = ratio(rj[static_cast<std::size_t>(y)], rn[static_cast<std::size_t>(y)]);
    if (p.row[static_cast<std::size_t>(y)] > p.worst_ratio) {
      p.worst_ratio = p.row[static_cast<std::size_t>(y)];
      p.worst_is_column = false;
      p.worst_index = y;
    }
  }
  p.wrap_ratio = ratio(cj[0] + rj[0], cn[0] + rn[0]);
  return p;
}

}  // namespace surftex
