// SPDX-License-Identifier: AGPL-3.0-or-later
// A base-mesh atlas repacked in texels for mip gutters (see gutter_atlas.h).
#include "geometry/gutter_atlas.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "geometry/atlas_gutter.h"
#include "geometry/errors.h"
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

struct Box {
  double u0 = HUGE_VAL, v0 = HUGE_VAL, u1 = -HUGE_VAL, v1 = -HUGE_VAL;
};

// Shelf packing (tallest first) of the chart boxes scaled by `s` texels per
// uv unit, `gap` texels between boxes and from the border (texels are
// counted up to the next whole texel, so the gap holds after rounding).
// Offsets in texels of each box's lower-left corner; false if it overflows.
bool shelf_pack(const std::vector<Box>& box, const std::vector<int>& order, double s, double gap, int N,
                std::vector<std::array<double, 2>>& at) {
  double x = gap, y = gap, shelf = 0;
  for (int c : order) {
    const double w = std::ceil((box[c].u1 - box[c].u0) * s) + 1, h = std::ceil((box[c].v1 - box[c].v0) * s) + 1;
    if (x + w + gap > N && x > gap) y += shelf + gap, x = gap, shelf = 0;
    if (x + w + gap > N || y + h + gap > N) return false;
    at[c] = {x, y};
    x += w + gap;
    shelf = std::max(shelf, h);
  }
  return true;
}

}  // namespace

GutterAtlas compute_gutter_atlas(Mesh& mesh, int N, int min_mip_size) {
  Timer t;
  GutterAtlas g;
  g.gutter = atlas_gutter_texels(N, min_mip_size);
  g.atlas = compute_base_mesh_atlas(mesh);
  auto uv = find(mesh, kCornerUV).first;
  auto patch = find(mesh, kFacePatch).first;
  std::vector<Box> box(g.atlas.num_charts);
  for (FaceIndex f : mesh.faces())
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      Box& b = box[patch[f]];
      b.u0 = std::min(b.u0, uv[h][0]), b.v0 = std::min(b.v0, uv[h][1]);
      b.u1 = std::max(b.u1, uv[h][0]), b.v1 = std::max(b.v1, uv[h][1]);
    }
  std::vector<int> order(box.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return box[a].v1 - box[a].v0 > box[b].v1 - box[b].v0; });
  // Charts 2 * gutter + 1 texels apart plus the raster's one-texel band on
  // both sides: the largest scale whose packing fits (bisection).
  const double gap = 2.0 * g.gutter + 3.0;
  std::vector<std::array<double, 2>> at(box.size()), best;
  double lo = 0, hi = N;  // texels per uv unit of the base atlas ([0,1]^2 = N texels fits at most)
  for (int it = 0; it < 40; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (shelf_pack(box, order, mid, gap, N, at)) lo = mid, best = at;
    else hi = mid;
  }
  if (best.empty())
    throw InvalidInputError("gutter atlas: " + std::to_string(box.size()) + " charts with a gutter of " +
                            std::to_string(g.gutter) + " texels do not fit in " + std::to_string(N) + " x " +
                            std::to_string(N) + " texels (a larger atlas or a smaller min mip size)");
  const double s = lo;
  for (FaceIndex f : mesh.faces())
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      const int c = patch[f];
      uv[h] = {(best[c][0] + 0.5 + (uv[h][0] - box[c].u0) * s) / N, (best[c][1] + 0.5 + (uv[h][1] - box[c].v0) * s) / N};
    }
  g.atlas.uv_per_length *= s / N;
  g.margin = gap / N;
  g.raster = rasterize_uv_triangles(face_uv_triangles(mesh), N, N, 1.0);
  g.chart.assign(g.raster.triangle.size(), -1);
  for (std::size_t i = 0; i < g.raster.triangle.size(); ++i)
    if (g.raster.triangle[i] >= 0) g.chart[i] = patch[FaceIndex(static_cast<std::uint32_t>(g.raster.triangle[i]))];
  g.owner = g.chart;
  Image labels_only(N, N, 1, 0.f);
  dilate_charts(labels_only, g.owner);
  g.violations = gutter_violations(g.chart, g.owner, N, N, g.gutter);
  g.seconds = t.seconds();
  return g;
}

}  // namespace surftex
