// SPDX-License-Identifier: AGPL-3.0-or-later
// A base-mesh atlas spaced and verified for mip gutters (see gutter_atlas.h).
#include "geometry/gutter_atlas.h"

#include <algorithm>

#include "geometry/atlas_gutter.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/timer.h"

namespace surftex {

namespace {

// UV triangles in corner order target(halfedge(f)), next, next-next.
std::vector<UvTriangle> face_uv_triangles(const Mesh& mesh) {
  auto uv = find(mesh, kCornerUV).first;
  std::vector<UvTriangle> tris(mesh.num_faces());
  for (FaceIndex f : mesh.faces()) {
    HalfedgeIndex h = mesh.halfedge(f);
    for (int k = 0; k < 3; ++k, h = mesh.next(h)) tris[f.idx()][k] = {uv[h][0], uv[h][1]};
  }
  return tris;
}

}  // namespace

GutterAtlas compute_gutter_atlas(Mesh& mesh, int size, int min_mip_size) {
  Timer t;
  GutterAtlas g;
  g.gutter = atlas_gutter_texels(size, min_mip_size);
  // Charts 2 * gutter + 1 texels apart, plus the raster's texel band on both
  // sides and slack for the packing's estimate of its final side.
  g.margin = std::min(0.099, 1.3 * (2.0 * g.gutter + 4.0) / size);
  for (int attempt = 0;; ++attempt) {
    BaseMeshAtlasOptions ao;
    ao.margin = g.margin;
    g.atlas = compute_base_mesh_atlas(mesh, ao);
    g.raster = rasterize_uv_triangles(face_uv_triangles(mesh), size, size, 1.0);
    auto patch = find(mesh, kFacePatch).first;
    g.chart.assign(g.raster.triangle.size(), -1);
    for (std::size_t i = 0; i < g.raster.triangle.size(); ++i)
      if (g.raster.triangle[i] >= 0) g.chart[i] = patch[FaceIndex(static_cast<std::uint32_t>(g.raster.triangle[i]))];
    g.owner = g.chart;
    Image labels_only(size, size, 1, 0.f);
    dilate_charts(labels_only, g.owner);
    g.violations = gutter_violations(g.chart, g.owner, size, size, g.gutter);
    if (g.violations == 0 || g.margin >= 0.099 || attempt >= 3) break;
    g.margin = std::min(0.099, g.margin * 1.5);
  }
  g.seconds = t.seconds();
  return g;
}

}  // namespace surftex
