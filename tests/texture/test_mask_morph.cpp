// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <numeric>
#include <vector>

#include "geometry/errors.h"
#include "texture/feature_mask.h"
#include "texture/mask_morph.h"
#include "test_support.h"

using namespace surftex;

namespace {
Image disc_mask(int size, std::vector<std::array<double, 3>> discs) {
  Image m(size, size, 1, 0.f);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (auto [cx, cy, r] : discs) {
        double dx = std::abs(x - cx), dy = std::abs(y - cy);
        dx = std::min(dx, size - dx);
        dy = std::min(dy, size - dy);
        if (dx * dx + dy * dy <= r * r) m.at(x, y) = 1.f;
      }
  return m;
}

// Sizes of the 8-connected toroidal components of the pixels whose class is `feature`.
std::vector<int> components(const Image& m, bool feature) {
  int w = m.width, h = m.height;
  std::vector<int> label(std::size_t(w) * h, -1), sizes, stack;
  for (int s = 0; s < w * h; ++s) {
    if (label[s] >= 0 || (m.data[s] > 0.5f) != feature) continue;
    int id = static_cast<int>(sizes.size()), n = 0;
    stack = {s};
    label[s] = id;
    while (!stack.empty()) {
      int p = stack.back();
      stack.pop_back();
      ++n;
      int x = p % w, y = p / w;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int q = ((y + dy + h) % h) * w + (x + dx + w) % w;
          if (label[q] < 0 && (m.data[q] > 0.5f) == feature) {
            label[q] = id;
            stack.push_back(q);
          }
        }
    }
    sizes.push_back(n);
  }
  return sizes;
}

using surftex::test::cv;
}  // namespace

TEST(MaskMorph, EndsAreTheInputMasksAndStepsAreEven) {
  Image a = disc_mask(64, {{16, 16, 6}, {48, 40, 5}, {20, 50, 4}});
  Image b = disc_mask(64, {{40, 20, 8}, {10, 36, 5}});
  MaskMorphResult r = morph_feature_masks(a, b, 8);
  ASSERT_EQ(r.masks.size(), 9u);
  EXPECT_EQ(r.masks.front().data, binarize_mask(a).data);
  EXPECT_EQ(r.masks.back().data, binarize_mask(b).data);
  ASSERT_EQ(r.sign_changes.size(), 8u);
  for (int m = 0; m < 8; ++m) {
    EXPECT_EQ(r.sign_changes[m], count_sign_changes(r.masks[m], r.masks[m + 1]));
    EXPECT_GT(r.sign_changes[m], 0);
    EXPECT_LT(r.step_of_layer[m], r.step_of_layer[m + 1]);
  }
  EXPECT_GE(r.steps, 16 * 8);
  EXPECT_LE(cv(r.sign_changes), 0.35);
  // Without the adaptive subsampling (uniform H), the speed is much less even.
  std::vector<long long> uniform;
  for (int m = 0; m < 8; ++m) {
    long long c = 0;
    for (int n = r.steps * m / 8; n < r.steps * (m + 1) / 8; ++n) c += r.step_sign_changes[n];
    uniform.push_back(c);
  }
  EXPECT_GT(cv(uniform), cv(r.sign_changes));
}

TEST(MaskMorph, OneBlobSplitsIntoTwoWithoutSpecksOrHoles) {
  const int size = 64;
  Image a = disc_mask(size, {{32, 32, 9}});
  Image b = disc_mask(size, {{18, 32, 7}, {46, 32, 7}});
  MaskMorphResult r = morph_feature_masks(a, b, 8);
  for (std::size_t m = 0; m < r.masks.size(); ++m) {
    std::vector<int> fg = components(r.masks[m], true), bg = components(r.masks[m], false);
    EXPECT_GE(fg.size(), 1u) << "mask " << m;
    EXPECT_LE(fg.size(), 2u) << "mask " << m;
    for (int s : fg) EXPECT_GE(s, 6) << "speck in mask " << m;
    EXPECT_EQ(bg.size(), 1u) << "hole in mask " << m;
  }
  EXPECT_EQ(components(r.masks.back(), true).size(), 2u);
  EXPECT_LE(cv(r.sign_changes), 0.35);
}

TEST(MaskMorph, TwoBlobsMergeIntoOne) {
  Image a = disc_mask(48, {{14, 24, 5}, {34, 24, 5}});
  Image b = disc_mask(48, {{24, 24, 8}});
  MaskMorphResult r = morph_feature_masks(a, b, 6);
  for (const Image& m : r.masks) {
    EXPECT_LE(components(m, true).size(), 2u);
    EXPECT_EQ(components(m, false).size(), 1u);
  }
  EXPECT_EQ(components(r.masks.back(), true).size(), 1u);
}

TEST(MaskMorph, FeaturesTravelAcrossTheSeam) {
  // Source blob near the left edge, target near the right edge: the short way is across the seam.
  Image a = disc_mask(48, {{3, 24, 5}}), b = disc_mask(48, {{42, 24, 5}});
  MaskMorphResult r = morph_feature_masks(a, b, 4);
  // Midway, the feature sits across x = 0 (both x = 46..47 and x = 0..1 columns hold feature).
  const Image& mid = r.masks[2];
  EXPECT_EQ(components(mid, true).size(), 1u);
  bool left = false, right = false;
  for (int y = 0; y < 48; ++y) {
    left |= mid.at(0, y) > 0.5f;
    right |= mid.at(47, y) > 0.5f;
  }
  EXPECT_TRUE(left && right);
}

TEST(MaskMorph, InvalidArgumentsThrow) {
  Image a(16, 16, 1, 0.f), b(16, 8, 1, 0.f);
  EXPECT_THROW(morph_feature_masks(a, b, 4), InvalidInputError);
  EXPECT_THROW(morph_feature_masks(a, a, 0), InvalidInputError);
  MaskMorphOptions o;
  o.steps = 3;
  EXPECT_THROW(morph_feature_masks(a, a, 4, o), InvalidInputError);
}
