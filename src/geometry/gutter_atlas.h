// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A multi-chart uv atlas of a triangle mesh ready for baking at a given
// texel size with mip-safe gutters (issue 16 item 3): the charts of
// geometry/base_mesh_atlas.h (segmentation, LSCM, rotation, merged while a
// merge saves atlas area at the full gutter's gap, its step 2b; grown in its
// default 50-degree normal cone and, when those cannot keep the full gutter,
// also in an 85-degree one: the packing with the higher texel density per
// mesh length, divided by the square root of the mean area distortion, is
// kept) repacked in texels: shelf packing of their boxes (tallest first) with 2 g + 3 texels
// between boxes and from the border (g = the gutter of geometry/
// atlas_gutter.h, plus the raster's one-texel band on each side), at the
// largest common scale that fits (bisection). When the full gutter leaves
// less than a quarter of the texel density of a one-texel gutter (very many
// small charts), the largest power-of-two gutter that keeps a quarter is
// used instead and `protected_mip_size` says down to which mip level the
// atlas stays clean. Then every face is rasterised
// in uv space (geometry/uv_raster.h) and the gutters are verified on the
// texels (`violations`, 0 by construction).
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

/// `size` x `size` texels; mips down to `min_mip_size` kept clean.
GutterAtlas compute_gutter_atlas(Mesh& mesh, int size, int min_mip_size = 64);

}  // namespace surftex
