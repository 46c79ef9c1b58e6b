// SPDX-License-Identifier: AGPL-3.0-or-later
// rasterize_uv_triangles against its definition (uv_raster.h), and the same
// raster for one and two threads (it runs over bands of rows in parallel).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>
#include <random>

#include "geometry/uv_raster.h"

namespace surftex {
namespace {

// Overlapping random triangles (overlaps exercise "the first in index order"),
// some of them tiny, some zero-area, some reaching outside [0,1]^2.
std::vector<UvTriangle> random_triangles(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-0.05, 1.05), size(0.002, 0.15);
  std::vector<UvTriangle> tris;
  for (int i = 0; i < n; ++i) {
    const double cx = pos(rng), cy = pos(rng), s = size(rng);
    UvTriangle t;
    for (auto& c : t) c = {cx + s * (pos(rng) - 0.5), cy + s * (pos(rng) - 0.5)};
    if (i % 37 == 0) t[2] = t[1];  // zero area
    tris.push_back(t);
  }
  return tris;
}

// Pass 1 of the header's definition, texel by texel: the first triangle in
// index order whose closed area holds the texel centre (to a tolerance the
// rasteriser's 1e-9 shares).
int first_holder(const std::vector<UvTriangle>& tris, int W, int H, int x, int y) {
  const double qx = x + 0.5, qy = y + 0.5;
  for (std::size_t t = 0; t < tris.size(); ++t) {
    double px[3], py[3];
    for (int k = 0; k < 3; ++k) px[k] = tris[t][k][0] * W, py[k] = (1.0 - tris[t][k][1]) * H;
    const double area = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    if (!(std::abs(area) > 1e-12)) continue;
    const double b1 = ((qx - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (qy - py[0])) / area;
    const double b2 = ((px[1] - px[0]) * (qy - py[0]) - (qx - px[0]) * (py[1] - py[0])) / area;
    if (1 - b1 - b2 >= -1e-9 && b1 >= -1e-9 && b2 >= -1e-9) return static_cast<int>(t);
  }
  return -1;
}

TEST(UvRaster, EachTexelTakesTheFirstTriangleHoldingItsCentre) {
  const int W = 97, H = 75;  // not a multiple of the row bands
  const auto tris = random_triangles(300, 7);
  const UvRaster r = rasterize_uv_triangles(tris, W, H, 0.0);
  std::size_t inside = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int want = first_holder(tris, W, H, x, y);
      ASSERT_EQ(r.triangle[static_cast<std::size_t>(y) * W + x], want) << "texel " << x << ", " << y;
      inside += want >= 0;
    }
  EXPECT_EQ(r.inside, inside);
  EXPECT_GT(inside, std::size_t(W * H / 8));
  EXPECT_EQ(r.band, 0u);
}

TEST(UvRaster, TheBandIsTheNearestTriangleWithinIt) {
  const int W = 64, H = 50;
  const auto tris = random_triangles(40, 3);
  const UvRaster r = rasterize_uv_triangles(tris, W, H, 1.5);
  const UvRaster inner = rasterize_uv_triangles(tris, W, H, 0.0);
  std::size_t band = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      if (inner.triangle[i] >= 0) {
        EXPECT_EQ(r.triangle[i], inner.triangle[i]);
        continue;
      }
      if (r.triangle[i] < 0) continue;
      ++band;
      // The point the band texel took lies within 1.5 texels of its centre.
      const auto& t = tris[r.triangle[i]];
      const auto& b = r.bary[i];
      double u = 0, v = 0;
      for (int k = 0; k < 3; ++k) u += b[k] * t[k][0], v += b[k] * t[k][1];
      EXPECT_LE(std::hypot(u * W - (x + 0.5), (1.0 - v) * H - (y + 0.5)), 1.5 + 1e-4);
    }
  EXPECT_EQ(r.band, band);
  EXPECT_GT(band, 0u);
}

TEST(UvRaster, OneAndTwoThreadsGiveTheSameRaster) {
  const auto tris = random_triangles(3000, 11);
  UvRaster one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = rasterize_uv_triangles(tris, 509, 300, 1.0);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = rasterize_uv_triangles(tris, 509, 300, 1.0);
  }
  EXPECT_EQ(one.triangle, two.triangle);
  ASSERT_EQ(one.bary.size(), two.bary.size());
  for (std::size_t i = 0; i < one.bary.size(); ++i) ASSERT_EQ(one.bary[i], two.bary[i]) << i;
  EXPECT_EQ(one.inside, two.inside);
  EXPECT_EQ(one.band, two.band);
}

}  // namespace
}  // namespace surftex
