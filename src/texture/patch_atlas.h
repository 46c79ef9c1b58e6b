// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Texture atlas of patch images and per-corner UVs into it (Gorla et al. 2003,
// 3.2 / 4.1: the paper stores one texture per patch and names an atlas "as in
// lapped textures" as the alternative; we pack one atlas so that the result
// opens as a standard textured OBJ/glTF).
//
// Every patch image (all res x res, flatten_patch.h) goes into a grid cell
// of res + 2 g texels, cols = ceil(sqrt(P)) cells per row, g = the mip gutter
// of geometry/atlas_gutter.h for the atlas side (2^K texels for the K
// halvings down to `min_mip_size`). The atlas is square, by default the
// smallest power of two that holds the grid with that gutter; when even
// `max_size` cannot (the gutter grows with the side: at most ~32 cells per
// row), it is `max_size` with the largest power-of-two gutter that fits
// (`gutter` and `protected_mip_size` say which levels stay clean).
// Inside and Boundary pixels (Boundary pixels hold the neighbour's texture,
// patch_synthesis.h step 7) are the charts; every other texel is filled by
// dilating them (geometry/atlas_gutter.h: each patch's gutter from its own
// colours, no background). UV of a corner: its flat (u, v) -> patch pixel ->
// atlas pixel -> (x / W, 1 - y / H) (v up, as write_mesh and the rasterizer
// expect).
//
// Writes kCornerUV (h:uv) for every face corner. Throws InvalidInputError if
// images and patches disagree in number or size, or options are out of range.

#include <array>
#include <vector>

#include "geometry/flatten_patch.h"
#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

struct PatchAtlasOptions {
  int min_mip_size = 64;     ///< smallest mip level kept free of bleeding, >= 1 (default 64)
  bool power_of_two = true;  ///< square power-of-two side (default); false = just the grid
  int max_size = 4096;       ///< largest side, 64..16384 (default 4096: 192 MiB of float RGB)
};

struct PatchAtlas {
  Image image;
  int cols = 0, rows = 0, cell = 0;
  int gutter = 0;              ///< texels of gutter around every cell's raster
  int protected_mip_size = 0;  ///< smallest mip side whose texels stay inside one patch's gutter
  std::vector<std::array<int, 2>> offset;  ///< per patch: top-left pixel of its raster
  std::vector<int> chart;      ///< per texel: patch of an Inside/Boundary pixel, -1 = other
  std::vector<int> owner;      ///< per texel after dilation
};

PatchAtlas pack_patch_atlas(Mesh& mesh, const FlattenResult& flat, const std::vector<Image>& images,
                            const PatchAtlasOptions& options = {});

}  // namespace surftex
