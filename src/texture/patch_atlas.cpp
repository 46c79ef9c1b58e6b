// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch image atlas with dilated gutters (Gorla et al. 2003, 3.2 / 4.1).
#include "texture/patch_atlas.h"

#include <cmath>
#include <string>

#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

PatchAtlas pack_patch_atlas(Mesh& mesh, const FlattenResult& flat, const std::vector<Image>& images,
                            const PatchAtlasOptions& opt) {
  const int P = static_cast<int>(flat.patches.size());
  if (opt.gutter < 0 || opt.gutter > 64)
    throw InvalidInputError("pack_patch_atlas: gutter " + std::to_string(opt.gutter) + " outside 0..64");
  if (P == 0 || static_cast<int>(images.size()) != P)
    throw InvalidInputError("pack_patch_atlas: " + std::to_string(images.size()) + " images for " +
                            std::to_string(P) + " patches");
  const int R = flat.patches[0].res, C = images[0].channels;
  for (int p = 0; p < P; ++p)
    if (images[p].width != R || images[p].height != R || images[p].channels != C ||
        flat.patches[p].res != R)
      throw InvalidInputError("pack_patch_atlas: patch " + std::to_string(p) +
                              " image does not match the raster size " + std::to_string(R));
  PatchAtlas at;
  at.cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(P))));
  at.rows = (P + at.cols - 1) / at.cols;
  at.cell = R + opt.gutter;
  const int W = at.cols * at.cell + opt.gutter, H = at.rows * at.cell + opt.gutter;
  at.image = Image(W, H, C, 0.f);
  std::vector<char> filled(static_cast<std::size_t>(W) * H, 0);
  std::vector<double> mean(C, 0.0);
  std::size_t nmean = 0;
  at.offset.resize(P);
  for (int p = 0; p < P; ++p) {
    const int ox = opt.gutter + (p % at.cols) * at.cell, oy = opt.gutter + (p / at.cols) * at.cell;
    at.offset[p] = {ox, oy};
    const FlatPatch& fp = flat.patches[p];
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < R; ++x) {
        if (fp.pixel[static_cast<std::size_t>(y) * R + x] == PatchPixel::Outside) continue;
        for (int c = 0; c < C; ++c) {
          at.image.at(ox + x, oy + y, c) = images[p].at(x, y, c);
          mean[c] += images[p].at(x, y, c);
        }
        ++nmean;
        filled[static_cast<std::size_t>(oy + y) * W + ox + x] = 1;
      }
  }
  // Dilation into empty pixels.
  const int passes = opt.gutter + 8;
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<char> next = filled;
    Image out = at.image;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        if (filled[static_cast<std::size_t>(y) * W + x]) continue;
        float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
        int n = 0;
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
          if (nx[k] < 0 || ny[k] < 0 || nx[k] >= W || ny[k] >= H) continue;
          if (!filled[static_cast<std::size_t>(ny[k]) * W + nx[k]]) continue;
          for (int c = 0; c < C && c < 8; ++c) acc[c] += at.image.at(nx[k], ny[k], c);
          ++n;
        }
        if (!n) continue;
        for (int c = 0; c < C && c < 8; ++c) out.at(x, y, c) = acc[c] / n;
        next[static_cast<std::size_t>(y) * W + x] = 1;
      }
    at.image = std::move(out);
    filled = std::move(next);
  }
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (!filled[static_cast<std::size_t>(y) * W + x])
        for (int c = 0; c < C; ++c)
          at.image.at(x, y, c) = nmean ? static_cast<float>(mean[c] / nmean) : 0.f;
  // Per-corner UVs.
  auto uv = get_or_add(mesh, kCornerUV, UV{0.0, 0.0});
  for (int p = 0; p < P; ++p) {
    const FlatPatch& fp = flat.patches[p];
    for (const FlatTriangle& t : fp.triangles) {
      const FaceIndex f(static_cast<Mesh::size_type>(t.face));
      HalfedgeIndex h = mesh.halfedge(f);  // corner k of face_vertices = target of h, next(h), prev(h)
      for (int k = 0; k < 3; ++k, h = mesh.next(h)) {
        const auto px = fp.to_pixel(t.corner[k][0], t.corner[k][1]);
        uv[h] = {(at.offset[p][0] + px[0]) / W, 1.0 - (at.offset[p][1] + px[1]) / H};
      }
    }
  }
  return at;
}

}  // namespace surftex
