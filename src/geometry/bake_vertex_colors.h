// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Bakes per-vertex colours into a texture atlas image, so a vertex-coloured
// result also exists as an image (Bangay & Morkel 2006, section 3.5: "the
// surface colouring can be converted into a conventional texture map").
// Triangles rasterised in uv (uv_raster.h), each texel the barycentric blend,
// empty texels filled by dilating the charts (atlas_gutter.h; kFacePatch, else
// one chart). bake_vertex_values: the same for any per-vertex values;
// rasterize_atlas: the texels with their triangle and barycentrics.
//
// Reads kCornerUV, kVertexColor, kFacePatch (optional). Throws
// InvalidInputError (non-triangle face, missing map, size outside 1..16384).

#include <array>
#include <functional>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "geometry/uv_raster.h"

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

/// `values`: `channels` floats per vertex, indexed by vertex index; the
/// image has `channels` channels. Throws InvalidInputError on a size mismatch.
BakeResult bake_vertex_values(const Mesh& mesh, const std::vector<float>& values, int channels,
                              const BakeOptions& opt = {});

/// Any values per texel: `value(corner, bary, out)` writes `channels` floats
/// for a covered texel of the triangle whose corners (halfedge indices,
/// target = vertex) and barycentrics are given; rows run in parallel, so it
/// must be safe to call from several threads. Throws InvalidInputError for
/// channels outside 1..4.
using TexelValueFn =
    std::function<void(const std::array<std::size_t, 3>& corner, const std::array<float, 3>& bary, float* out)>;
BakeResult bake_texel_values(const Mesh& mesh, int channels, const TexelValueFn& value, const BakeOptions& opt = {});

/// The texels every face covers (faces in index order = raster triangles).
struct AtlasTexels {
  UvRaster raster;
  std::vector<std::array<std::size_t, 3>> corner;  ///< per triangle: the halfedge index of each corner (target = vertex)
  std::vector<int> chart;                          ///< per texel: chart (kFacePatch, else 0), -1 = none
  std::size_t covered = 0;
};
AtlasTexels rasterize_atlas(const Mesh& mesh, int size);

}  // namespace surftex
