// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A multi-chart uv atlas of a triangle mesh ready for baking at a given
// texel size with mip-safe gutters (issue 16 item 3): the charts of
// geometry/base_mesh_atlas.h packed with a spacing of more than twice the
// gutter of geometry/atlas_gutter.h, every face rasterised in uv space
// (geometry/uv_raster.h, one texel band), and the spacing verified on the
// texels: if a chart's gutter would reach another chart's texels, the atlas
// is rebuilt with 1.5x the spacing (at most 3 times; the spacing is capped at
// the atlas's limit of 0.099 of the side, reported by `violations`).
//
// Writes kCornerUV and kFacePatch. Throws what compute_base_mesh_atlas and
// rasterize_uv_triangles throw.

#include <vector>

#include "geometry/base_mesh_atlas.h"
#include "geometry/mesh_fwd.h"
#include "geometry/uv_raster.h"

namespace surftex {

struct GutterAtlas {
  BaseMeshAtlasResult atlas;
  UvRaster raster;          ///< triangle = face index (faces in index order)
  std::vector<int> chart;   ///< per texel: chart id, -1 = empty
  std::vector<int> owner;   ///< per texel: chart after dilation (every texel >= 0)
  int gutter = 0;           ///< texels (atlas_gutter_texels)
  double margin = 0;        ///< chart spacing used, fraction of the side
  std::size_t violations = 0;  ///< gutter_violations of the final atlas (0 wanted)
  double seconds = 0;
};

/// `size` x `size` texels; mips down to `min_mip_size` kept clean.
GutterAtlas compute_gutter_atlas(Mesh& mesh, int size, int min_mip_size = 64);

}  // namespace surftex
