// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch image atlas with mip gutters (Gorla et al. 2003, 3.2 / 4.1; see patch_atlas.h).
#include "texture/patches/patch_atlas.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "geometry/atlas_gutter.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

namespace {

// Bounding box of a patch's Inside and Boundary pixels (its chart), inclusive.
struct Box {
  int x0, y0, x1, y1;
  int w() const { return x1 - x0 + 1; }
  int h() const { return y1 - y0 + 1; }
};

// The patch's stored window (an empty raster's is one texel).
Box chart_box(const FlatPatch& fp) { return {fp.bx, fp.by, fp.bx + fp.bw - 1, fp.by + fp.bh - 1}; }

// Shelf packing (tallest first) of the boxes into a `side` square, `gap`
// texels between boxes and g = gap / 2 from the border; top-left corner of
// each box, false if they do not fit.
bool shelf_pack(const std::vector<Box>& box, const std::vector<int>& order, int side, int g,
                std::vector<std::array<int, 2>>& at) {
  const int gap = 2 * g + 1;
  int x = g, y = g, shelf = 0;
  for (int p : order) {
    if (x + box[p].w() + g > side && x > g) y += shelf + gap, x = g, shelf = 0;
    if (x + box[p].w() + g > side || y + box[p].h() + g > side) return false;
    at[p] = {x, y};
    x += box[p].w() + gap;
    shelf = std::max(shelf, box[p].h());
  }
  return true;
}

// The smallest side (a power of two unless !power_of_two) whose gutter lets
// the boxes fit; at max_size the largest power-of-two gutter that fits; 0
// when nothing fits.
int try_atlas_layout(const std::vector<Box>& box, const std::vector<int>& order, const PatchAtlasOptions& opt,
                     int& gutter, std::vector<std::array<int, 2>>& at) {
  for (int s = 64; s <= opt.max_size; s = opt.power_of_two ? 2 * s : s + std::max(1, s / 16)) {
    gutter = atlas_gutter_texels(s, opt.min_mip_size);
    if (shelf_pack(box, order, s, gutter, at)) return s;
  }
  const int s = opt.power_of_two ? [&] {
    int p = 64;
    while (2 * p <= opt.max_size) p *= 2;
    return p;
  }() : opt.max_size;
  for (gutter = atlas_gutter_texels(s, opt.min_mip_size); gutter >= 1; gutter /= 2)
    if (shelf_pack(box, order, s, gutter, at)) return s;
  return 0;
}

int atlas_layout(const std::vector<Box>& box, const std::vector<int>& order, const PatchAtlasOptions& opt,
                 int& gutter, std::vector<std::array<int, 2>>& at) {
  const int s = try_atlas_layout(box, order, opt, gutter, at);
  if (s == 0)
    throw InvalidInputError("pack_patch_atlas: " + std::to_string(box.size()) + " patches do not fit in max_size " +
                            std::to_string(opt.max_size) + " (fewer, larger patches or a smaller patch resolution)");
  return s;
}

// The chart boxes, tallest first (the packing order).
std::vector<int> packing_order(const FlattenResult& flat, std::vector<Box>& box) {
  const int P = static_cast<int>(flat.patches.size());
  box.resize(static_cast<std::size_t>(P));
  for (int p = 0; p < P; ++p) box[p] = chart_box(flat.patches[p]);
  std::vector<int> order(P);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return box[a].h() > box[b].h(); });
  return order;
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
  const int C = images[0].channels;
  for (int p = 0; p < P; ++p) {
    const FlatPatch& fp = flat.patches[p];
    if (images[p].width != fp.bw || images[p].height != fp.bh || images[p].channels != C)
      throw InvalidInputError("pack_patch_atlas: patch " + std::to_string(p) + " image is " +
                              std::to_string(images[p].width) + " x " + std::to_string(images[p].height) +
                              ", its raster window " + std::to_string(fp.bw) + " x " + std::to_string(fp.bh));
  }
  std::vector<Box> box;
  const std::vector<int> order = packing_order(flat, box);
  std::vector<std::array<int, 2>> corner(P);
  PatchAtlas at;
  const int W = atlas_layout(box, order, opt, at.gutter, corner), H = W;
  at.protected_mip_size = W / at.gutter;
  at.image = Image(W, H, C, 0.f);
  at.chart.assign(static_cast<std::size_t>(W) * H, -1);
  at.offset.resize(P);
  for (int p = 0; p < P; ++p) {
    const int ox = corner[p][0] - box[p].x0, oy = corner[p][1] - box[p].y0;
    at.offset[p] = {ox, oy};
    const FlatPatch& fp = flat.patches[p];
    for (int y = box[p].y0; y <= box[p].y1; ++y)
      for (int x = box[p].x0; x <= box[p].x1; ++x) {
        const std::size_t i = fp.index(x, y);
        const PatchPixel state = fp.pixel[i];
        if (state == PatchPixel::Outside) continue;
        // A Boundary pixel whose neighbour lookup found no Inside texel stays
        // all zero in the patch image: the dilation fills it instead.
        const float* v = images[p].data.data() + i * C;
        bool zero = true;
        for (int c = 0; c < C && zero; ++c) zero = v[c] == 0.f;
        if (state == PatchPixel::Boundary && zero) continue;
        for (int c = 0; c < C; ++c) at.image.at(ox + x, oy + y, c) = v[c];
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

bool patch_rasters_fit(const FlattenResult& flat, const PatchAtlasOptions& opt) {
  if (flat.patches.empty()) return true;
  std::vector<Box> box;
  const std::vector<int> order = packing_order(flat, box);
  std::vector<std::array<int, 2>> at(box.size());
  int gutter = 0;
  return try_atlas_layout(box, order, opt, gutter, at) > 0;
}

}  // namespace surftex
