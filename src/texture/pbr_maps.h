// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The PBR texture set of an atlas (issue 16 item 2): height and tangent-space
// normal maps beside the base colour, the same for every image-texture method.
//
// Height: the luminance of the base colour (Rec. 709 weights), or an exemplar
// height map resampled where the colour came from (the caller's synthesis
// coordinates). Normal: from the height's slopes in the atlas, by central
// differences between texels of the same chart (one-sided at a chart's
// edge, flat where a texel has no same-chart neighbour on either side):
//   n = normalize(-k dh/du, -k dh/dv, 1),  k = strength_per_texel,
// in the tangent frame of the atlas uv (x along +u, y along +v: "+Y up", the
// OpenGL / glTF convention), stored as (n + 1) / 2. The GLB carries a
// TANGENT attribute in that frame (geometry/vertex_tangents.h), so viewers do
// not have to generate one (the glTF validator warns when they must).
// No CGAL here.

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
