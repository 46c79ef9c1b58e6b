// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Texture atlas of patch images and per-corner UVs into it (Gorla et al. 2003,
// 3.2 / 4.1: the paper stores one texture per patch and names an atlas "as in
// lapped textures" as the alternative; we pack one atlas so that the result
// opens as a standard textured OBJ/glTF).
//
// Each patch's chart (the box of its Inside and Boundary pixels) is
// shelf-packed, tallest first, 2 g + 1 texels apart (g: atlas_gutter.h's mip
// gutter); the atlas is the smallest fitting power of two, else `max_size`
// with the largest gutter that fits (`gutter`, `protected_mip_size`). One
// atlas texel per patch texel; the rest filled by dilation; corner UVs
// (x / W, 1 - y / H), v up. In full: docs/decisions/302-atlas-gutters.md.
//
// Writes kCornerUV (h:uv) for every face corner. Throws InvalidInputError if
// images and patches disagree in number or size, or options are out of range.

#include <array>
#include <vector>

#include "texture/patches/flatten_patch.h"
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
  int gutter = 0;              ///< texels of gutter around every chart
  int protected_mip_size = 0;  ///< smallest mip side whose texels stay inside one patch's gutter
  std::vector<std::array<int, 2>> offset;  ///< per patch: atlas pixel of its raster's pixel (0, 0)
  std::vector<int> chart;      ///< per texel: patch of an Inside/Boundary pixel, -1 = other
  std::vector<int> owner;      ///< per texel after dilation
};

PatchAtlas pack_patch_atlas(Mesh& mesh, const FlattenResult& flat, const std::vector<Image>& images,
                            const PatchAtlasOptions& options = {});

/// Whether pack_patch_atlas would fit the rasters of `flat` (it throws when
/// not); cheap: the chart boxes and the packing only, no image.
bool patch_rasters_fit(const FlattenResult& flat, const PatchAtlasOptions& options = {});

}  // namespace surftex
