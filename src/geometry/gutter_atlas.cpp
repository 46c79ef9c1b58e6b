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

// One packing of base_mesh_atlas's charts (grown with `cone` degrees): the
// uv and chart of every corner before the repacking, the chart boxes, the
// gutter, scale and box offsets chosen.
struct Candidate {
  BaseMeshAtlasResult atlas;
  std::vector<UV> uv;        // per halfedge index
  std::vector<int> patch;    // per face index
  std::vector<Box> box;
  std::vector<std::array<double, 2>> offset;
  int gutter = 0;
  double scale = 0;          // texels per base-atlas uv unit
  double density() const {   // texels per mesh length, discounted by the area distortion
    return scale * atlas.uv_per_length / std::sqrt(std::max(1.0, atlas.mean_area_distortion));
  }
};

// Share of the one-texel-gutter density the full mip gutter may cost before
// it is narrowed (decision 302).
constexpr double kMinDensityShare = 0.25;

Candidate pack_candidate(Mesh& mesh, int N, int full_gutter, double cone, std::size_t max_chart_faces) {
  Candidate c;
  BaseMeshAtlasOptions ao;
  ao.max_normal_angle_deg = cone;
  ao.merge_charts = true;  // merges weigh the full gutter's gap (2 g + 3 texels)
  ao.max_chart_faces = max_chart_faces;
  ao.margin = std::min(0.099, (2.0 * full_gutter + 3.0) / N);
  c.atlas = compute_base_mesh_atlas(mesh, ao);
  auto uv = find(mesh, kCornerUV).first;
  auto patch = find(mesh, kFacePatch).first;
  c.uv.assign(mesh.num_halfedges(), UV{0, 0});
  c.patch.assign(mesh.num_faces(), -1);
  c.box.resize(c.atlas.num_charts);
  for (FaceIndex f : mesh.faces()) {
    c.patch[f.idx()] = patch[f];
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      c.uv[h.idx()] = uv[h];
      Box& b = c.box[patch[f]];
      b.u0 = std::min(b.u0, uv[h][0]), b.v0 = std::min(b.v0, uv[h][1]);
      b.u1 = std::max(b.u1, uv[h][0]), b.v1 = std::max(b.v1, uv[h][1]);
    }
  }
  std::vector<int> order(c.box.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return c.box[a].v1 - c.box[a].v0 > c.box[b].v1 - c.box[b].v0; });
  double largest_side = 1e-300;
  for (const Box& b : c.box) largest_side = std::max({largest_side, b.u1 - b.u0, b.v1 - b.v0});
  // Charts 2 * gutter + 1 texels apart plus the raster's one-texel band on
  // both sides: the largest scale whose packing fits (bisection; 0 = none).
  auto best_scale = [&](int gutter, std::vector<std::array<double, 2>>& best) {
    const double gap = 2.0 * gutter + 3.0;
    std::vector<std::array<double, 2>> at(c.box.size());
    double lo = 0, hi = N / largest_side;  // texels per uv unit of the base atlas (largest box fits)
    best.clear();
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (shelf_pack(c.box, order, mid, gap, N, at)) lo = mid, best = at;
      else hi = mid;
    }
    return best.empty() ? 0.0 : lo;
  };
  // The full mip gutter unless it leaves less than a quarter of the texel
  // density of a one-texel gutter (so many small charts that the gutters
  // would take the atlas): then the largest power-of-two gutter that keeps it.
  std::vector<std::array<double, 2>> one;
  const double s1 = best_scale(1, one);
  for (int gut = full_gutter; gut >= 1 && s1 > 0; gut /= 2) {
    c.scale = gut == 1 ? s1 : best_scale(gut, c.offset);
    if (gut == 1) c.offset = one;
    c.gutter = gut;
    if (c.scale >= kMinDensityShare * s1) break;
  }
  return c;
}

}  // namespace

GutterAtlas compute_gutter_atlas(Mesh& mesh, int N, int min_mip_size, std::size_t max_chart_faces) {
  Timer t;
  GutterAtlas g;
  const int full = atlas_gutter_texels(N, min_mip_size);
  // Charts grown in base_mesh_atlas's default 50-degree normal cone and
  // merged; if they cannot keep the full gutter, also in an 85-degree one
  // (fewer, larger charts: less gutter, more distortion); the one with the
  // higher texel density (discounted by its distortion) wins.
  Candidate c = pack_candidate(mesh, N, full, 50.0, max_chart_faces);
  if (c.gutter < full) {
    Candidate wide = pack_candidate(mesh, N, full, 85.0, max_chart_faces);
    if (wide.scale > 0 && (c.scale <= 0 || wide.density() > c.density())) c = std::move(wide);
  }
  if (c.scale <= 0)
    throw InvalidInputError("gutter atlas: " + std::to_string(c.box.size()) + " charts do not fit in " +
                            std::to_string(N) + " x " + std::to_string(N) + " texels (a larger atlas)");
  auto uv = find(mesh, kCornerUV).first;
  auto patch = find(mesh, kFacePatch).first;
  for (FaceIndex f : mesh.faces()) {
    const int k = c.patch[f.idx()];
    patch[f] = k;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      const UV& q = c.uv[h.idx()];
      uv[h] = {(c.offset[k][0] + 0.5 + (q[0] - c.box[k].u0) * c.scale) / N,
               (c.offset[k][1] + 0.5 + (q[1] - c.box[k].v0) * c.scale) / N};
    }
  }
  g.atlas = c.atlas;
  g.atlas.uv_per_length *= c.scale / N;
  g.gutter = c.gutter;
  g.protected_mip_size = N / g.gutter;
  g.margin = (2.0 * g.gutter + 3.0) / N;
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
