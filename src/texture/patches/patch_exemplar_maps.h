// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Other maps of the exemplar (normal, height, roughness, ...) carried
// through one patch synthesis (issue 16 item 2: "one synthesis, every
// channel"): Inside pixels take the map where their colour came from
// (PatchSynthesisResult::sources), Boundary pixels the neighbour's; a
// tangent-space normal map has its (x, y) turned as the texture was, giving
// normals in the patch images' (atlas uv) frame.
//
// Reads the mesh's kFacePatch indirectly through `result.flat`. Throws
// InvalidInputError if the map's size differs from the exemplar the synthesis
// used (`exemplar_size`), the result has no sources, or a tangent normal map
// has fewer than 3 channels.

#include <array>
#include <vector>

#include "geometry/image.h"
#include "texture/efros_leung.h"
#include "texture/patches/patch_synthesis.h"

namespace surftex {

/// Per patch, window-sized (FlatPatch::bw x bh) images of `map` (exemplar 0's map; its channels).
/// `el` = the synthesis's ElOptions (rotations, window, periodic_exemplar).
std::vector<Image> resample_patch_map(const PatchSynthesisResult& result, const Image& map,
                                      std::array<int, 2> exemplar_size, const ElOptions& el,
                                      bool tangent_normal);

}  // namespace surftex
