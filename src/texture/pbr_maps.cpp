// SPDX-License-Identifier: AGPL-3.0-or-later
// Height, normal and metallic-roughness maps of an atlas (see pbr_maps.h).
#include "texture/pbr_maps.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/atlas_gutter.h"
#include "geometry/errors.h"

namespace surftex {

Image height_from_luminance(const Image& c) {
  if (c.empty()) throw InvalidInputError("height_from_luminance: empty image");
  Image h(c.width, c.height, 1);
  for (std::size_t i = 0; i < h.data.size(); ++i) {
    const float* p = c.data.data() + i * c.channels;
    const float v = c.channels >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0];
    h.data[i] = std::min(1.f, std::max(0.f, v));
  }
  return h;
}

Image normal_map_from_height(const Image& h, const std::vector<int>& owner, double k) {
  if (h.empty() || h.channels != 1)
    throw InvalidInputError("normal_map_from_height: needs a one-channel height map, got " +
                            std::to_string(h.channels) + " channels");
  const int W = h.width, H = h.height;
  if (!owner.empty() && owner.size() != static_cast<std::size_t>(W) * H)
    throw InvalidInputError("normal_map_from_height: " + std::to_string(owner.size()) + " chart labels for " +
                            std::to_string(W) + " x " + std::to_string(H) + " texels");
  if (!(k >= 0) || !std::isfinite(k))
    throw InvalidInputError("normal_map_from_height: strength must be >= 0, got " + std::to_string(k));
  auto chart = [&](int x, int y) { return owner.empty() ? 0 : owner[static_cast<std::size_t>(y) * W + x]; };
  // Slope along one axis: central where both neighbours are of the texel's
  // chart, one-sided where one is, 0 where none is.
  auto slope = [&](int x, int y, int dx, int dy) -> double {
    const int c = chart(x, y);
    const int ax = x - dx, ay = y - dy, bx = x + dx, by = y + dy;
    const bool a = ax >= 0 && ay >= 0 && ax < W && ay < H && chart(ax, ay) == c;
    const bool b = bx >= 0 && by >= 0 && bx < W && by < H && chart(bx, by) == c;
    if (a && b) return 0.5 * (h.at(bx, by) - h.at(ax, ay));
    if (b) return h.at(bx, by) - h.at(x, y);
    if (a) return h.at(x, y) - h.at(ax, ay);
    return 0.0;
  };
  Image n(W, H, 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (chart(x, y) < 0) continue;  // gutter: dilated below
      const double du = slope(x, y, 1, 0);
      const double dv = -slope(x, y, 0, 1);  // rows go down, v goes up
      double nx = -k * du, ny = -k * dv, nz = 1.0;
      const double l = std::sqrt(nx * nx + ny * ny + nz * nz);
      nx /= l, ny /= l, nz /= l;
      n.at(x, y, 0) = static_cast<float>(0.5 * nx + 0.5);
      n.at(x, y, 1) = static_cast<float>(0.5 * ny + 0.5);
      n.at(x, y, 2) = static_cast<float>(0.5 * nz + 0.5);
    }
  if (!owner.empty()) {
    std::vector<int> label = owner;
    bool any = false;
    for (int l : label) any = any || l >= 0;
    if (any) dilate_charts(n, label);
  }
  return n;
}

Image metallic_roughness_from_roughness(const Image& r) {
  if (r.empty()) throw InvalidInputError("metallic_roughness_from_roughness: empty image");
  Image m(r.width, r.height, 3);
  for (std::size_t i = 0; i < static_cast<std::size_t>(r.width) * r.height; ++i) {
    m.data[3 * i] = 1.f;
    m.data[3 * i + 1] = r.data[i * r.channels];
    m.data[3 * i + 2] = 0.f;
  }
  return m;
}

}  // namespace surftex
