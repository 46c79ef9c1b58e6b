// SPDX-License-Identifier: AGPL-3.0-or-later
// Material-space mapping -> UV atlas (see bake_material_space.h).
#include "texture/material_space/bake_material_space.h"
#include "geometry/vec3.h"

#include <nlohmann/json.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/atlas_gutter.h"
#include "geometry/gutter_atlas.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/polygon_util.h"
#include "geometry/properties.h"
#include "geometry/timer.h"
#include "texture/pbr_maps.h"
#include "texture/tangent_space_bake.h"

namespace surftex {

namespace {

double luminance(const Vec3f& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// The lookups of a point of `face` (section 3): calls f(weight, position,
// chart corners) once with the face's own corners (regular face, or no fix),
// or three times with each corner's chart and its barycentric weight.
template <class F>
void for_each_lookup(const PgpSingularities& sing, std::uint32_t face, const std::array<double, 3>& b, bool fix,
                     F&& f) {
  if (!fix || !sing.singular_face[face]) {
    f(1.0, plain_lookup_position(sing, face, b), sing.corners[face]);
    return;
  }
  const auto p = singular_lookup_positions(sing, face, b);
  for (int k = 0; k < 3; ++k) f(b[k], p[k], sing.charts[face][k]);
}

using D3 = std::array<double, 3>;
using vec3::sub;
D3 axpy(double s, const D3& a, const D3& y) { return {s * a[0] + y[0], s * a[1] + y[1], s * a[2] + y[2]}; }
using vec3::dot;
bool normalise(D3& a) {
  const double l = std::sqrt(dot(a, a));
  if (!(l > 1e-300) || !std::isfinite(l)) return false;
  for (double& c : a) c /= l;
  return true;
}

// A face's corner positions and vertex normals, in PGP corner order.
struct BakeFaceFrame {
  D3 p[3], n[3];
};

// The object-space normal of tile normal `tn` (decoded, tile frame) at
// barycentrics b of face `ff`, the chart's (s,t) at the corners being `c`.
// Falls back to the interpolated normal where the chart is degenerate.
D3 object_normal(const BakeFaceFrame& ff, const std::array<StmPoint, 3>& c, const std::array<double, 3>& b, const D3& tn) {
  D3 N{0, 0, 0};
  for (int k = 0; k < 3; ++k) N = axpy(b[k], ff.n[k], N);
  if (!normalise(N)) {
    const D3 e1 = sub(ff.p[1], ff.p[0]), e2 = sub(ff.p[2], ff.p[0]);
    N = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    if (!normalise(N)) return {0, 0, 1};
  }
  // P(s,t) is affine on the face: (ds, dt) = a (s1-s0, t1-t0) + b (s2-s0, t2-t0).
  const double s1 = c[1][0] - c[0][0], t1 = c[1][1] - c[0][1], s2 = c[2][0] - c[0][0], t2 = c[2][1] - c[0][1];
  const double det = s1 * t2 - s2 * t1;
  if (!(std::abs(det) > 1e-300)) return N;
  const D3 e1 = sub(ff.p[1], ff.p[0]), e2 = sub(ff.p[2], ff.p[0]);
  D3 S = axpy(t2 / det, e1, axpy(-t1 / det, e2, {0, 0, 0}));   // dP/ds
  D3 U = axpy(s2 / det, e1, axpy(-s1 / det, e2, {0, 0, 0}));   // -dP/dt: up in the tile image
  S = axpy(-dot(S, N), N, S);
  if (!normalise(S)) return N;
  U = axpy(-dot(U, N), N, U);
  U = axpy(-dot(U, S), S, U);
  if (!normalise(U)) return N;
  D3 n = axpy(tn[0], S, axpy(tn[1], U, axpy(tn[2], N, {0, 0, 0})));
  return normalise(n) ? n : N;
}

}  // namespace

Vec3f material_space_color(const PgpSingularities& sing, const MaterialTile& tile, std::uint32_t face,
                           const std::array<double, 3>& b, bool fix) {
  Vec3f out{0.f, 0.f, 0.f};
  for_each_lookup(sing, face, b, fix, [&](double w, const StmPoint& p, const std::array<StmPoint, 3>&) {
    const Vec3f c = sample_material_tile(tile, p[0], p[1], p[2]);
    for (int d = 0; d < 3; ++d) out[d] += static_cast<float>(w) * c[d];
  });
  return out;
}

namespace {

// Corner positions and vertex normals of every face (kVertexNormal, else the
// area-weighted normals the mesh writers compute).
std::vector<BakeFaceFrame> face_frames(const Mesh& mesh) {
  std::vector<Vector3> vn;
  if (auto m = find(mesh, kVertexNormal); m.second) {
    vn.resize(mesh.number_of_vertices());
    for (VertexIndex v : mesh.vertices()) vn[v.idx()] = m.first[v];
  } else {
    vn = polygon_vertex_normals(mesh);
  }
  std::vector<BakeFaceFrame> frames(mesh.num_faces());
  for (FaceIndex f : mesh.faces()) {
    int k = 0;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      if (k == 3) break;
      const Point3& p = mesh.point(mesh.target(h));
      const Vector3& n = vn[mesh.target(h).idx()];
      frames[f.idx()].p[k] = {p.x(), p.y(), p.z()};
      frames[f.idx()].n[k] = {n.x(), n.y(), n.z()};
      ++k;
    }
  }
  return frames;
}

}  // namespace

MaterialBakeResult bake_material_space(Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile,
                                       const MaterialBakeOptions& opt) {
  if (opt.size < 64 || opt.size > 8192)
    throw InvalidInputError("bake_material_space: size " + std::to_string(opt.size) + " outside 64..8192");
  if (opt.min_mip_size < 1)
    throw InvalidInputError("bake_material_space: min_mip_size must be >= 1, got " + std::to_string(opt.min_mip_size));
  validate_material_tile(tile);
  if (mesh.has_garbage() || sing.charts.size() != mesh.num_faces() || sing.singular_face.size() != mesh.num_faces() ||
      sing.corners.size() != mesh.num_faces())
    throw InvalidInputError("bake_material_space: the singularities cover " + std::to_string(sing.charts.size()) +
                            " faces, the mesh has " + std::to_string(mesh.num_faces()));
  MaterialBakeResult r;
  const int N = opt.size;
  GutterAtlas ga = compute_gutter_atlas(mesh, N, opt.min_mip_size);
  r.seconds_atlas = ga.seconds;
  r.charts = ga.atlas.num_charts;
  r.texels_per_length = ga.atlas.uv_per_length * N;
  r.gutter = ga.gutter;
  r.protected_mip_size = ga.protected_mip_size;
  r.margin = ga.margin;
  r.gutter_violations = ga.violations;
  r.chart = std::move(ga.chart);
  const UvRaster& raster = ga.raster;
  Timer tl;
  r.color = Image(N, N, 3, 0.f);
  r.height = Image(N, N, 1, 0.f);
  r.height_from_tile = !tile.height_layers.empty();
  if (!tile.roughness_layers.empty()) r.roughness = Image(N, N, 1, 0.f);
  const bool normals = !tile.normal_layers.empty();
  std::vector<BakeFaceFrame> frames;
  if (normals) frames = face_frames(mesh);
  if (normals) r.object_normal = Image(N, N, 3, 0.f);
  // Every channel through the same lookups (for_each_lookup): colour, the
  // maps' values blended with the same weights.
  tbb::parallel_for(0, N, [&](int y) {
    for (int x = 0; x < N; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * N + x;
      if (raster.triangle[i] < 0) continue;
      const auto& bf = raster.bary[i];
      const std::array<double, 3> b{bf[0], bf[1], bf[2]};
      const auto face = static_cast<std::uint32_t>(raster.triangle[i]);
      const Vec3f c = material_space_color(sing, tile, face, b, opt.fix_singularities);
      for (int k = 0; k < 3; ++k) r.color.data[3 * i + k] = c[k];
      double h = 0, rough = 0;
      D3 n{0, 0, 0};
      for_each_lookup(sing, face, b, opt.fix_singularities,
                      [&](double w, const StmPoint& p, const std::array<StmPoint, 3>& chart) {
                        if (r.height_from_tile) h += w * sample_material_layers(tile.height_layers, p[0], p[1], p[2])[0];
                        if (!r.roughness.empty())
                          rough += w * sample_material_layers(tile.roughness_layers, p[0], p[1], p[2])[0];
                        if (!normals) return;
                        const Vec3f e = sample_material_layers(tile.normal_layers, p[0], p[1], p[2]);
                        D3 tn{2.0 * e[0] - 1, 2.0 * e[1] - 1, 2.0 * e[2] - 1};
                        if (!normalise(tn)) tn = {0, 0, 1};
                        n = axpy(w, object_normal(frames[face], chart, b, tn), n);
                      });
      r.height.data[i] = static_cast<float>(std::clamp(r.height_from_tile ? h : luminance(c), 0.0, 1.0));
      if (!r.roughness.empty()) r.roughness.data[i] = static_cast<float>(std::clamp(rough, 0.0, 1.0));
      if (normals) {
        if (!normalise(n)) n = object_normal(frames[face], sing.corners[face], b, {0, 0, 1});
        for (int k = 0; k < 3; ++k) r.object_normal.data[3 * i + k] = static_cast<float>(n[k]);
      }
    }
  });
  r.seconds_lookup = tl.seconds();
  std::size_t covered = 0;
  for (int c : r.chart) covered += c >= 0;
  r.coverage = static_cast<double>(covered) / (static_cast<double>(N) * N);
  Timer tg;
  r.owner = r.chart;  // the same labels as ga.owner, now with the colours
  std::vector<int> owner2 = r.chart;
  dilate_charts(r.color, r.owner);
  dilate_charts(r.height, owner2);
  if (!r.roughness.empty()) {
    owner2 = r.chart;
    dilate_charts(r.roughness, owner2);
  }
  r.seconds_gutter += tg.seconds();
  return r;
}

Image material_space_tangent_normals(const Mesh& mesh, const MaterialBakeResult& bake) {
  const Image& on = bake.object_normal;
  if (on.empty() || on.channels != 3 || bake.chart.size() != static_cast<std::size_t>(on.width) * on.height)
    throw InvalidInputError("material_space_tangent_normals: the bake holds no object-space normals");
  const int N = on.width;
  // The frame per texel, from the one tangent-space bake (tangent_space_bake.h):
  // a constant per-vertex normal e_k gives per texel (e_k.T, e_k.B, e_k.N),
  // column k of the orthonormal frame [T B N], a unit vector (its
  // normalisation there changes nothing); n_ts = sum_k n_k column_k.
  std::array<Image, 3> column;
  for (int k = 0; k < 3; ++k) {
    std::array<float, 3> e{0.f, 0.f, 0.f};
    e[k] = 1.f;
    column[k] = tangent_space_normal_map(mesh, std::vector<std::array<float, 3>>(mesh.num_vertices(), e), N);
  }
  Image out(N, N, 3, 0.f);
  for (std::size_t i = 0; i < bake.chart.size(); ++i) {
    if (bake.chart[i] < 0) continue;
    D3 ts{0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) ts[c] += on.data[3 * i + k] * (2.0 * column[k].data[3 * i + c] - 1.0);
    if (!normalise(ts)) ts = {0, 0, 1};
    for (int c = 0; c < 3; ++c) out.data[3 * i + c] = static_cast<float>(0.5 * ts[c] + 0.5);
  }
  std::vector<int> label = bake.chart;
  dilate_charts(out, label);
  return out;
}


MaterialAsset bake_material_asset(Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile, int atlas_size,
                                  double bump, double period) {
  MaterialAsset a;
  MaterialBakeOptions bo;
  bo.size = atlas_size;
  a.bake = bake_material_space(mesh, sing, tile, bo);
  if (!a.bake.roughness.empty()) a.metallic_roughness = metallic_roughness_from_roughness(a.bake.roughness);
  if (!a.bake.object_normal.empty()) {  // the tile's normals, in the GLB's tangent frames
    a.normal = material_space_tangent_normals(mesh, a.bake);
    a.normal_source = "exemplar_normal";
    return a;
  }
  a.normal = normal_map_from_height(a.bake.height, a.bake.chart, bump * period * a.bake.texels_per_length);
  a.normal_source = "height";
  return a;
}

nlohmann::json to_json(const MaterialAsset& a) {
  const MaterialBakeResult& b = a.bake;
  return {{"size", b.color.width},          {"charts", b.charts},
          {"gutter", b.gutter},             {"gutter_violations", b.gutter_violations},
          {"protected_mip_size", b.protected_mip_size},
          {"margin", b.margin},             {"coverage", b.coverage},
          {"texels_per_length", b.texels_per_length},
          {"normal_source", a.normal_source},
          {"height_source", b.height_from_tile ? "exemplar_height" : "luminance"},
          {"roughness", !b.roughness.empty()},
          {"seconds", {{"atlas", b.seconds_atlas}, {"lookup", b.seconds_lookup}, {"gutter", b.seconds_gutter}}}};
}

}  // namespace surftex
