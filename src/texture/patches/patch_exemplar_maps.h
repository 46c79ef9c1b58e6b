// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Other maps of the exemplar (normal, height, roughness, ...) carried
// through one patch synthesis (issue 16 item 2: "one synthesis, every
// channel"): every Inside pixel of every patch image takes the map's value
// where its colour came from (PatchSynthesisResult::sources: pixel of the
// exemplar rotated as the colour was, rotate_exemplar's bilinear resampling
// in float), and every Boundary pixel the neighbour patch's value, as step 7
// of patch_synthesis.h does for the colour. A tangent-space normal map
// (`tangent_normal`: channels 0-2 = (n + 1) / 2, +Y up) has its (x, y)
// turned by the same orientation as the texture (rotated_exemplars.h: angle
// a turns the exemplar counter-clockwise as displayed), so the result is a
// tangent-space normal map in the patch images' frame (x right, y up: the
// atlas uv frame of patch_atlas.h).
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

/// Per patch, res x res images of `map` (exemplar 0's map; its channels).
/// `el` = the synthesis's ElOptions (rotations, window, periodic_exemplar).
std::vector<Image> resample_patch_map(const PatchSynthesisResult& result, const Image& map,
                                      std::array<int, 2> exemplar_size, const ElOptions& el,
                                      bool tangent_normal);

}  // namespace surftex
