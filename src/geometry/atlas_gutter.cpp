// SPDX-License-Identifier: AGPL-3.0-or-later
// Atlas gutters filled by dilation (see atlas_gutter.h).
#include "geometry/atlas_gutter.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "geometry/errors.h"

namespace surftex {

int atlas_gutter_texels(int size, int min_mip_size) {
  if (size < 1 || min_mip_size < 1)
    throw InvalidInputError("atlas_gutter_texels: size " + std::to_string(size) + " and min_mip_size " +
                            std::to_string(min_mip_size) + " must be >= 1");
  int g = 1;
  for (int s = size; s / 2 >= min_mip_size; s /= 2) g *= 2;
  return g;
}

int next_power_of_two(int n) {
  if (n < 1 || n > 16384) throw InvalidInputError("next_power_of_two: " + std::to_string(n) + " outside 1..16384");
  int p = 1;
  while (p < n) p *= 2;
  return p;
}

namespace {

// Chessboard distance of every texel to the nearest labelled one (0 on
// them), by the two-pass chamfer with unit 8-neighbour steps (exact for this
// metric): the ring each empty texel is filled in.
std::vector<int> chessboard_distance(const std::vector<int>& label, int W, int H) {
  const int far = W + H;
  std::vector<int> d(label.size());
  for (std::size_t i = 0; i < label.size(); ++i) d[i] = label[i] >= 0 ? 0 : far;
  auto at = [&](int x, int y) -> int& { return d[static_cast<std::size_t>(y) * W + x]; };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      int& v = at(x, y);
      if (x > 0) v = std::min(v, at(x - 1, y) + 1);
      if (y > 0) {
        v = std::min(v, at(x, y - 1) + 1);
        if (x > 0) v = std::min(v, at(x - 1, y - 1) + 1);
        if (x + 1 < W) v = std::min(v, at(x + 1, y - 1) + 1);
      }
    }
  for (int y = H - 1; y >= 0; --y)
    for (int x = W - 1; x >= 0; --x) {
      int& v = at(x, y);
      if (x + 1 < W) v = std::min(v, at(x + 1, y) + 1);
      if (y + 1 < H) {
        v = std::min(v, at(x, y + 1) + 1);
        if (x + 1 < W) v = std::min(v, at(x + 1, y + 1) + 1);
        if (x > 0) v = std::min(v, at(x - 1, y + 1) + 1);
      }
    }
  return d;
}

// One ring's texel i: the majority label of its labelled 8-neighbours (ties:
// the lower) and their mean value, written to label_out / value_out.
void fill_from_inner_ring(const Image& img, const std::vector<int>& label, std::size_t i, int& label_out,
                          float* value_out) {
  const int W = img.width, H = img.height, C = img.channels;
  const int x = static_cast<int>(i % W), y = static_cast<int>(i / W);
  int labels[8], counts[8], n = 0;
  std::size_t nb[8];
  int m = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
      const std::size_t j = static_cast<std::size_t>(qy) * W + qx;
      if (label[j] < 0) continue;
      nb[m++] = j;
      int s = 0;
      while (s < n && labels[s] != label[j]) ++s;
      if (s == n) labels[n] = label[j], counts[n++] = 0;
      ++counts[s];
    }
  int best = 0;
  for (int s = 1; s < n; ++s)
    if (counts[s] > counts[best] || (counts[s] == counts[best] && labels[s] < labels[best])) best = s;
  label_out = labels[best];
  for (int c = 0; c < C; ++c) value_out[c] = 0.f;
  for (int q = 0; q < m; ++q) {
    if (label[nb[q]] != labels[best]) continue;
    for (int c = 0; c < C; ++c) value_out[c] += img.data[nb[q] * C + c];
  }
  for (int c = 0; c < C; ++c) value_out[c] /= static_cast<float>(counts[best]);
}

}  // namespace

int dilate_charts(Image& img, std::vector<int>& label) {
  const int W = img.width, H = img.height, C = img.channels;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  if (img.empty() || label.size() != N)
    throw InvalidInputError("dilate_charts: " + std::to_string(label.size()) + " labels for a " + std::to_string(W) +
                            " x " + std::to_string(H) + " image");
  if (std::none_of(label.begin(), label.end(), [](int l) { return l >= 0; }))
    throw InvalidInputError("dilate_charts: no texel belongs to a chart");
  // Ring r = the empty texels at chessboard distance r, in row-major order.
  const std::vector<int> dist = chessboard_distance(label, W, H);
  const int rings = *std::max_element(dist.begin(), dist.end());
  std::vector<std::size_t> first(static_cast<std::size_t>(rings) + 2, 0);
  for (int v : dist) ++first[static_cast<std::size_t>(v) + 1];
  for (std::size_t r = 1; r < first.size(); ++r) first[r] += first[r - 1];
  if (N > 0xffffffffu) throw InvalidInputError("dilate_charts: " + std::to_string(N) + " texels (at most 2^32 - 1)");
  std::vector<std::uint32_t> order(N);
  std::vector<std::size_t> fill = first;
  for (std::size_t i = 0; i < N; ++i) order[fill[dist[i]]++] = static_cast<std::uint32_t>(i);
  std::vector<int> new_label;
  std::vector<float> new_value;
  for (int r = 1; r <= rings; ++r) {
    const std::uint32_t* front = order.data() + first[r];
    const std::size_t n = first[r + 1] - first[r];
    new_label.assign(n, -1);
    new_value.assign(n * C, 0.f);
    // Each texel of the ring from the ring inside it: independent, in parallel
    // (each writes its own slot: the same bytes for any thread count).
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t k = b.begin(); k < b.end(); ++k)
        fill_from_inner_ring(img, label, front[k], new_label[k], new_value.data() + k * C);
    });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t k = b.begin(); k < b.end(); ++k) {
        label[front[k]] = new_label[k];
        for (int c = 0; c < C; ++c) img.data[front[k] * C + c] = new_value[k * C + c];
      }
    });
  }
  return rings;
}

namespace {

// Minimum and maximum of in[q] over q in [x - g, x + g] (clipped to the
// line) for every x, in O(n) whatever g (van Herk / Gil-Werman: prefix and
// suffix extrema within blocks of the window's width on the padded line).
// Neutral values: lo_none for the minimum, hi_none for the maximum.
void window_extrema(const std::vector<int>& in_lo, const std::vector<int>& in_hi, int g, int lo_none,
                    int hi_none, std::vector<int>& out_lo, std::vector<int>& out_hi) {
  const int n = static_cast<int>(in_lo.size()), w = 2 * g + 1, m = n + 2 * g;
  std::vector<int> pl(m, lo_none), ph(m, hi_none);
  std::copy(in_lo.begin(), in_lo.end(), pl.begin() + g);
  std::copy(in_hi.begin(), in_hi.end(), ph.begin() + g);
  std::vector<int> rl(m), rh(m), ll(m), lh(m);  // prefix (r) and suffix (l) extrema per block
  for (int i = 0; i < m; ++i) {
    const bool start = i % w == 0;
    rl[i] = start ? pl[i] : std::min(rl[i - 1], pl[i]);
    rh[i] = start ? ph[i] : std::max(rh[i - 1], ph[i]);
  }
  for (int i = m - 1; i >= 0; --i) {
    const bool end = i == m - 1 || (i + 1) % w == 0;
    ll[i] = end ? pl[i] : std::min(ll[i + 1], pl[i]);
    lh[i] = end ? ph[i] : std::max(lh[i + 1], ph[i]);
  }
  out_lo.resize(n);
  out_hi.resize(n);
  for (int x = 0; x < n; ++x) {
    out_lo[x] = std::min(ll[x], rl[x + w - 1]);
    out_hi[x] = std::max(lh[x], rh[x + w - 1]);
  }
}

}  // namespace

std::size_t gutter_violations(const std::vector<int>& chart, const std::vector<int>& fin, int W, int H, int g) {
  const std::size_t N = static_cast<std::size_t>(W) * H;
  if (chart.size() != N || fin.size() != N) throw InvalidInputError("gutter_violations: label sizes do not match");
  if (g < 0) throw InvalidInputError("gutter_violations: gutter " + std::to_string(g) + " < 0");
  // Smallest and largest chart label within Chebyshev distance g of every
  // texel (separable: rows, then columns); a texel near one chart only must
  // carry that chart's label, a texel near two charts is a violation anyway.
  const int none_lo = std::numeric_limits<int>::max(), none_hi = -1;
  std::vector<int> lo(N), hi(N);
  tbb::parallel_for(0, H, [&](int y) {
    std::vector<int> a(W), b(W), ra, rb;
    for (int x = 0; x < W; ++x) {
      const int c = chart[static_cast<std::size_t>(y) * W + x];
      a[x] = c >= 0 ? c : none_lo;
      b[x] = c >= 0 ? c : none_hi;
    }
    window_extrema(a, b, g, none_lo, none_hi, ra, rb);
    std::copy(ra.begin(), ra.end(), lo.begin() + static_cast<std::ptrdiff_t>(y) * W);
    std::copy(rb.begin(), rb.end(), hi.begin() + static_cast<std::ptrdiff_t>(y) * W);
  });
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, W), std::size_t(0),
      [&](const tbb::blocked_range<int>& r, std::size_t bad) {
        std::vector<int> a(H), b(H), ra, rb;
        for (int x = r.begin(); x < r.end(); ++x) {
          for (int y = 0; y < H; ++y) {
            a[y] = lo[static_cast<std::size_t>(y) * W + x];
            b[y] = hi[static_cast<std::size_t>(y) * W + x];
          }
          window_extrema(a, b, g, none_lo, none_hi, ra, rb);
          for (int y = 0; y < H; ++y) {
            if (rb[y] < 0) continue;  // no chart within g
            const int f = fin[static_cast<std::size_t>(y) * W + x];
            bad += ra[y] != rb[y] || f != ra[y];
          }
        }
        return bad;
      },
      std::plus<std::size_t>());
}

}  // namespace surftex
