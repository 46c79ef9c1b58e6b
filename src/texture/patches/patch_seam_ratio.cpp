// SPDX-License-Identifier: AGPL-3.0-or-later
// On-surface seam ratio of a patch-textured mesh.
#include "texture/patches/patch_seam_ratio.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <unordered_map>

#include "geometry/mesh_util.h"
#include "geometry/properties.h"
#include "geometry/rasterizer.h"

namespace surftex {
namespace {

struct Located {
  int face = -1;
  std::array<double, 3> bary{};
};

// Barycentrics of (u, v) in flat triangle t, clamped to the triangle.
std::array<double, 3> bary_in(const FlatTriangle& t, double u, double v) {
  const auto& a = t.corner[0];
  const auto& b = t.corner[1];
  const auto& c = t.corner[2];
  const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
  if (!(std::abs(det) > 0)) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
  double b1 = ((u - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (v - a[1])) / det;
  double b2 = ((b[0] - a[0]) * (v - a[1]) - (u - a[0]) * (b[1] - a[1])) / det;
  double b0 = 1 - b1 - b2;
  b0 = std::max(0.0, b0);
  b1 = std::max(0.0, b1);
  b2 = std::max(0.0, b2);
  const double s = b0 + b1 + b2;
  return {b0 / s, b1 / s, b2 / s};
}

}  // namespace

SeamRatioResult patch_seam_ratio(const Mesh& mesh, const FlattenResult& flat, const Image& atlas,
                                 const SeamRatioOptions& opt) {
  if (!(opt.step_texels > 0) || !std::isfinite(opt.step_texels))
    throw InvalidInputError("patch_seam_ratio: step_texels " + std::to_string(opt.step_texels) +
                            " must be finite and > 0");
  if (opt.samples < 1)
    throw InvalidInputError("patch_seam_ratio: samples " + std::to_string(opt.samples) + " < 1");
  if (atlas.empty()) throw InvalidInputError("patch_seam_ratio: empty atlas");
  auto [uv, found] = find(mesh, kCornerUV);
  if (!found) throw InvalidInputError("patch_seam_ratio: the mesh has no h:uv map");
  const int P = static_cast<int>(flat.patches.size());
  if (P == 0) throw InvalidInputError("patch_seam_ratio: no patches");
  std::vector<int> face_patch(mesh.num_faces(), -1);
  for (int p = 0; p < P; ++p)
    for (const FlatTriangle& t : flat.patches[p].triangles) face_patch[t.face] = p;
  // Per patch: face -> flat triangle (patch and boundary).
  std::vector<std::unordered_map<int, const FlatTriangle*>> tri(P);
  std::vector<std::vector<std::size_t>> inside(P);
  for (int p = 0; p < P; ++p) {
    for (const FlatTriangle& t : flat.patches[p].triangles) tri[p][t.face] = &t;
    for (const FlatTriangle& t : flat.patches[p].boundary) tri[p][t.face] = &t;
    const auto& px = flat.patches[p].pixel;
    for (std::size_t i = 0; i < px.size(); ++i)
      if (px[i] == PatchPixel::Inside) inside[p].push_back(i);
  }
  auto colour = [&](int face, const std::array<double, 3>& b) {
    const FaceIndex f(static_cast<Mesh::size_type>(face));
    HalfedgeIndex h = mesh.halfedge(f);
    double u = 0, v = 0;
    for (int k = 0; k < 3; ++k, h = mesh.next(h)) {
      u += b[k] * uv[h][0];
      v += b[k] * uv[h][1];
    }
    return sample_texture(atlas, static_cast<float>(u), static_cast<float>(v), RenderOptions::Wrap::Clamp);
  };
  auto locate = [&](int p, double u, double v) -> Located {
    const FlatPatch& fp = flat.patches[p];
    const auto px = fp.to_pixel(u, v);
    const int x = static_cast<int>(std::floor(px[0])), y = static_cast<int>(std::floor(px[1]));
    if (!fp.in_window(x, y)) return {};
    const int face = fp.pixel_face[fp.index(x, y)];
    if (face < 0) return {};
    return {face, bary_in(*tri[p].at(face), u, v)};
  };
  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  SeamRatioResult r;
  double sum_a = 0, sum_w = 0;
  for (int s = 0; s < opt.samples; ++s) {
    const int p = static_cast<int>(std::min<double>(P - 1, U(rng) * P));
    if (inside[p].empty()) continue;
    const FlatPatch& fp = flat.patches[p];
    const std::size_t i = inside[p][std::min<std::size_t>(inside[p].size() - 1,
                                                          static_cast<std::size_t>(U(rng) * inside[p].size()))];
    const double x = static_cast<double>(fp.raster_x(i)) + U(rng), y = static_cast<double>(fp.raster_y(i)) + U(rng);
    const double th = 2 * M_PI * U(rng);
    const double x2 = x + opt.step_texels * std::cos(th), y2 = y + opt.step_texels * std::sin(th);
    const double u1 = fp.u0 + x * fp.texel, v1 = fp.v0 - y * fp.texel;
    const double u2 = fp.u0 + x2 * fp.texel, v2 = fp.v0 - y2 * fp.texel;
    const Located a = locate(p, u1, v1), b = locate(p, u2, v2);
    if (a.face < 0 || b.face < 0 || face_patch[a.face] != p) continue;
    const Vec3f ca = colour(a.face, a.bary), cb = colour(b.face, b.bary);
    const double d = std::sqrt((ca[0] - cb[0]) * (ca[0] - cb[0]) + (ca[1] - cb[1]) * (ca[1] - cb[1]) +
                               (ca[2] - cb[2]) * (ca[2] - cb[2]));
    if (face_patch[b.face] != p) {
      sum_a += d;
      ++r.pairs_across;
    } else {
      sum_w += d;
      ++r.pairs_within;
    }
  }
  r.mean_across = r.pairs_across ? sum_a / r.pairs_across : 0;
  r.mean_within = r.pairs_within ? sum_w / r.pairs_within : 0;
  r.ratio = (r.pairs_across && r.mean_within > 0) ? r.mean_across / r.mean_within : 0;
  return r;
}

}  // namespace surftex
