// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Tileable (periodic) texture tiles, the T_0 / T_M of Ray, Nivoliers, Lefebvre,
// Levy 2009 "Material-space texturing", section 1: "tileable versions of them
// T_0 and T_M ... can be done by using the graph-cut algorithm [KdE*03]".
// Graph-cut synthesis (texture/graphcut_synthesis.h) on the torus: every
// index is taken modulo the tile size, patches wrap across the edges, and the
// seams across the wrap are cut like any other seam, so the tile repeats
// without a visible border left-right and top-bottom (check with
// texture/wrap_seam_ratio.h).

#include <cstdint>

#include "geometry/image.h"
#include "geometry/progress.h"
#include "texture/graphcut_synthesis.h"

namespace surftex {

struct TileOptions {
  /// Patch side in pixels, 0 = automatic: min(7 size / 8, 3/4 of the shorter
  /// exemplar side), at least 4 (3/4: several offsets remain to choose from,
  /// as in graph-cut synthesis). Large patches: a periodic tile holds few of them, so each
  /// exemplar structure (wood grain, a check pattern's period) is copied over
  /// long stretches and the few seams can be placed where they cost least
  /// (measured at size 128: wood_512 seam cost 50 -> 24 and wrap-seam ratio
  /// 1.34 -> 0.63 against the earlier min(64, size/2)). No floor on the
  /// band left outside a patch was added: the 32-px key tiles of
  /// material_tile (32-px resampled exemplars) already get 24 px (3/4 of the
  /// exemplar, overlap 8), and the 1.64 wrap ratio of the mud key there is a
  /// crack of the exemplar along the wrap column, which holds no seam
  /// (texture/wrap_seam_ratio.h). 24 vs 28 px for 32-px tiles of full-size
  /// exemplars is not measured on all textures yet. Range 0 or >= 4
  /// (clipped to size - 1).
  int patch_size = 0;
  /// Overlap of the fill patches, 0 = automatic (patch/3). Range >= 0, < patch.
  int overlap = 0;
  /// Seam-repair passes after the tile is filled. Range >= 0.
  int refinement_passes = 4;
  /// Placement temperature (GraphcutOptions::k). Range > 0.
  double k = 0.002;
  PlacementMode placement = PlacementMode::SubPatch;
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

struct TileResult {
  Image tile;                  ///< size x size, exemplar channels, periodic
  double wrap_seam_ratio = 0;  ///< texture/wrap_seam_ratio.h of `tile`
  double seam_cost = 0;        ///< final total seam cost (graph-cut units)
};

/// A size x size periodic tile grown from `exemplar`. Throws InvalidInputError
/// naming the option for size < 8, an empty exemplar or an invalid option.
TileResult make_tileable_detailed(const Image& exemplar, int size, const TileOptions& options = {});

/// make_tileable_detailed(...).tile.
Image make_tileable(const Image& exemplar, int size, const TileOptions& options = {});

}  // namespace surftex
