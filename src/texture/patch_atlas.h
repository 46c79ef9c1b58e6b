// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Texture atlas of patch images and per-corner UVs into it (Gorla et al. 2003,
// 3.2 / 4.1: the paper stores one texture per patch and names an atlas "as in
// lapped textures" as the alternative; we pack one atlas so that the result
// opens as a standard textured OBJ/glTF).
//
// Every patch image (all res x res, flatten_patch.h) goes into a grid cell of
// (res + gutter) pixels; the atlas is cols x rows cells, cols = ceil(sqrt(P)).
// Pixels that are neither Inside nor Boundary (Boundary pixels hold the
// neighbour's texture, patch_synthesis.h step 7) and the gutter are filled by
// dilation (each pass gives an empty pixel the mean of its filled
// 4-neighbours; gutter + 8 passes, the rest gets the mean colour),
// so bilinear lookups near patch edges do not bleed in unrelated texels.
// UV of a corner: its flat (u, v) -> patch pixel -> atlas pixel -> (x / W,
// 1 - y / H) (v up, as write_mesh and the rasterizer expect).
//
// Writes kCornerUV (h:uv) for every face corner. Throws InvalidInputError if
// images and patches disagree in number or size.

#include <array>
#include <vector>

#include "geometry/flatten_patch.h"
#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

struct PatchAtlasOptions {
  int gutter = 4;  ///< pixels between cells, 0..64
};

struct PatchAtlas {
  Image image;
  int cols = 0, rows = 0, cell = 0;
  std::vector<std::array<int, 2>> offset;  ///< per patch: top-left pixel of its cell
};

PatchAtlas pack_patch_atlas(Mesh& mesh, const FlattenResult& flat, const std::vector<Image>& images,
                            const PatchAtlasOptions& options = {});

}  // namespace surftex
