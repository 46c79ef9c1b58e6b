// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/errors.h"
#include "texture/procedural_texture.h"

using namespace surftex;

namespace {
// Mean absolute jump across the wrap (last column -> first, last row -> first)
// and between interior neighbours.
std::pair<double, double> wrap_and_inner_jumps(const Image& img) {
  double wrap = 0, inner = 0;
  long nw = 0, ni = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < img.channels; ++c) {
        double dx = std::abs(img.at(x, y, c) - img.at_wrap(x + 1, y, c));
        double dy = std::abs(img.at(x, y, c) - img.at_wrap(x, y + 1, c));
        if (x == img.width - 1) { wrap += dx; ++nw; } else { inner += dx; ++ni; }
        if (y == img.height - 1) { wrap += dy; ++nw; } else { inner += dy; ++ni; }
      }
  return {wrap / nw, inner / ni};
}
}  // namespace

TEST(ProceduralTexture, EveryPatternTiles) {
  for (const Image& img : {make_stripes(64, 8, 30), make_noise(64, 4, 7), make_cells(64, 4, 7)}) {
    auto [wrap, inner] = wrap_and_inner_jumps(img);
    EXPECT_LT(wrap, 1.6 * inner + 1e-3);
  }
}

TEST(ProceduralTexture, SameSeedSameBytesOtherSeedDiffers) {
  EXPECT_EQ(make_noise(32, 4, 3).data, make_noise(32, 4, 3).data);
  EXPECT_NE(make_noise(32, 4, 3).data, make_noise(32, 4, 4).data);
  EXPECT_EQ(make_cells(32, 4, 3).data, make_cells(32, 4, 3).data);
}

TEST(ProceduralTexture, HorizontalStripesVaryOnlyAlongY) {
  Image s = make_stripes(32, 8, 0);
  for (int y = 0; y < 32; ++y)
    for (int x = 1; x < 32; ++x) EXPECT_FLOAT_EQ(s.at(x, y), s.at(0, y));
  double range = 0;
  for (int y = 0; y < 32; ++y) range = std::max(range, std::abs(double(s.at(0, y)) - s.at(0, 0)));
  EXPECT_GT(range, 0.5);
}

TEST(ProceduralTexture, InvalidParametersThrow) {
  EXPECT_THROW(make_stripes(64, 1.0, 0), InvalidInputError);
  EXPECT_THROW(make_noise(2, 1, 0), InvalidInputError);
  EXPECT_THROW(make_cells(64, 0, 0), InvalidInputError);
}
