// SPDX-License-Identifier: AGPL-3.0-or-later
// Vertex colours -> texture atlas (see bake_vertex_colors.h).
#include "geometry/bake_vertex_colors.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex {

BakeResult bake_vertex_colors(const Mesh& mesh, const BakeOptions& opt) {
  if (opt.size < 1 || opt.size > 16384)
    throw InvalidInputError("bake_vertex_colors: size must be in 1..16384 (got " + std::to_string(opt.size) + ")");
  if (opt.dilate < 0) throw InvalidInputError("bake_vertex_colors: dilate must be >= 0");
  auto uv = find(mesh, kCornerUV);
  auto col = find(mesh, kVertexColor);
  if (!uv.second || !col.second)
    throw InvalidInputError("bake_vertex_colors: the mesh needs kCornerUV (h:uv) and kVertexColor (v:color)");
  const int N = opt.size;
  BakeResult res;
  res.image = Image(N, N, 3);
  std::vector<char> filled(static_cast<std::size_t>(N) * N, 0);
  for (FaceIndex f : mesh.faces()) {
    if (mesh.degree(f) != 3)
      throw InvalidInputError("bake_vertex_colors: face " + std::to_string(f.idx()) + " is not a triangle");
    std::array<double, 3> x{}, y{};
    std::array<Color3f, 3> c{};
    int i = 0;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      x[i] = uv.first[h][0] * N;
      y[i] = (1.0 - uv.first[h][1]) * N;
      c[i] = col.first[mesh.target(h)];
      ++i;
    }
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (!(std::abs(area) > 1e-18)) continue;
    const int x0 = std::max(0, int(std::floor(*std::min_element(x.begin(), x.end()) - 0.5)));
    const int x1 = std::min(N - 1, int(std::ceil(*std::max_element(x.begin(), x.end()) + 0.5)));
    const int y0 = std::max(0, int(std::floor(*std::min_element(y.begin(), y.end()) - 0.5)));
    const int y1 = std::min(N - 1, int(std::ceil(*std::max_element(y.begin(), y.end()) + 0.5)));
    for (int py = y0; py <= y1; ++py)
      for (int px = x0; px <= x1; ++px) {
        const double sx = px + 0.5, sy = py + 0.5;
        const double b1 = ((sx - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (sy - y[0])) / area;
        const double b2 = ((x[1] - x[0]) * (sy - y[0]) - (sx - x[0]) * (y[1] - y[0])) / area;
        const double b0 = 1 - b1 - b2;
        if (b0 < -1e-6 || b1 < -1e-6 || b2 < -1e-6) continue;
        for (int k = 0; k < 3; ++k)
          res.image.at(px, py, k) = float(b0 * c[0][k] + b1 * c[1][k] + b2 * c[2][k]);
        filled[static_cast<std::size_t>(py) * N + px] = 1;
      }
  }
  for (char f : filled) res.covered += f != 0;
  for (int ring = 0; ring < opt.dilate; ++ring) {
    std::vector<char> next = filled;
    Image out = res.image;
    for (int py = 0; py < N; ++py)
      for (int px = 0; px < N; ++px) {
        if (filled[static_cast<std::size_t>(py) * N + px]) continue;
        float s[3] = {0, 0, 0};
        int n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = px + dx, qy = py + dy;
            if (qx < 0 || qy < 0 || qx >= N || qy >= N || !filled[static_cast<std::size_t>(qy) * N + qx]) continue;
            for (int k = 0; k < 3; ++k) s[k] += res.image.at(qx, qy, k);
            ++n;
          }
        if (!n) continue;
        for (int k = 0; k < 3; ++k) out.at(px, py, k) = s[k] / n;
        next[static_cast<std::size_t>(py) * N + px] = 1;
      }
    res.image = std::move(out);
    filled.swap(next);
  }
  for (int py = 0; py < N; ++py)
    for (int px = 0; px < N; ++px)
      if (!filled[static_cast<std::size_t>(py) * N + px])
        for (int k = 0; k < 3; ++k) res.image.at(px, py, k) = opt.background[k];
  return res;
}

}  // namespace surftex
