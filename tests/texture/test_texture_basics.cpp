// SPDX-License-Identifier: AGPL-3.0-or-later
// Gaussian pyramid/stack, image ops, rotated exemplars, quality metrics.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "texture/bidirectional_similarity.h"
#include "texture/gaussian_pyramid.h"
#include "texture/histogram_distance.h"
#include "texture/image_ops.h"
#include "texture/rotated_exemplars.h"

using namespace surftex;

namespace {
Image noise(int w, int h, int c, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> n(0.f, 1.f);
  Image img(w, h, c);
  for (float& v : img.data) v = n(rng);
  return img;
}
double variance(const Image& img) {
  double m = 0, v = 0;
  for (float x : img.data) m += x;
  m /= img.data.size();
  for (float x : img.data) v += (x - m) * (x - m);
  return v / img.data.size();
}
// 1D kernel of the stack's level l: binomial taps dilated by 1, 2, ..., 2^(l-1), convolved.
std::vector<double> stack_kernel(int level) {
  std::vector<double> k{1.0};
  const double taps[5] = {1 / 16., 4 / 16., 6 / 16., 4 / 16., 1 / 16.};
  for (int l = 0; l < level; ++l) {
    const int s = 1 << l;
    std::vector<double> next(k.size() + 4 * s, 0.0);
    for (std::size_t i = 0; i < k.size(); ++i)
      for (int t = 0; t < 5; ++t) next[i + t * s] += k[i] * taps[t];
    k = next;
  }
  return k;
}
}  // namespace

TEST(GaussianPyramid, LevelSizesHalve) {
  const Image img = noise(37, 20, 2, 1);
  const auto pyr = gaussian_pyramid(img);
  ASSERT_EQ(pyr.size(), 5u);  // 20 -> 10 -> 5 -> 3 -> 2: min side 20 gives 1 + floor(log2 20)
  const int w[] = {37, 19, 10, 5, 3}, h[] = {20, 10, 5, 3, 2};
  for (std::size_t l = 0; l < pyr.size(); ++l) {
    EXPECT_EQ(pyr[l].width, w[l]);
    EXPECT_EQ(pyr[l].height, h[l]);
    EXPECT_EQ(pyr[l].channels, 2);
  }
  // A constant image stays constant at every level (weights sum to 1).
  const auto flat = gaussian_pyramid(Image(16, 16, 1, 0.25f), {3, true});
  for (const Image& l : flat)
    for (float v : l.data) EXPECT_NEAR(v, 0.25f, 1e-6);
}

TEST(GaussianStack, SameSizeAndWhiteNoiseVarianceDropsAsTheKernelPredicts) {
  const Image img = noise(256, 256, 4, 9);
  const auto st = gaussian_stack(img, {5, true});
  ASSERT_EQ(st.size(), 5u);
  const double v0 = variance(img);
  double prev = v0;
  for (int l = 0; l < 5; ++l) {
    EXPECT_EQ(st[l].width, 256);
    EXPECT_EQ(st[l].height, 256);
    // Blurred white noise keeps variance v0 * (sum of squared 1D taps)^2.
    const auto k = stack_kernel(l);
    double s2 = 0;
    for (double t : k) s2 += t * t;
    const double expect = v0 * s2 * s2;
    EXPECT_NEAR(variance(st[l]), expect, 0.2 * expect) << "level " << l;
    if (l > 0) {
      EXPECT_LT(variance(st[l]), 0.5 * prev);
    }
    prev = variance(st[l]);
  }
  // Level 1 is one 5-tap binomial pass: 70/256 of the 1D energy per axis.
  EXPECT_NEAR(variance(st[1]) / v0, (70.0 / 256) * (70.0 / 256), 0.01);
  EXPECT_THROW(gaussian_stack(Image()), InvalidInputError);
  EXPECT_THROW(gaussian_pyramid(img, {-1, false}), InvalidInputError);
}

TEST(ImageOps, CropWrapResizeAndRotate) {
  Image img(4, 3, 1);
  for (int i = 0; i < 12; ++i) img.data[i] = static_cast<float>(i);
  const Image c = crop(img, 3, 2, 2, 2, true);
  EXPECT_EQ(c.at(0, 0), img.at(3, 2));
  EXPECT_EQ(c.at(1, 1), img.at(0, 0));
  EXPECT_THROW(crop(img, 3, 2, 2, 2, false), InvalidInputError);
  const Image same = resize_bilinear(img, 4, 3);
  EXPECT_EQ(same.data, img.data);
  // 90 degrees counter-clockwise: the exemplar's +x axis points up.
  Image sq(5, 5, 1);
  for (int i = 0; i < 25; ++i) sq.data[i] = static_cast<float>(i);
  const Image r = rotate_image(sq, M_PI / 2, 5, 5, false);
  EXPECT_NEAR(r.at(2, 0), sq.at(4, 2), 1e-4);  // right of centre -> above centre
  EXPECT_NEAR(r.at(0, 2), sq.at(2, 0), 1e-4);  // top -> left
  const Image lum = luminance(Image(2, 2, 3, 1.f));
  EXPECT_NEAR(lum.at(1, 1), 1.f, 1e-6);
}

// The largest opaque block against every block of small random masks (each
// pixel transparent with probability 1/4, 1/2 or 3/4; RGBA and grey + alpha).
TEST(ImageOps, LargestOpaqueRectangleIsTheLargestBlockWithoutTransparentPixels) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 60; ++trial) {
    const int w = 1 + static_cast<int>(rng() % 9), h = 1 + static_cast<int>(rng() % 9), channels = trial % 2 ? 4 : 2;
    const unsigned holes = 1 + trial % 3;
    Image img(w, h, channels, 0.3f);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) img.at(x, y, channels - 1) = rng() % 4 < holes ? 0.2f : 0.9f;
    auto opaque = [&](int x0, int y0, int bw, int bh) {
      for (int y = y0; y < y0 + bh; ++y)
        for (int x = x0; x < x0 + bw; ++x)
          if (is_transparent(img, x, y)) return false;
      return true;
    };
    long long largest = 0;
    for (int y0 = 0; y0 < h; ++y0)
      for (int x0 = 0; x0 < w; ++x0)
        for (int bh = 1; y0 + bh <= h; ++bh)
          for (int bw = 1; x0 + bw <= w; ++bw)
            if (opaque(x0, y0, bw, bh)) largest = std::max(largest, static_cast<long long>(bw) * bh);
    const PixelRect r = largest_opaque_rectangle(img);
    EXPECT_EQ(r.area(), largest) << "trial " << trial;
    if (r.area() > 0) {
      EXPECT_TRUE(r.x >= 0 && r.y >= 0 && r.x + r.width <= w && r.y + r.height <= h);
      EXPECT_TRUE(opaque(r.x, r.y, r.width, r.height)) << "trial " << trial;
    }
  }
  const PixelRect whole = largest_opaque_rectangle(Image(5, 3, 3, 0.f));  // no alpha: all of it
  EXPECT_EQ(whole.width, 5);
  EXPECT_EQ(whole.height, 3);
  EXPECT_EQ(largest_opaque_rectangle(Image(4, 4, 4, 0.f)).area(), 0);  // all transparent
}

TEST(RotatedExemplars, IndexWrapsAndRotationZeroIsExact) {
  EXPECT_EQ(rotation_index(0.0, 64), 0);
  EXPECT_EQ(rotation_index(2 * M_PI, 64), 0);
  EXPECT_EQ(rotation_index(-2 * M_PI / 64, 64), 63);
  EXPECT_EQ(rotation_index(M_PI, 64), 32);
  const Image ex = noise(16, 12, 3, 3);
  RotatedExemplarOptions ro;
  ro.rotations = 8;
  ro.only = {0, 2};
  const auto set = rotated_exemplars(ex, ro);
  ASSERT_EQ(set.items.size(), 8u);
  EXPECT_EQ(set.items[0].image.data, ex.data);
  EXPECT_TRUE(set.items[1].image.empty());
  // 90 degrees of a 16x12 image: 12x16 bounding box, fully valid.
  EXPECT_EQ(set.items[2].image.width, 12);
  EXPECT_EQ(set.items[2].image.height, 16);
  for (float v : set.items[2].valid.data) EXPECT_EQ(v, 1.f);
  // 45 degrees: corners of the bounding box are invalid, the centre valid.
  const RotatedExemplar r45 = rotate_exemplar(ex, M_PI / 4, false);
  EXPECT_EQ(r45.valid.at(0, 0), 0.f);
  EXPECT_EQ(r45.valid.at(r45.valid.width / 2, r45.valid.height / 2), 1.f);
  // Periodic: margin added, all valid, rotation 0 wraps exactly.
  const RotatedExemplar p = rotate_exemplar(ex, 0.0, true, 3);
  EXPECT_EQ(p.image.width, 22);
  EXPECT_EQ(p.image.at(0, 0, 1), ex.at(13, 9, 1));
  RotatedExemplarOptions bad;
  bad.rotations = 0;
  EXPECT_THROW(rotated_exemplars(ex, bad), InvalidInputError);
  bad.rotations = 129;
  EXPECT_THROW(rotated_exemplars(ex, bad), InvalidInputError);
}

// Orientation k >= K/4 built by exact quarter turns of orientation k mod K/4
// is the direct rotation up to rounding: same canvas, same validity, same
// samples (a wrong turn direction would put the texture upside down).
TEST(RotatedExemplars, QuarterTurnsAreTheDirectRotation) {
  for (const auto& size : {std::array<int, 2>{16, 16}, std::array<int, 2>{20, 12}}) {
    const Image ex = noise(size[0], size[1], 3, 7);
    ASSERT_TRUE(quarter_turns_shared(ex, 64, false));
    for (int k : {16, 19, 32, 37, 48, 63}) {
      const RotatedExemplar turned = rotate_exemplar_step(ex, k, 64, false, 0);
      const RotatedExemplar direct = rotate_exemplar(ex, 2.0 * M_PI * k / 64, false, 0);
      ASSERT_EQ(turned.image.width, direct.image.width) << k;
      ASSERT_EQ(turned.image.height, direct.image.height) << k;
      std::size_t differ = 0;
      for (std::size_t i = 0; i < direct.valid.data.size(); ++i) {
        differ += turned.valid.data[i] != direct.valid.data[i];
        if (turned.valid.data[i] == 0.f || direct.valid.data[i] == 0.f) continue;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(turned.image.data[i * 3 + c], direct.image.data[i * 3 + c], 1e-4) << k;
      }
      EXPECT_LE(differ, direct.valid.data.size() / 100) << k;  // samples exactly on the border may flip
    }
    EXPECT_EQ(rotate_exemplar_step(ex, 5, 64, false, 0).image.data, rotate_exemplar(ex, 2.0 * M_PI * 5 / 64, false, 0).image.data);
  }
  EXPECT_FALSE(quarter_turns_shared(noise(16, 15, 3, 1), 64, false));  // odd side difference
  EXPECT_FALSE(quarter_turns_shared(noise(16, 16, 3, 1), 64, true));   // periodic
  EXPECT_FALSE(quarter_turns_shared(noise(16, 16, 3, 1), 30, false));  // K not a multiple of 4
}

TEST(BidirectionalSimilarity, VerbatimCopyIsCoherentAndKdTreeMatchesBruteForce) {
  std::mt19937_64 rng(5);
  Image ex = binomial_blur(noise(40, 40, 3, 8));
  // A patchwork of verbatim exemplar blocks: coherence ~0 only for patches
  // inside a block; use one block = a crop.
  const Image copy = crop(ex, 7, 5, 24, 20);
  BidirectionalOptions o;
  o.patch = 5;
  const auto c = bidirectional_similarity(copy, ex, o);
  EXPECT_LT(c.coherence, 1e-12);
  EXPECT_GT(c.completeness, 0.0);  // the crop misses part of the exemplar
  EXPECT_NEAR(c.total, c.coherence + c.completeness, 1e-15);
  EXPECT_EQ(c.output_patches, 20u * 16u);
  EXPECT_EQ(c.exemplar_patches, 36u * 36u);
  for (int trial = 0; trial < 3; ++trial) {
    const Image out = binomial_blur(noise(30, 26, 3, 50 + trial));
    BidirectionalOptions fast = o, brute = o;
    brute.brute_force = true;
    fast.pca_dims = 4 + 4 * trial;
    const auto a = bidirectional_similarity(out, ex, fast);
    const auto b = bidirectional_similarity(out, ex, brute);
    EXPECT_NEAR(a.coherence, b.coherence, 1e-9 * b.coherence);
    EXPECT_NEAR(a.completeness, b.completeness, 1e-9 * b.completeness);
  }
  EXPECT_THROW(bidirectional_similarity(copy, ex, {0}), InvalidInputError);
  BidirectionalOptions negative = o;
  negative.search_eps = -1.f;
  EXPECT_THROW(bidirectional_similarity(copy, ex, negative), InvalidInputError);
  EXPECT_THROW(bidirectional_similarity(Image(), ex), InvalidInputError);
  EXPECT_THROW(bidirectional_similarity(Image(8, 8, 1), ex), InvalidInputError);
}

TEST(HistogramDistance, IdenticalZeroDisjointOne) {
  const Image a(8, 8, 3, 0.1f), b(5, 5, 3, 0.9f);
  EXPECT_EQ(histogram_chi_square(a, a), 0.0);
  EXPECT_NEAR(histogram_chi_square(a, b), 1.0, 1e-12);
  Image half(8, 8, 3, 0.1f);
  for (int i = 0; i < 32 * 3; ++i) half.data[i] = 0.9f;
  // p = (1, 0), q = (0.5, 0.5): 0.5 * (0.25/1.5 + 0.25/0.5) = 1/3.
  EXPECT_NEAR(histogram_chi_square(a, half), 1.0 / 3.0, 1e-12);
  EXPECT_THROW(histogram_chi_square(a, Image(8, 8, 1)), InvalidInputError);
  EXPECT_THROW(histogram_chi_square(a, a, {0}), InvalidInputError);
}
