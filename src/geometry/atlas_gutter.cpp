// SPDX-License-Identifier: AGPL-3.0-or-later
// Atlas gutters filled by dilation (see atlas_gutter.h).
#include "geometry/atlas_gutter.h"

#include <algorithm>
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
    for (std::size_t k = 0; k < front.size(); ++k) {
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
        if (counts[s] > counts[best] || (counts[s] == counts[best] && labels[s] < labels[best])) best = s;
      new_label[k] = labels[best];
      for (int q = 0; q < m; ++q) {
        if (label[nb[q]] != labels[best]) continue;
        for (int c = 0; c < C; ++c) new_value[k * C + c] += img.data[nb[q] * C + c];
      }
      for (int c = 0; c < C; ++c) new_value[k * C + c] /= static_cast<float>(counts[best]);
    }
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

std::size_t gutter_violations(const std::vector<int>& chart, const std::vector<int>& fin, int W, int H, int g) {
  const std::size_t N = static_cast<std::size_t>(W) * H;
  if (chart.size() != N || fin.size() != N) throw InvalidInputError("gutter_violations: label sizes do not match");
  // Smallest and largest chart label within Chebyshev distance g of every
  // texel (separable: rows, then columns); a texel near one chart only must
  // carry that chart's label, a texel near two charts is a violation anyway.
  const int none_lo = std::numeric_limits<int>::max(), none_hi = -1;
  std::vector<int> lo(N, none_lo), hi(N, none_hi);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      int a = none_lo, b = none_hi;
      for (int q = std::max(0, x - g); q <= std::min(W - 1, x + g); ++q) {
        const int c = chart[static_cast<std::size_t>(y) * W + q];
        if (c >= 0) a = std::min(a, c), b = std::max(b, c);
      }
      lo[static_cast<std::size_t>(y) * W + x] = a;
      hi[static_cast<std::size_t>(y) * W + x] = b;
    }
  std::size_t bad = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      int a = none_lo, b = none_hi;
      for (int q = std::max(0, y - g); q <= std::min(H - 1, y + g); ++q) {
        a = std::min(a, lo[static_cast<std::size_t>(q) * W + x]);
        b = std::max(b, hi[static_cast<std::size_t>(q) * W + x]);
      }
      if (b < 0) continue;  // no chart within g
      const int f = fin[static_cast<std::size_t>(y) * W + x];
      bad += a != b || f != a;
    }
  return bad;
}

}  // namespace surftex
