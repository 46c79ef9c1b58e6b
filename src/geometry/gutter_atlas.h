// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A multi-chart uv atlas for baking at a texel size with mip-safe gutters
// (issue 16 item 3): base_mesh_atlas.h's charts (50-degree cone, or 85 when
// that packs denser per distortion) shelf-packed in texels 2 g + 3 apart at
// the largest common scale (bisection); when the full gutter costs more than
// 3/4 of the density, the largest power-of-two gutter keeping a quarter
// (`protected_mip_size`). Faces rasterised in uv (uv_raster.h) and gutters
// verified (`violations`, 0 by construction). In full: decision 302.
//
// Writes kCornerUV and kFacePatch. Throws what compute_base_mesh_atlas and
// rasterize_uv_triangles throw, and InvalidInputError when the charts cannot
// fit with their gutters.

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
  int gutter = 0;           ///< texels (atlas_gutter_texels, or less, see above)
  int protected_mip_size = 0;  ///< smallest mip side kept free of bleeding (size / gutter)
  double margin = 0;        ///< chart spacing (2 g + 3 texels) as a fraction of the side
  std::size_t violations = 0;  ///< gutter_violations of the final atlas (0 wanted)
  double seconds = 0;
};

/// `size` x `size` texels; mips down to `min_mip_size` kept clean; charts of
/// at most `max_chart_faces` faces (BaseMeshAtlasOptions, >= 1).
GutterAtlas compute_gutter_atlas(Mesh& mesh, int size, int min_mip_size = 64, std::size_t max_chart_faces = 4000);

}  // namespace surftex
