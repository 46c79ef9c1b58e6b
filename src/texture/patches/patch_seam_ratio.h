// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Seam visibility of a patch-textured mesh, measured on the surface
// (issue 6 figure for Gorla et al. 2003: "seams due to discontinuities
// between texture element features in adjacent patches", 3.3).
//
// Seeded pairs of surface points `step_texels` apart, located in the patch
// flattenings; "across" when their faces lie in different patches. Colours
// through the atlas at each face's corner UVs; ratio = mean |c1 - c2| across
// over within (about 1 when seams are invisible).
//
// Reads kCornerUV. Throws InvalidInputError (no kCornerUV, empty atlas, bad
// options).

#include <cstddef>
#include <cstdint>

#include "texture/patches/flatten_patch.h"
#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

struct SeamRatioOptions {
  double step_texels = 2.0;  ///< pair distance, texels, > 0
  int samples = 40000;       ///< pairs drawn, >= 1
  std::uint64_t seed = 1;
};

struct SeamRatioResult {
  double ratio = 0;          ///< mean_across / mean_within (0 if either is empty)
  double mean_across = 0, mean_within = 0;
  std::size_t pairs_across = 0, pairs_within = 0;
};

SeamRatioResult patch_seam_ratio(const Mesh& mesh, const FlattenResult& flat, const Image& atlas,
                                 const SeamRatioOptions& options = {});

}  // namespace surftex
