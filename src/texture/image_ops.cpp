// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/image_ops.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"

namespace surftex {
namespace {
void require_image(const Image& img, const char* what) {
  if (img.empty() || img.data.size() != static_cast<std::size_t>(img.width) * img.height * img.channels)
    throw InvalidInputError(std::string(what) + " is empty or malformed (" +
                            std::to_string(img.width) + "x" + std::to_string(img.height) + "x" +
                            std::to_string(img.channels) + ")");
}
int wrap_index(int i, int n) {
  i %= n;
  return i < 0 ? i + n : i;
}
}  // namespace

Image luminance(const Image& img) {
  require_image(img, "luminance: image");
  Image out(img.width, img.height, 1);
  const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
  for (std::size_t i = 0; i < n; ++i) {
    const float* p = img.data.data() + i * img.channels;
    out.data[i] = img.channels >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
  }
  return out;
}

Image as_rgb(const Image& img) {
  if (img.channels == 3) return img;
  Image out(img.width, img.height, 3);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) out.at(x, y, c) = img.at(x, y, img.channels >= 3 ? c : 0);
  return out;
}

Image crop(const Image& img, int x, int y, int w, int h, bool wrap) {
  require_image(img, "crop: image");
  if (w <= 0 || h <= 0)
    throw InvalidInputError("crop: size " + std::to_string(w) + "x" + std::to_string(h) +
                            " must be positive");
  if (!wrap && (x < 0 || y < 0 || x + w > img.width || y + h > img.height))
    throw InvalidInputError("crop: block (" + std::to_string(x) + "," + std::to_string(y) + ") " +
                            std::to_string(w) + "x" + std::to_string(h) + " exceeds the " +
                            std::to_string(img.width) + "x" + std::to_string(img.height) + " image");
  Image out(w, h, img.channels);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      int sx = wrap ? wrap_index(x + i, img.width) : x + i;
      int sy = wrap ? wrap_index(y + j, img.height) : y + j;
      std::copy_n(img.pixel(sx, sy), img.channels, out.pixel(i, j));
    }
  return out;
}

bool is_transparent(const Image& img, int x, int y) {
  return (img.channels == 2 || img.channels == 4) && img.at(x, y, img.channels - 1) < 0.5f;
}

// Row by row, the opaque run above each column is a histogram; its largest
// rectangle comes from a stack of increasing heights (each bar popped when a
// lower one ends it: its rectangle spans from the bar below it in the stack).
PixelRect largest_opaque_rectangle(const Image& img) {
  require_image(img, "largest_opaque_rectangle: image");
  const int W = img.width, H = img.height;
  std::vector<int> run(static_cast<std::size_t>(W) + 1, 0), stack;  // run[W] = 0 closes every row
  stack.reserve(static_cast<std::size_t>(W) + 1);
  PixelRect best;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) run[x] = is_transparent(img, x, y) ? 0 : run[x] + 1;
    stack.clear();
    for (int x = 0; x <= W; ++x) {
      while (!stack.empty() && run[stack.back()] >= run[x]) {
        const int h = run[stack.back()];
        stack.pop_back();
        const int left = stack.empty() ? 0 : stack.back() + 1;
        const PixelRect r{left, y - h + 1, x - left, h};
        const bool same_row_left = r.area() == best.area() && r.y + r.height == best.y + best.height && r.x < best.x;
        if (h > 0 && (r.area() > best.area() || same_row_left)) best = r;
      }
      stack.push_back(x);
    }
  }
  return best;
}

void sample_bilinear(const Image& img, double x, double y, bool wrap, float* out) {
  const double fx = std::floor(x), fy = std::floor(y);
  const double tx = x - fx, ty = y - fy;
  int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy), x1 = x0 + 1, y1 = y0 + 1;
  if (wrap) {
    x0 = wrap_index(x0, img.width);
    x1 = wrap_index(x1, img.width);
    y0 = wrap_index(y0, img.height);
    y1 = wrap_index(y1, img.height);
  } else {
    x0 = std::clamp(x0, 0, img.width - 1);
    x1 = std::clamp(x1, 0, img.width - 1);
    y0 = std::clamp(y0, 0, img.height - 1);
    y1 = std::clamp(y1, 0, img.height - 1);
  }
  const float* a = img.pixel(x0, y0);
  const float* b = img.pixel(x1, y0);
  const float* c = img.pixel(x0, y1);
  const float* d = img.pixel(x1, y1);
  for (int k = 0; k < img.channels; ++k) {
    // Exact copies at integer positions (weights 1 and 0).
    double top = tx == 0.0 ? a[k] : (1.0 - tx) * a[k] + tx * b[k];
    double bot = tx == 0.0 ? c[k] : (1.0 - tx) * c[k] + tx * d[k];
    out[k] = static_cast<float>(ty == 0.0 ? top : (1.0 - ty) * top + ty * bot);
  }
}

Image resize_bilinear(const Image& img, int w, int h, bool wrap) {
  require_image(img, "resize_bilinear: image");
  if (w <= 0 || h <= 0)
    throw InvalidInputError("resize_bilinear: size " + std::to_string(w) + "x" +
                            std::to_string(h) + " must be positive");
  Image out(w, h, img.channels);
  const double sx = static_cast<double>(img.width) / w, sy = static_cast<double>(img.height) / h;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      double x = (i + 0.5) * sx - 0.5, y = (j + 0.5) * sy - 0.5;
      if (!wrap) x = std::clamp(x, 0.0, img.width - 1.0), y = std::clamp(y, 0.0, img.height - 1.0);
      sample_bilinear(img, x, y, wrap, out.pixel(i, j));
    }
  return out;
}

Image rotate_image(const Image& img, double radians, int out_w, int out_h, bool wrap,
                   Image* valid) {
  require_image(img, "rotate_image: image");
  if (out_w <= 0 || out_h <= 0)
    throw InvalidInputError("rotate_image: output size " + std::to_string(out_w) + "x" +
                            std::to_string(out_h) + " must be positive");
  if (!std::isfinite(radians))
    throw InvalidInputError("rotate_image: angle " + std::to_string(radians) + " is not finite");
  Image out(out_w, out_h, img.channels);
  if (valid) *valid = Image(out_w, out_h, 1);
  const double c = std::cos(radians), s = std::sin(radians);
  const double eps = 1e-9;
  for (int j = 0; j < out_h; ++j)
    for (int i = 0; i < out_w; ++i) {
      const auto [x, y] = exemplar_point(img.width, img.height, out_w, out_h, c, s, i, j);
      const bool inside =
          x >= -eps && y >= -eps && x <= img.width - 1 + eps && y <= img.height - 1 + eps;
      if (valid) valid->at(i, j) = (wrap || inside) ? 1.f : 0.f;
      if (wrap || inside)
        sample_bilinear(img, wrap ? x : std::clamp(x, 0.0, img.width - 1.0),
                        wrap ? y : std::clamp(y, 0.0, img.height - 1.0), wrap, out.pixel(i, j));
    }
  return out;
}

}  // namespace surftex
