// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The PBR texture set of an atlas (issue 16 item 2): height and tangent-space
// normal maps beside the base colour, the same for every image-texture method.
//
// Height: the base colour's luminance (Rec. 709) or a resampled exemplar
// height. Normal: n = normalize(-k dh/du, -k dh/dv, 1) from central
// differences within a chart, in the atlas uv frame (+Y up, glTF), stored
// (n + 1) / 2; the GLB carries a matching TANGENT. No CGAL here.

#include <vector>

#include "geometry/image.h"

namespace surftex {

/// Luminance of the first three channels (grey: the channel), one channel.
Image height_from_luminance(const Image& color);

/// Tangent-space normal map (3 channels, encoded (n+1)/2) of `height` (one
/// channel, [0,1]); `owner` = chart per texel before the gutter dilation
/// (empty = one chart): texels of label < 0 (gutters) are filled by dilating
/// the charts' normals (geometry/atlas_gutter.h), not from the gutter's height;
/// `strength_per_texel` = tilt per unit of height per atlas texel, >= 0.
/// Throws InvalidInputError on a bad size or strength.
Image normal_map_from_height(const Image& height, const std::vector<int>& owner, double strength_per_texel);

/// A glTF metallicRoughness image (R unused = 1, G = roughness, B = metallic = 0) from a one-channel roughness map.
Image metallic_roughness_from_roughness(const Image& roughness);

}  // namespace surftex
