// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/gaussian_pyramid.h"

#include <algorithm>
#include <string>

#include "geometry/errors.h"

namespace surftex {
namespace {
constexpr float kTaps[5] = {1.f / 16, 4.f / 16, 6.f / 16, 4.f / 16, 1.f / 16};

int border(int i, int n, bool toroidal) {
  if (toroidal) {
    i %= n;
    return i < 0 ? i + n : i;
  }
  return std::clamp(i, 0, n - 1);
}

void require(const Image& img, const char* fn) {
  if (img.empty())
    throw InvalidInputError(std::string(fn) + ": image is empty (" + std::to_string(img.width) +
                            "x" + std::to_string(img.height) + "x" +
                            std::to_string(img.channels) + ")");
}

int default_levels(const Image& img) {
  int m = std::min(img.width, img.height), l = 1;
  while (m > 1) {
    m /= 2;
    ++l;
  }
  return l;
}
}  // namespace

Image binomial_blur(const Image& img, int step, bool toroidal) {
  require(img, "binomial_blur");
  if (step < 1) throw InvalidInputError("binomial_blur: step " + std::to_string(step) + " < 1");
  const int w = img.width, h = img.height, c = img.channels;
  Image tmp(w, h, c), out(w, h, c);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* o = tmp.pixel(x, y);
      for (int t = 0; t < 5; ++t) {
        const float* p = img.pixel(border(x + (t - 2) * step, w, toroidal), y);
        for (int k = 0; k < c; ++k) o[k] += kTaps[t] * p[k];
      }
    }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float* o = out.pixel(x, y);
      for (int t = 0; t < 5; ++t) {
        const float* p = tmp.pixel(x, border(y + (t - 2) * step, h, toroidal));
        for (int k = 0; k < c; ++k) o[k] += kTaps[t] * p[k];
      }
    }
  return out;
}

std::vector<Image> gaussian_pyramid(const Image& img, const PyramidOptions& opt) {
  require(img, "gaussian_pyramid");
  if (opt.levels < 0)
    throw InvalidInputError("gaussian_pyramid: levels " + std::to_string(opt.levels) + " < 0");
  const int levels = opt.levels == 0 ? default_levels(img) : opt.levels;
  std::vector<Image> pyr{img};
  for (int l = 1; l < levels; ++l) {
    const Image& prev = pyr.back();
    Image blurred = binomial_blur(prev, 1, opt.toroidal);
    Image next((prev.width + 1) / 2, (prev.height + 1) / 2, prev.channels);
    for (int y = 0; y < next.height; ++y)
      for (int x = 0; x < next.width; ++x)
        std::copy_n(blurred.pixel(2 * x, 2 * y), prev.channels, next.pixel(x, y));
    pyr.push_back(std::move(next));
  }
  return pyr;
}

std::vector<Image> gaussian_stack(const Image& img, const StackOptions& opt) {
  require(img, "gaussian_stack");
  if (opt.levels < 0)
    throw InvalidInputError("gaussian_stack: levels " + std::to_string(opt.levels) + " < 0");
  const int levels = opt.levels == 0 ? default_levels(img) : opt.levels;
  std::vector<Image> stack{img};
  for (int l = 1; l < levels; ++l) stack.push_back(binomial_blur(stack.back(), 1 << (l - 1), opt.toroidal));
  return stack;
}

}  // namespace surftex
