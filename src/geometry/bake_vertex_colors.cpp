// SPDX-License-Identifier: AGPL-3.0-or-later
// Vertex colours -> texture atlas (see bake_vertex_colors.h).
#include "geometry/bake_vertex_colors.h"

#include <algorithm>
#include <string>

#include <tbb/parallel_for.h>

#include "geometry/atlas_gutter.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex {

AtlasTexels rasterize_atlas(const Mesh& mesh, int size) {
  if (size < 1 || size > 16384)
    throw InvalidInputError("bake_vertex_colors: size must be in 1..16384 (got " + std::to_string(size) + ")");
  auto uv = find(mesh, kCornerUV);
  if (!uv.second) throw InvalidInputError("bake_vertex_colors: the mesh needs kCornerUV (h:uv)");
  auto patch = find(mesh, kFacePatch);
  std::vector<UvTriangle> tris;
  std::vector<int> chart_of;
  AtlasTexels at;
  for (FaceIndex f : mesh.faces()) {
    if (mesh.degree(f) != 3)
      throw InvalidInputError("bake_vertex_colors: face " + std::to_string(f.idx()) + " is not a triangle");
    UvTriangle t;
    std::array<std::size_t, 3> c;
    int i = 0;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      t[i] = {uv.first[h][0], uv.first[h][1]};
      c[i++] = h.idx();
    }
    tris.push_back(t);
    at.corner.push_back(c);
    chart_of.push_back(patch.second ? std::max(0, patch.first[f]) : 0);
  }
  at.raster = rasterize_uv_triangles(tris, size, size, 1.0);
  at.chart.assign(static_cast<std::size_t>(size) * size, -1);
  for (std::size_t i = 0; i < at.chart.size(); ++i) {
    const int t = at.raster.triangle[i];
    if (t < 0) continue;
    at.chart[i] = chart_of[t];
    ++at.covered;
  }
  return at;
}

BakeResult bake_texel_values(const Mesh& mesh, int C, const TexelValueFn& value, const BakeOptions& opt) {
  if (C < 1 || C > 4) throw InvalidInputError("bake_texel_values: channels must be 1..4 (got " + std::to_string(C) + ")");
  const AtlasTexels at = rasterize_atlas(mesh, opt.size);
  const int N = opt.size;
  BakeResult res;
  res.image = Image(N, N, C);
  res.chart = at.chart;
  res.covered = at.covered;
  tbb::parallel_for(0, N, [&](int row) {  // each texel written once: any thread count gives the same bytes
    for (std::size_t i = static_cast<std::size_t>(row) * N, e = i + N; i < e; ++i) {
      const int t = at.raster.triangle[i];
      if (t >= 0) value(at.corner[t], at.raster.bary[i], &res.image.data[C * i]);
    }
  });
  res.owner = res.chart;
  if (res.covered > 0) dilate_charts(res.image, res.owner);
  return res;
}

BakeResult bake_vertex_values(const Mesh& mesh, const std::vector<float>& values, int C, const BakeOptions& opt) {
  if (C < 1 || values.size() != static_cast<std::size_t>(C) * mesh.num_vertices())
    throw InvalidInputError("bake_vertex_values: " + std::to_string(values.size()) + " values for " +
                            std::to_string(mesh.num_vertices()) + " vertices x " + std::to_string(C) + " channels");
  const auto blend = [&](const std::array<std::size_t, 3>& corner, const std::array<float, 3>& bary, float* out) {
    for (int k = 0; k < C; ++k) {
      float s = 0.f;
      for (int c = 0; c < 3; ++c)
        s += bary[c] * values[mesh.target(HalfedgeIndex(static_cast<Mesh::size_type>(corner[c]))).idx() * C + k];
      out[k] = s;
    }
  };
  return bake_texel_values(mesh, C, blend, opt);
}

BakeResult bake_vertex_colors(const Mesh& mesh, const BakeOptions& opt) {
  auto uv = find(mesh, kCornerUV);
  auto col = find(mesh, kVertexColor);
  if (!uv.second || !col.second)
    throw InvalidInputError("bake_vertex_colors: the mesh needs kCornerUV (h:uv) and kVertexColor (v:color)");
  std::vector<float> values(3 * mesh.num_vertices(), 0.f);
  for (VertexIndex v : mesh.vertices())
    for (int k = 0; k < 3; ++k) values[3 * v.idx() + k] = col.first[v][k];
  return bake_vertex_values(mesh, values, 3, opt);
}

}  // namespace surftex
