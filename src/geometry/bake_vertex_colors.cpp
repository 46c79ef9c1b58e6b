// SPDX-License-Identifier: AGPL-3.0-or-later
// Vertex colours -> texture atlas (see bake_vertex_colors.h).
#include "geometry/bake_vertex_colors.h"

#include <algorithm>
#include <string>

#include "geometry/atlas_gutter.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/uv_raster.h"

namespace surftex {

BakeResult bake_vertex_colors(const Mesh& mesh, const BakeOptions& opt) {
  if (opt.size < 1 || opt.size > 16384)
    throw InvalidInputError("bake_vertex_colors: size must be in 1..16384 (got " + std::to_string(opt.size) + ")");
  auto uv = find(mesh, kCornerUV);
  auto col = find(mesh, kVertexColor);
  if (!uv.second || !col.second)
    throw InvalidInputError("bake_vertex_colors: the mesh needs kCornerUV (h:uv) and kVertexColor (v:color)");
  auto patch = find(mesh, kFacePatch);
  const int N = opt.size;
  std::vector<UvTriangle> tris;
  std::vector<std::array<VertexIndex, 3>> corners;
  std::vector<int> chart_of;
  for (FaceIndex f : mesh.faces()) {
    if (mesh.degree(f) != 3)
      throw InvalidInputError("bake_vertex_colors: face " + std::to_string(f.idx()) + " is not a triangle");
    UvTriangle t;
    std::array<VertexIndex, 3> v;
    int i = 0;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      t[i] = {uv.first[h][0], uv.first[h][1]};
      v[i++] = mesh.target(h);
    }
    tris.push_back(t);
    corners.push_back(v);
    chart_of.push_back(patch.second ? std::max(0, patch.first[f]) : 0);
  }
  const UvRaster r = rasterize_uv_triangles(tris, N, N, 1.0);
  BakeResult res;
  res.image = Image(N, N, 3);
  res.chart.assign(static_cast<std::size_t>(N) * N, -1);
  for (std::size_t i = 0; i < res.chart.size(); ++i) {
    const int t = r.triangle[i];
    if (t < 0) continue;
    res.chart[i] = chart_of[t];
    ++res.covered;
    for (int k = 0; k < 3; ++k) {
      float s = 0.f;
      for (int c = 0; c < 3; ++c) s += r.bary[i][c] * col.first[corners[t][c]][k];
      res.image.data[3 * i + k] = s;
    }
  }
  res.owner = res.chart;
  if (res.covered > 0) dilate_charts(res.image, res.owner);
  return res;
}

}  // namespace surftex
