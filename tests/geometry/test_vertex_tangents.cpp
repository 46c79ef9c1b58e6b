// SPDX-License-Identifier: AGPL-3.0-or-later
// Tangent frames for normal maps, uv-space atlas rasterisation and gutters
// (issue 16 items 2-3).
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/atlas_gutter.h"
#include "geometry/errors.h"
#include "geometry/uv_raster.h"
#include "geometry/vertex_tangents.h"

namespace surftex {
namespace {

// A quad in the z = 0 plane, normal +z. uv = (x, y): the tangent is +x and
// cross(N, T) = +y = +v, so w = +1; mirrored uv (u = -x) gives T = -x, w = -1.
TEST(VertexTangents, FollowUAndSayWhetherVIsMirrored) {
  const std::vector<std::array<float, 3>> p{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const std::vector<std::array<float, 3>> n(4, {0, 0, 1});
  const std::vector<std::uint32_t> tri{0, 1, 2, 0, 2, 3};
  std::vector<std::array<float, 2>> uv{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (const auto& t : vertex_tangents(p, n, uv, tri)) {
    EXPECT_NEAR(t[0], 1.f, 1e-6);
    EXPECT_NEAR(t[1], 0.f, 1e-6);
    EXPECT_EQ(t[3], 1.f);
  }
  for (auto& q : uv) q[0] = -q[0];
  for (const auto& t : vertex_tangents(p, n, uv, tri)) {
    EXPECT_NEAR(t[0], -1.f, 1e-6);
    EXPECT_EQ(t[3], -1.f);
  }
  // Rotated uv (u along +y): the tangent turns with it.
  uv = {{0, 0}, {0, -1}, {1, -1}, {1, 0}};
  for (const auto& t : vertex_tangents(p, n, uv, tri)) {
    EXPECT_NEAR(t[1], 1.f, 1e-6);
    EXPECT_EQ(t[3], 1.f);
  }
  EXPECT_THROW(vertex_tangents(p, n, uv, {0, 1, 7}), InvalidInputError);
}

TEST(UvRaster, CoversEachTexelOnceAndAddsABand) {
  // Two triangles tiling the square [0.25, 0.75]^2 of a 16 x 16 grid: the
  // 8 x 8 texels inside, each once, and a one-texel band around them.
  const std::vector<UvTriangle> t{{{{0.25, 0.25}, {0.75, 0.25}, {0.75, 0.75}}},
                                  {{{0.25, 0.25}, {0.75, 0.75}, {0.25, 0.75}}}};
  const UvRaster r = rasterize_uv_triangles(t, 16, 16, 1.0);
  EXPECT_EQ(r.inside, 64u);
  EXPECT_EQ(r.band, 10u * 10u - 64u);  // centres within one texel of the square, corners included
  for (int y = 4; y < 12; ++y)
    for (int x = 4; x < 12; ++x) EXPECT_GE(r.triangle[y * 16 + x], 0);
  EXPECT_EQ(r.triangle[0], -1);
  EXPECT_THROW(rasterize_uv_triangles(t, 0, 16), InvalidInputError);
}

TEST(AtlasGutter, PowerOfTwoGutterAndChartOwnedDilation) {
  EXPECT_EQ(atlas_gutter_texels(2048), 32);
  EXPECT_EQ(atlas_gutter_texels(1024), 16);
  EXPECT_EQ(atlas_gutter_texels(64), 1);
  EXPECT_EQ(atlas_gutter_texels(100), 1);
  EXPECT_EQ(next_power_of_two(300), 512);
  // Two one-texel charts 9 texels apart on a 16 x 1 strip: each owns the 4
  // texels on its side; everything is filled with its chart's value.
  Image img(16, 1, 1, 0.f);
  std::vector<int> label(16, -1);
  img.at(3, 0) = 1.f, label[3] = 0;
  img.at(12, 0) = 2.f, label[12] = 1;
  const std::vector<int> chart = label;
  dilate_charts(img, label);
  for (int x = 0; x < 16; ++x) {
    EXPECT_EQ(label[x], x < 8 ? 0 : 1) << x;
    EXPECT_EQ(img.at(x, 0), x < 8 ? 1.f : 2.f) << x;
  }
  EXPECT_EQ(gutter_violations(chart, label, 16, 1, 4), 0u);
  EXPECT_GT(gutter_violations(chart, label, 16, 1, 5), 0u);  // 5 texels would reach the other chart
}

}  // namespace
}  // namespace surftex
