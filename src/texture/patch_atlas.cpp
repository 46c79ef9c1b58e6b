// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch image atlas with mip gutters (Gorla et al. 2003, 3.2 / 4.1; see patch_atlas.h).
#include "texture/patch_atlas.h"

#include <cmath>
#include <string>

#include "geometry/atlas_gutter.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

namespace {

struct Layout {
  int side = 0, gutter = 0;
};

// The square side and gutter for `cols` cells of `res` texels per row.
Layout atlas_layout(int cols, int res, const PatchAtlasOptions& opt) {
  if (opt.power_of_two) {
    for (int s = 64; s <= opt.max_size; s *= 2) {
      const int g = atlas_gutter_texels(s, opt.min_mip_size);
      if (static_cast<long>(cols) * (res + 2 * g) <= s) return {s, g};
    }
  } else {
    int g = 1;
    for (int it = 0; it < 16; ++it) {
      const long s = static_cast<long>(cols) * (res + 2 * g);
      if (s > opt.max_size) break;
      const int g2 = atlas_gutter_texels(static_cast<int>(s), opt.min_mip_size);
      if (g2 == g) return {static_cast<int>(s), g};
      g = g2;
    }
  }
  // The largest side with the largest power-of-two gutter that fits.
  int s = opt.power_of_two ? 64 : opt.max_size;
  while (opt.power_of_two && s * 2 <= opt.max_size) s *= 2;
  for (int g = atlas_gutter_texels(s, opt.min_mip_size); g >= 1; g /= 2)
    if (static_cast<long>(cols) * (res + 2 * g) <= s) return {s, g};
  throw InvalidInputError("pack_patch_atlas: " + std::to_string(cols) + " cells of " + std::to_string(res) +
                          " texels per row do not fit in max_size " + std::to_string(opt.max_size) +
                          " (fewer, larger patches or a smaller patch resolution)");
}

}  // namespace

PatchAtlas pack_patch_atlas(Mesh& mesh, const FlattenResult& flat, const std::vector<Image>& images,
                            const PatchAtlasOptions& opt) {
  const int P = static_cast<int>(flat.patches.size());
  if (opt.min_mip_size < 1 || opt.max_size < 64 || opt.max_size > 16384)
    throw InvalidInputError("pack_patch_atlas: min_mip_size " + std::to_string(opt.min_mip_size) + " (>= 1) or max_size " +
                            std::to_string(opt.max_size) + " (64..16384) out of range");
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
  const Layout lay = atlas_layout(at.cols, R, opt);
  at.gutter = lay.gutter;
  at.cell = R + 2 * lay.gutter;
  const int W = lay.side, H = lay.side;
  at.protected_mip_size = W / lay.gutter;
  at.image = Image(W, H, C, 0.f);
  at.chart.assign(static_cast<std::size_t>(W) * H, -1);
  at.offset.resize(P);
  for (int p = 0; p < P; ++p) {
    const int ox = lay.gutter + (p % at.cols) * at.cell, oy = lay.gutter + (p / at.cols) * at.cell;
    at.offset[p] = {ox, oy};
    const FlatPatch& fp = flat.patches[p];
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < R; ++x) {
        if (fp.pixel[static_cast<std::size_t>(y) * R + x] == PatchPixel::Outside) continue;
        for (int c = 0; c < C; ++c) at.image.at(ox + x, oy + y, c) = images[p].at(x, y, c);
        at.chart[static_cast<std::size_t>(oy + y) * W + ox + x] = p;
      }
  }
  at.owner = at.chart;
  dilate_charts(at.image, at.owner);
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
