// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "geometry/errors.h"
#include "texture/feature_mask.h"
#include "texture/signed_distance_field.h"

using namespace surftex;

namespace {
Image random_mask(int w, int h, double density, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::bernoulli_distribution b(density);
  Image m(w, h, 1);
  for (float& v : m.data) v = b(rng) ? 1.f : 0.f;
  return m;
}

// Brute force: toroidal distance to the nearest pixel of the other class.
double brute_signed(const Image& m, int x, int y) {
  bool in = m.at(x, y) > 0.5f;
  double best = std::numeric_limits<double>::infinity();
  for (int v = 0; v < m.height; ++v)
    for (int u = 0; u < m.width; ++u) {
      if ((m.at(u, v) > 0.5f) == in) continue;
      int dx = std::abs(u - x), dy = std::abs(v - y);
      dx = std::min(dx, m.width - dx);
      dy = std::min(dy, m.height - dy);
      best = std::min(best, std::sqrt(double(dx * dx + dy * dy)));
    }
  return in ? best : -best;
}
}  // namespace

TEST(SignedDistanceField, MatchesBruteForceOnRandomMasks) {
  int k = 0;
  for (auto [w, h, dens] : {std::tuple{23, 17, 0.05}, std::tuple{32, 32, 0.5}, std::tuple{40, 9, 0.01},
                            std::tuple{16, 31, 0.9}}) {
    Image m = random_mask(w, h, dens, 100 + k++);
    if (count_feature_pixels(m) == 0) m.at(3, 4) = 1.f;
    Image phi = signed_distance_field(m);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) ASSERT_NEAR(phi.at(x, y), brute_signed(m, x, y), 1e-4) << x << "," << y;
  }
}

TEST(SignedDistanceField, DistancesWrapAroundTheTorus) {
  Image m(20, 20, 1, 0.f);
  m.at(0, 0) = 1.f;
  Image phi = signed_distance_field(m);
  EXPECT_NEAR(phi.at(19, 19), -std::sqrt(2.0), 1e-5);  // diagonal neighbour across both seams
  EXPECT_NEAR(phi.at(10, 10), -std::sqrt(200.0), 1e-4);
  EXPECT_NEAR(phi.at(0, 0), 1.0, 1e-6);
}

TEST(SignedDistanceField, DegenerateMasks) {
  Image none(8, 6, 1, 0.f), all(8, 6, 1, 1.f);
  for (float v : signed_distance_field(none).data) EXPECT_EQ(v, -14.f);
  for (float v : signed_distance_field(all).data) EXPECT_EQ(v, 14.f);
  EXPECT_THROW(signed_distance_field(Image()), InvalidInputError);
}

TEST(FeatureMask, PaintedMaskThresholdsLuminanceAtHalf) {
  Image p(4, 1, 3, 0.f);
  p.at(1, 0, 1) = 0.8f;                               // green 0.8 -> lum 0.57
  p.at(2, 0, 0) = 0.9f;                               // red 0.9 -> lum 0.19
  for (int c = 0; c < 3; ++c) p.at(3, 0, c) = 0.5f;   // grey 0.5 -> feature
  Image m = mask_from_painted(p);
  EXPECT_EQ(m.data, (std::vector<float>{0, 1, 0, 1}));
  EXPECT_THROW(mask_from_painted(p, 1.5), InvalidInputError);
}

TEST(FeatureMask, AutomaticMaskPicksTheMinorityClassOfDots) {
  // Dark dots on a light background, and the inverse: the dots are the feature either way.
  Image img(64, 64, 3, 0.9f), inv(64, 64, 3, 0.1f);
  int dots = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      int dx = (x % 16) - 8, dy = (y % 16) - 8;
      if (dx * dx + dy * dy <= 16) {
        ++dots;
        for (int c = 0; c < 3; ++c) img.at(x, y, c) = 0.2f, inv.at(x, y, c) = 0.8f;
      }
    }
  for (const Image& t : {img, inv}) {
    FeatureMaskResult r = compute_feature_mask(t);
    EXPECT_NEAR(double(count_feature_pixels(r.mask)), dots, dots * 0.15);
    EXPECT_GT(r.mask.at(8, 8), 0.5f);
    EXPECT_LT(r.mask.at(0, 0), 0.5f);
  }
  FeatureMaskOptions g;
  g.rule = FeatureMaskOptions::Rule::Gradient;
  FeatureMaskResult e = compute_feature_mask(img, g);
  EXPECT_LT(e.mask.at(8, 8), 0.5f);  // dot centre: flat
  EXPECT_LT(e.mask.at(0, 0), 0.5f);  // background: flat
  EXPECT_GT(e.mask.at(12, 8), 0.5f); // dot rim: edge
  EXPECT_EQ(count_feature_pixels(compute_feature_mask(Image(8, 8, 3, 0.3f)).mask), 0);
}
