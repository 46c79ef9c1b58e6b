// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Checks of a uv atlas (kCornerUV) shared by the atlas tests: faces that are
// flipped in uv, and texels covered twice (charts folded over themselves or
// over each other), counted independently of the atlas code.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex::test {

/// Faces whose uv triangle (corners in face order) has non-positive signed area.
inline std::size_t uv_flipped_faces(const Mesh& m) {
  auto uv = find(m, kCornerUV).first;
  std::size_t n = 0;
  for (FaceIndex f : m.faces()) {
    std::array<UV, 3> t;
    int k = 0;
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) t[k++] = uv[h];
    n += !((t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]) > 0);
  }
  return n;
}

/// Texel centres of an N x N grid over [0,1]^2 strictly inside (all
/// barycentrics > 1e-6) the uv triangles of two or more faces.
inline std::size_t uv_overlap_texels(const Mesh& m, int N) {
  auto uv = find(m, kCornerUV).first;
  std::vector<unsigned char> hits(static_cast<std::size_t>(N) * N, 0);
  std::size_t twice = 0;
  for (FaceIndex f : m.faces()) {
    std::array<std::array<double, 2>, 3> t;
    int k = 0;
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f)))
      t[k++] = {uv[h][0] * N - 0.5, uv[h][1] * N - 0.5};
    const double area = (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    if (!(area > 0)) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({t[0][0], t[1][0], t[2][0]}))));
    const int x1 = std::min(N - 1, static_cast<int>(std::ceil(std::max({t[0][0], t[1][0], t[2][0]}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({t[0][1], t[1][1], t[2][1]}))));
    const int y1 = std::min(N - 1, static_cast<int>(std::ceil(std::max({t[0][1], t[1][1], t[2][1]}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        bool inside = true;
        for (int e = 0; e < 3 && inside; ++e) {
          const auto &a = t[e], &b = t[(e + 1) % 3];
          inside = ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) / area > 1e-6;
        }
        unsigned char& n = hits[static_cast<std::size_t>(y) * N + x];
        if (inside && n < 2 && ++n == 2) ++twice;
      }
  }
  return twice;
}

}  // namespace surftex::test
