// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Rasterises triangles given in texture space (u right, v up, [0,1]^2) into a
// width x height texel grid, for baking anything defined on a surface into an
// atlas (vertex colours, material-space lookups, PBR maps).
//
// Pass 1: texel centres inside a triangle (first in index order on shared
// edges) take it and their barycentrics. Pass 2 (`band` > 0): uncovered texels
// within `band` take the nearest triangle and nearest point, so chart edges
// hold the chart's own values. Zero-area triangles cover nothing.
//
// This header uses no CGAL. Throws InvalidInputError on sizes outside
// 1..16384, band outside [0, 4] or a non-finite uv.

#include <array>
#include <vector>

namespace surftex {

struct UvRaster {
  int width = 0, height = 0;
  std::vector<int> triangle;                 ///< per texel (row-major, row 0 = top = v 1), -1 = none
  std::vector<std::array<float, 3>> bary;    ///< per texel, barycentrics in `triangle`
  std::size_t inside = 0;                    ///< texels of pass 1
  std::size_t band = 0;                      ///< texels of pass 2
};

using UvTriangle = std::array<std::array<double, 2>, 3>;

UvRaster rasterize_uv_triangles(const std::vector<UvTriangle>& triangles, int width, int height,
                                double band = 1.0);

}  // namespace surftex
