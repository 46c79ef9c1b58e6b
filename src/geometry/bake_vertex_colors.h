// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Bakes per-vertex colours into a texture atlas image, so a vertex-coloured
// result also exists as an image (Bangay & Morkel 2006, section 3.5: "the
// surface colouring can be converted into a conventional texture map").
// Every triangle is rasterised in uv space (kCornerUV, v up; geometry/
// uv_raster.h: texel centres inside, plus a one-texel band at the nearest
// point), each texel the barycentric blend of the three vertex colours; then
// every empty texel is filled by dilating the charts (geometry/atlas_gutter.h:
// no background, each chart's gutter from its own colours). Charts are
// kFacePatch when present (geometry/gutter_atlas.h spaces them for mip
// gutters), else one chart.
//
// Reads kCornerUV, kVertexColor, kFacePatch (optional). Throws
// InvalidInputError (non-triangle face, missing map, size outside 1..16384).

#include <array>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

struct BakeOptions {
  int size = 1024;  ///< atlas width = height, pixels
};

struct BakeResult {
  Image image;                 ///< size x size x 3
  std::size_t covered = 0;     ///< pixels covered by a triangle (or its one-texel band)
  std::vector<int> chart;      ///< per texel before dilation (-1 = empty)
  std::vector<int> owner;      ///< per texel after dilation
};

BakeResult bake_vertex_colors(const Mesh& mesh, const BakeOptions& opt = {});

}  // namespace surftex
