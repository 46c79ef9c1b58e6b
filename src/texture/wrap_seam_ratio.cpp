// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/wrap_seam_ratio.h"

#include <cmath>
#include <limits>
#include <string>

#include "geometry/errors.h"

namespace surftex {

namespace {
double jump(const Image& img, int x0, int y0, int x1, int y1) {
  double s = 0.0;
  for (int c = 0; c < img.channels; ++c) {
    double d = static_cast<double>(img.at(x0, y0, c)) - img.at(x1, y1, c);
    s += d * d;
  }
  return std::sqrt(s);
}
}  // namespace

WrapSeamStats wrap_seam_stats(const Image& img) {
  if (img.empty() || img.width < 2 || img.height < 2)
    throw InvalidInputError("wrap_seam_ratio: the image must be at least 2x2, got " +
                            std::to_string(img.width) + "x" + std::to_string(img.height));
  const int W = img.width, H = img.height;
  double inside = 0.0, wrap = 0.0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (x + 1 < W) inside += jump(img, x, y, x + 1, y);
      if (y + 1 < H) inside += jump(img, x, y, x, y + 1);
    }
  for (int y = 0; y < H; ++y) wrap += jump(img, W - 1, y, 0, y);
  for (int x = 0; x < W; ++x) wrap += jump(img, x, H - 1, x, 0);
  WrapSeamStats s;
  s.inside_mean = inside / (static_cast<double>(W - 1) * H + static_cast<double>(W) * (H - 1));
  s.wrap_mean = wrap / static_cast<double>(W + H);
  if (s.inside_mean > 0.0)
    s.ratio = s.wrap_mean / s.inside_mean;
  else
    s.ratio = s.wrap_mean > 0.0 ? std::numeric_limits<double>::infinity() : 1.0;
  return s;
}

double wrap_seam_ratio(const Image& img) { return wrap_seam_stats(img).ratio; }

}  // namespace surftex
