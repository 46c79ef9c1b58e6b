// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A float image with any number of interleaved channels, row-major, (0,0) at
// the top-left. The common image type of the rasterizer (geometry) and all
// synthesis code (texture); it lives in geometry because the rasterizer reads
// textures. Values are linear floats; 8-bit files map to [0,1].

#include <cstddef>
#include <vector>

namespace surftex {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> data;  // width * height * channels

  Image() = default;
  Image(int w, int h, int c, float fill = 0.f)
      : width(w), height(h), channels(c), data(static_cast<std::size_t>(w) * h * c, fill) {}

  bool empty() const { return width <= 0 || height <= 0 || channels <= 0; }
  std::size_t index(int x, int y, int c = 0) const {
    return (static_cast<std::size_t>(y) * width + x) * channels + c;
  }
  float& at(int x, int y, int c = 0) { return data[index(x, y, c)]; }
  float at(int x, int y, int c = 0) const { return data[index(x, y, c)]; }
  float* pixel(int x, int y) { return data.data() + index(x, y); }
  const float* pixel(int x, int y) const { return data.data() + index(x, y); }
  /// Toroidal access: coordinates wrap around (periodic tiles).
  float at_wrap(int x, int y, int c = 0) const {
    x %= width; if (x < 0) x += width;
    y %= height; if (y < 0) y += height;
    return at(x, y, c);
  }
};

}  // namespace surftex
