// SPDX-License-Identifier: AGPL-3.0-or-later
// Atlas gutters filled by dilation (see atlas_gutter.h).
#include "geometry/atlas_gutter.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
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

int dilate_charts(Image& img, std::vector<int>& label) {
  const int W = img.width, H = img.height, C = img.channels;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  if (img.empty() || label.size() != N)
    throw InvalidInputError("dilate_charts: " + std::to_string(label.size()) + " labels for a " + std::to_string(W) +
                            " x " + std::to_string(H) + " image");
  std::vector<std::size_t> front;
  std::vector<char> queued(N, 0);
  auto push_neighbours = [&](std::size_t i, std::vector<std::size_t>& out) {
    const int x = static_cast<int>(i % W), y = static_cast<int>(i / W);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int qx = x + dx, qy = y + dy;
        if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
        const std::size_t j = static_cast<std::size_t>(qy) * W + qx;
        if (label[j] < 0 && !queued[j]) queued[j] = 1, out.push_back(j);
      }
  };
  bool any = false;
  for (std::size_t i = 0; i < N; ++i)
    if (label[i] >= 0) any = true, push_neighbours(i, front);
  if (!any) throw InvalidInputError("dilate_charts: no texel belongs to a chart");
  int rings = 0;
  std::vector<int> new_label;
  std::vector<float> new_value;
  while (!front.empty()) {
    std::sort(front.begin(), front.end());  // deterministic order of the next ring
    new_label.assign(front.size(), -1);
    new_value.assign(front.size() * C, 0.f);
    // Each texel of the ring from the ring inside it: independent, in parallel
    // (each writes its own slot: the same bytes for any thread count).
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, front.size(), 4096),
        [&](const tbb::blocked_range<std::size_t>& r) {
          for (std::size_t k = r.begin(); k < r.end(); ++k) {
            const std::size_t i = front[k];
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
              if (counts[s] > counts[best] || (counts[s] == counts[best] && labels[s] < labels[best]))
                best = s;
            new_label[k] = labels[best];
            for (int q = 0; q < m; ++q) {
              if (label[nb[q]] != labels[best]) continue;
              for (int c = 0; c < C; ++c) new_value[k * C + c] += img.data[nb[q] * C + c];
            }
            for (int c = 0; c < C; ++c) new_value[k * C + c] /= static_cast<float>(counts[best]);
          }
        });
    for (std::size_t k = 0; k < front.size(); ++k) {
      label[front[k]] = new_label[k];
      for (int c = 0; c < C; ++c) img.data[front[k] * C + c] = new_value[k * C + c];
    }
    std::vector<std::size_t> next;
    for (std::size_t i : front) push_neighbours(i, next);
    front.swap(next);
    ++rings;
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
