// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/errors.h"
#include "texture/procedural_texture.h"

using namespace surftex;

namespace {
// Mean absolute jump between column x and x+1 (wrapping), and between row y and y+1.
double column_jump(const Image& img, int x) {
  double s = 0;
  for (int y = 0; y < img.height; ++y)
    for (int c = 0; c < img.channels; ++c) s += std::abs(img.at(x, y, c) - img.at_wrap(x + 1, y, c));
  return s / (img.height * img.channels);
}
double row_jump(const Image& img, int y) {
  double s = 0;
  for (int x = 0; x < img.width; ++x)
    for (int c = 0; c < img.channels; ++c) s += std::abs(img.at(x, y, c) - img.at_wrap(x, y + 1, c));
  return s / (img.width * img.channels);
}
}  // namespace

// A tiling image is continuous across the wrap: the jump there is no larger
// than the largest jump between interior columns / rows.
TEST(ProceduralTexture, EveryPatternTiles) {
  for (const Image& img : {make_stripes(64, 8, 30), make_noise(64, 4, 7), make_cells(64, 4, 7)}) {
    double max_col = 0, max_row = 0;
    for (int i = 0; i + 1 < img.width; ++i) max_col = std::max(max_col, column_jump(img, i));
    for (int i = 0; i + 1 < img.height; ++i) max_row = std::max(max_row, row_jump(img, i));
    EXPECT_LE(column_jump(img, img.width - 1), max_col * 1.05 + 1e-6);
    EXPECT_LE(row_jump(img, img.height - 1), max_row * 1.05 + 1e-6);
  }
}

TEST(ProceduralTexture, ShiftedImageFailsTheTilingCheck) {
  // Guard that the check can fail: cut a noise image at a third of its width.
  Image img = make_noise(64, 4, 7), cut(42, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 42; ++x)
      for (int c = 0; c < 3; ++c) cut.at(x, y, c) = img.at(x, y, c);
  double max_col = 0;
  for (int i = 0; i + 1 < cut.width; ++i) max_col = std::max(max_col, column_jump(cut, i));
  EXPECT_GT(column_jump(cut, cut.width - 1), max_col * 1.05);
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
