// SPDX-License-Identifier: AGPL-3.0-or-later
// wrap_verdict and wrap_window_stats (texture/wrap_seam_ratio.h). The plain
// wrap-seam ratio's own tests: test_tileable_tile.cpp.
#include <gtest/gtest.h>

#include <random>

#include "geometry/errors.h"
#include "texture/wrap_seam_ratio.h"
#include "wrap_test_images.h"
#include "test_support.h"

using namespace surftex;

// A wall cut along its mortar tiles: the plain ratio is fooled by the
// mortar line on the wrap row, the lines and windows are not.
TEST(WrapVerdict, ABrickWallCutAlongItsMortarTiles) {
  const Image wall = test::mortar_cut_brick_wall(1);
  const WrapVerdict v = wrap_verdict(wall, 1.3, 9);
  EXPECT_GT(v.seam_ratio, 1.3) << "the test needs a wall whose plain ratio says it does not tile";
  EXPECT_TRUE(v.lines_within_interior);
  EXPECT_GE(v.window_ratio, 0.0);
  EXPECT_LE(v.window_ratio, 1.3);
  EXPECT_TRUE(v.seamless);
}

// Stripes whose period does not divide the width: every line looks like a
// stripe edge, but the windows across the wrap show a hairline found
// nowhere inside.
TEST(WrapVerdict, StripesCutMidPeriodDoNotTile) {
  const Image stripes = test::stripes_cut_mid_period();
  const WrapVerdict v = wrap_verdict(stripes, 1.3, 9);
  EXPECT_GT(v.seam_ratio, 1.3);
  EXPECT_TRUE(v.lines_within_interior);
  EXPECT_GT(v.window_ratio, 1.3);
  EXPECT_FALSE(v.seamless);
}

// Noise that does not tile (a ramp under it) fails the line check; a
// seamless tile passes on the plain ratio alone, without the windows.
TEST(WrapVerdict, NonTilingNoiseFailsAndASeamlessTilePassesOnTheRatio) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  Image ramp(48, 48, 3), tile(48, 48, 3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x)
      for (int c = 0; c < 3; ++c) {
        ramp.at(x, y, c) = 0.1f + 0.8f * float(x) / 47.f + u(rng);
        tile.at(x, y, c) = 0.5f + u(rng);
      }
  const WrapVerdict r = wrap_verdict(ramp, 1.3, 9);
  EXPECT_FALSE(r.lines_within_interior);
  EXPECT_FALSE(r.seamless);
  const WrapVerdict t = wrap_verdict(tile, 1.3, 9);
  EXPECT_TRUE(t.seamless);
  EXPECT_EQ(t.window_ratio, -1.0);  // not needed
}

TEST(WrapVerdict, RejectsBadInput) {
  EXPECT_THROW(wrap_verdict(Image(8, 8, 3, 0.2f), 0.0, 9), InvalidInputError);
  EXPECT_THROW(wrap_window_stats(Image(16, 16, 3, 0.2f), 9), InvalidInputError);  // needs 19 x 19
  EXPECT_THROW(wrap_window_stats(Image(32, 32, 3, 0.2f), 0), InvalidInputError);
}
