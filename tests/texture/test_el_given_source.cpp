// SPDX-License-Identifier: AGPL-3.0-or-later
// A Fill pixel next to a given (Known) pixel whose exemplar source is known
// (ElInput::known_source) continues that source: a patch carries its
// neighbours' texture across the seam instead of matching it anew, which
// for flat features wider than the window (stripes, bricks) picks any phase.
#include <gtest/gtest.h>

#include <cmath>

#include "texture/efros_leung.h"
#include "texture/rotated_exemplars.h"

namespace surftex {
namespace {

// Vertical bands 16 px wide, two colours, 64 x 48.
Image bands() {
  Image ex(64, 48, 3);
  for (int y = 0; y < ex.height; ++y)
    for (int x = 0; x < ex.width; ++x) {
      const bool blue = (x / 16) % 2 == 0;
      ex.at(x, y, 0) = blue ? 0.05f : 1.f;
      ex.at(x, y, 1) = blue ? 0.6f : 1.f;
      ex.at(x, y, 2) = blue ? 0.9f : 1.f;
    }
  return ex;
}

// Target 26 x 24: columns 0..11 given, copied from exemplar columns 33..44,
// inside one band (no edge for the window to see); the rest to fill.
// Returns the share of filled pixels whose colour is that of exemplar column
// 33 + x: the band carried on to its width, its edge at column 15.
double continued_share(bool with_sources, std::uint64_t seed) {
  const Image ex = bands();
  const int W = 26, H = 24, x0 = 33, given = 12;
  ElInput in;
  in.exemplars = {ex};
  in.target = Image(W, H, 3, 0.f);
  in.state.assign(W * H, PixelState::Fill);
  if (with_sources) in.known_source.assign(W * H, ElExemplarPoint());
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < given; ++x) {
      for (int c = 0; c < 3; ++c) in.target.at(x, y, c) = ex.at(x0 + x, y + 12, c);
      in.state[y * W + x] = PixelState::Known;
      if (with_sources) in.known_source[y * W + x] = {0, float(x0 + x), float(y + 12)};
    }
  ElOptions o;
  o.seed = seed;
  const ElResult r = efros_leung_synthesize(in, o);
  int same = 0, filled = 0;
  for (int y = 0; y < H; ++y)
    for (int x = given; x < W; ++x, ++filled) same += r.image.at(x, y, 0) == ex.at(x0 + x, 0, 0);
  return double(same) / filled;
}

TEST(EfrosLeungGivenSource, BandsWiderThanTheWindowContinueFromTheGivenPixels) {
  double worst_without = 1;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    EXPECT_GE(continued_share(true, seed), 0.97) << "seed " << seed;
    worst_without = std::min(worst_without, continued_share(false, seed));
  }
  // Without the sources the band's edge lands where a random pick among the
  // flat band's positions puts it.
  EXPECT_LT(worst_without, 0.9);
}

TEST(EfrosLeungGivenSource, NonFiniteSourcesAreRefused) {
  ElInput in;
  in.exemplars = {bands()};
  in.target = Image(16, 16, 3, 0.f);
  in.state.assign(256, PixelState::Fill);
  in.state[0] = PixelState::Known;
  in.known_source.assign(256, ElExemplarPoint());
  in.known_source[0] = {0, std::nanf(""), 1.f};
  EXPECT_THROW(efros_leung_synthesize(in), InvalidInputError);
  in.known_source.resize(10);
  EXPECT_THROW(efros_leung_synthesize(in), InvalidInputError);
}

// rotated_point is rotate_exemplar's map: exact on quarter turns, and the
// inverse of exemplar_point at any angle.
TEST(RotatedExemplars, RotatedPointFindsTheExemplarPixelInTheCanvas) {
  Image ex(20, 12, 1);
  for (std::size_t i = 0; i < ex.data.size(); ++i) ex.data[i] = float(i);
  for (int k : {0, 4, 8, 12}) {
    const RotatedExemplar r = rotate_exemplar_step(ex, k, 16, false, 0);
    for (int y = 0; y < ex.height; ++y)
      for (int x = 0; x < ex.width; ++x) {
        const auto c = rotated_point(20, 12, r.image.width, r.image.height, std::cos(r.angle), std::sin(r.angle), x, y);
        const int i = int(std::lround(c[0])), j = int(std::lround(c[1]));
        ASSERT_NEAR(c[0], i, 1e-9);
        ASSERT_NEAR(c[1], j, 1e-9);
        ASSERT_EQ(r.image.at(i, j), ex.at(x, y)) << k << " " << x << "," << y;
      }
  }
  for (double a : {0.3, 2.0, -1.1}) {
    const auto c = rotated_point(20, 12, 25, 22, std::cos(a), std::sin(a), 3.25, 7.5);
    const auto e = exemplar_point(20, 12, 25, 22, std::cos(a), std::sin(a), c[0], c[1]);
    EXPECT_NEAR(e[0], 3.25, 1e-9);
    EXPECT_NEAR(e[1], 7.5, 1e-9);
  }
}

}  // namespace
}  // namespace surftex
