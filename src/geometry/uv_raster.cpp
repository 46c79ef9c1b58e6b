// SPDX-License-Identifier: AGPL-3.0-or-later
// Texture-space triangle rasterisation (see uv_raster.h).
#include "geometry/uv_raster.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "geometry/errors.h"

namespace surftex {

namespace {

struct P2 {
  double x, y;
};

// Barycentrics of q in (a, b, c) with signed doubled area `area`.
std::array<double, 3> barycentric(const P2& a, const P2& b, const P2& c, double area, const P2& q) {
  const double b1 = ((q.x - a.x) * (c.y - a.y) - (c.x - a.x) * (q.y - a.y)) / area;
  const double b2 = ((b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y)) / area;
  return {1 - b1 - b2, b1, b2};
}

// Nearest point of segment (p, q) to x: parameter in [0, 1] and squared distance.
std::pair<double, double> nearest_on_segment(const P2& p, const P2& q, const P2& x) {
  const double dx = q.x - p.x, dy = q.y - p.y, l2 = dx * dx + dy * dy;
  double t = l2 > 0 ? ((x.x - p.x) * dx + (x.y - p.y) * dy) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double ex = p.x + t * dx - x.x, ey = p.y + t * dy - x.y;
  return {t, ex * ex + ey * ey};
}

struct Box {
  int x0, x1, y0, y1;
};

Box texel_box(const P2 (&p)[3], double pad, int W, int H) {
  const double lx = std::min({p[0].x, p[1].x, p[2].x}) - pad, hx = std::max({p[0].x, p[1].x, p[2].x}) + pad;
  const double ly = std::min({p[0].y, p[1].y, p[2].y}) - pad, hy = std::max({p[0].y, p[1].y, p[2].y}) + pad;
  return {std::max(0, static_cast<int>(std::floor(lx - 0.5))), std::min(W - 1, static_cast<int>(std::ceil(hx - 0.5))),
          std::max(0, static_cast<int>(std::floor(ly - 0.5))), std::min(H - 1, static_cast<int>(std::ceil(hy - 0.5)))};
}

constexpr int kBandRows = 16;

// Pass 1 over rows y0..y1: texel centres inside a triangle (the first in
// index order) take it. Returns the texels covered.
std::size_t cover_texel_centres(const std::vector<std::uint32_t>& tris, const std::vector<P2>& px,
                                const std::vector<double>& area, int y0, int y1, UvRaster& r) {
  const int W = r.width, H = r.height;
  std::size_t covered = 0;
  for (std::uint32_t t : tris) {
    const P2 p[3] = {px[3 * t], px[3 * t + 1], px[3 * t + 2]};
    const Box bx = texel_box(p, 0.0, W, H);
    for (int y = std::max(bx.y0, y0); y <= std::min(bx.y1, y1); ++y)
      for (int x = bx.x0; x <= bx.x1; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * W + x;
        if (r.triangle[i] >= 0) continue;
        const auto b = barycentric(p[0], p[1], p[2], area[t], {x + 0.5, y + 0.5});
        if (b[0] < -1e-9 || b[1] < -1e-9 || b[2] < -1e-9) continue;
        r.triangle[i] = static_cast<int>(t);
        r.bary[i] = {static_cast<float>(b[0]), static_cast<float>(b[1]), static_cast<float>(b[2])};
        ++covered;
      }
  }
  return covered;
}

// Pass 2 over rows y0..y1 (after pass 1 on them): texels uncovered by pass 1
// within `band` take the nearest triangle (the first in index order on ties)
// at its nearest point. Returns the texels added.
std::size_t cover_band(const std::vector<std::uint32_t>& tris, const std::vector<P2>& px,
                       const std::vector<double>& area, double band, int y0, int y1, UvRaster& r) {
  const int W = r.width, H = r.height;
  std::vector<double> best(static_cast<std::size_t>(y1 - y0 + 1) * W, std::numeric_limits<double>::infinity());
  const double band2 = band * band;
  std::size_t added = 0;
  for (std::uint32_t t : tris) {
    const P2 p[3] = {px[3 * t], px[3 * t + 1], px[3 * t + 2]};
    const Box bx = texel_box(p, band, W, H);
    for (int y = std::max(bx.y0, y0); y <= std::min(bx.y1, y1); ++y)
      for (int x = bx.x0; x <= bx.x1; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * W + x, j = static_cast<std::size_t>(y - y0) * W + x;
        if (r.triangle[i] >= 0 && best[j] == std::numeric_limits<double>::infinity()) continue;  // pass 1
        const P2 q{x + 0.5, y + 0.5};
        double d2 = std::numeric_limits<double>::infinity();
        std::array<double, 3> b{};
        for (int e = 0; e < 3; ++e) {
          const auto [s, dd] = nearest_on_segment(p[e], p[(e + 1) % 3], q);
          if (dd < d2) {
            d2 = dd;
            b = {0, 0, 0};
            b[e] = 1 - s;
            b[(e + 1) % 3] = s;
          }
        }
        if (d2 > band2 || !(d2 < best[j])) continue;
        if (r.triangle[i] < 0) ++added;
        best[j] = d2;
        r.triangle[i] = static_cast<int>(t);
        r.bary[i] = {static_cast<float>(b[0]), static_cast<float>(b[1]), static_cast<float>(b[2])};
      }
  }
  return added;
}

}  // namespace

UvRaster rasterize_uv_triangles(const std::vector<UvTriangle>& tris, int W, int H, double band) {
  if (W < 1 || H < 1 || W > 16384 || H > 16384)
    throw InvalidInputError("rasterize_uv_triangles: size " + std::to_string(W) + " x " + std::to_string(H) +
                            " outside 1..16384");
  if (!(band >= 0 && band <= 4))
    throw InvalidInputError("rasterize_uv_triangles: band " + std::to_string(band) + " outside [0, 4]");
  UvRaster r;
  r.width = W;
  r.height = H;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  r.triangle.assign(N, -1);
  r.bary.assign(N, {0.f, 0.f, 0.f});
  std::vector<P2> px(3 * tris.size());
  std::vector<double> area(tris.size());
  for (std::size_t t = 0; t < tris.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const double u = tris[t][k][0], v = tris[t][k][1];
      if (!std::isfinite(u) || !std::isfinite(v))
        throw InvalidInputError("rasterize_uv_triangles: triangle " + std::to_string(t) + " has a non-finite uv");
      px[3 * t + k] = {u * W, (1.0 - v) * H};
    }
    const P2 &a = px[3 * t], &b = px[3 * t + 1], &c = px[3 * t + 2];
    area[t] = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  }
  // Rows in bands, each band's triangles in index order: a texel sees the
  // triangles in the same order as one pass over all of them would, so the
  // raster is the same for any thread count.
  const int bands = (H + kBandRows - 1) / kBandRows;
  std::vector<std::vector<std::uint32_t>> in_band(static_cast<std::size_t>(bands));
  for (std::size_t t = 0; t < tris.size(); ++t) {
    if (!(std::abs(area[t]) > 1e-12)) continue;
    const P2 p[3] = {px[3 * t], px[3 * t + 1], px[3 * t + 2]};
    const Box bx = texel_box(p, band, W, H);
    if (bx.x0 > bx.x1 || bx.y0 > bx.y1) continue;
    for (int b = bx.y0 / kBandRows; b <= bx.y1 / kBandRows; ++b) in_band[b].push_back(static_cast<std::uint32_t>(t));
  }
  std::vector<std::size_t> inside(in_band.size(), 0), banded(in_band.size(), 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, bands, 1), [&](const tbb::blocked_range<int>& range) {
    for (int b = range.begin(); b != range.end(); ++b) {
      const int y0 = b * kBandRows, y1 = std::min(H, y0 + kBandRows) - 1;
      inside[b] = cover_texel_centres(in_band[b], px, area, y0, y1, r);
      if (band > 0) banded[b] = cover_band(in_band[b], px, area, band, y0, y1, r);
    }
  });
  for (int b = 0; b < bands; ++b) r.inside += inside[b], r.band += banded[b];
  return r;
}

}  // namespace surftex
