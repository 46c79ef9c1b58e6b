// SPDX-License-Identifier: AGPL-3.0-or-later
// Efros-Leung reports where every synthesised pixel came from (ElResult::
// source), so that other maps of the exemplar can follow the same synthesis
// (issue 16 item 2).
#include <gtest/gtest.h>

#include <cmath>

#include "texture/efros_leung.h"
#include "texture/procedural_texture.h"
#include "texture/rotated_exemplars.h"

namespace surftex {
namespace {

TEST(EfrosLeungSource, EveryFilledPixelNamesTheTexelItCopied) {
  const Image ex = make_noise(32, 4, 5);
  ElInput in;
  in.exemplars = {ex};
  in.target = Image(20, 16, 3);
  ElOptions o;
  o.window = 7;
  o.seed = 3;
  const ElResult r = efros_leung_synthesize(in, o);
  ASSERT_EQ(r.source.size(), 20u * 16u);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 20; ++x) {
      const ElSource& s = r.source[y * 20 + x];
      ASSERT_EQ(s.exemplar, 0);
      ASSERT_EQ(s.rotation, 0);
      for (int c = 0; c < 3; ++c) ASSERT_EQ(r.image.at(x, y, c), ex.at(s.x, s.y, c)) << x << "," << y;
    }
}

// Also for orientations built by quarter turns (k >= K/4: 2.5 rad is k = 3 of
// 8), with their base's index (odd windows) or their own (an even window).
TEST(EfrosLeungSource, RotatedSourcesIndexTheRotatedExemplar) {
  const Image ex = make_noise(32, 4, 6);
  for (int window : {5, 6}) {
    for (float angle : {0.7f, 2.5f}) {
      ElInput in;
      in.exemplars = {ex};
      in.target = Image(16, 16, 3);
      in.angle = Image(16, 16, 1, angle);
      ElOptions o;
      o.window = window;
      o.rotations = 8;
      const ElResult r = efros_leung_synthesize(in, o);
      const int k = rotation_index(angle, 8);
      const RotatedExemplar rot = rotate_exemplar_step(ex, k, 8, false, o.window / 2);
      for (std::size_t p = 0; p < r.source.size(); ++p) {
        const ElSource& s = r.source[p];
        ASSERT_EQ(s.rotation, k);
        for (int c = 0; c < 3; ++c) ASSERT_EQ(r.image.data[p * 3 + c], rot.image.at(s.x, s.y, c)) << p;
      }
    }
  }
}

}  // namespace
}  // namespace surftex
