// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Two exemplars whose wrap the plain wrap-seam ratio judges wrongly
// (texture/wrap_seam_ratio.h wrap_verdict; docs/decisions/207-wrap-verdict.md).

#include <cstdint>
#include <random>

#include "geometry/image.h"

namespace surftex::test {

// A brick wall that tiles, cut along its mortar: courses 16 px tall, bricks
// 32 px wide in running bond (every other course shifted by 16), 2 px of
// light mortar on top of each course and a 1 px dark shadow at its bottom,
// so the wrap row (row 63 -> row 0) is a shadow-to-mortar step like every
// course boundary inside. Bricks carry per-pixel noise (seeded), so no pair
// of neighbours is special. 64 x 64: a whole number of periods both ways.
inline Image mortar_cut_brick_wall(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  Image im(64, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const int row = y % 16, course = y / 16;
      const int bx = (x + (course % 2) * 16) % 32;
      float r = 0.55f, g = 0.25f, b = 0.2f;  // brick
      if (row < 2 || bx < 2)
        r = 0.8f, g = 0.78f, b = 0.75f;  // mortar (bed and head joints)
      else if (row == 15)
        r = 0.15f, g = 0.1f, b = 0.1f;  // shadow under the brick
      const float n = noise(rng);
      im.at(x, y, 0) = r + n, im.at(x, y, 1) = g + n, im.at(x, y, 2) = b + n;
    }
  return im;
}

// Vertical stripes of period 20 (10 blue, 10 white) on 51 columns: the
// period does not divide the width, the last column is a 1 px white sliver,
// so the tiling shows two blue stripes joined by a hairline. The wrap column
// is a white-to-blue edge like every stripe edge inside. 51 x 32.
inline Image stripes_cut_mid_period() {
  Image im(51, 32, 3);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 51; ++x) {
      const bool blue = x % 20 < 10;
      im.at(x, y, 0) = blue ? 0.05f : 1.0f, im.at(x, y, 1) = blue ? 0.6f : 1.0f,
                  im.at(x, y, 2) = blue ? 0.9f : 1.0f;
    }
  return im;
}

}  // namespace surftex::test
