// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Exact Euclidean signed distance field of a binary mask on the torus, the
// phi_0 / phi_M of Ray et al. 2009, section 1 (pipeline step 1; the paper uses
// Yamashita et al.'s algorithm, we use the Felzenszwalb-Huttenlocher lower
// envelope of parabolas, which is also exact).
//
// Toroidal: the image is a tile, distances are measured on the torus
// (dx, dy taken modulo width / height). Each 1D pass runs the lower envelope
// over three periods of the line (copies at -n, 0, +n) and reads the middle
// period: on a cycle the nearest site is at most n/2 away, so it is always among
// the three copies and the result is exact.

#include "geometry/image.h"

namespace surftex {

/// Squared toroidal Euclidean distance (pixels^2) from every pixel to the
/// nearest pixel with `sites(x,y) > 0.5`; +infinity everywhere if there is none.
/// Returns a 1-channel image. Throws InvalidInputError on an empty image.
Image squared_distance_transform_torus(const Image& sites);

/// Signed distance in pixels between pixel centres: at a feature pixel
/// (mask > 0.5) +distance to the nearest background pixel, at a background
/// pixel -distance to the nearest feature pixel; so |phi| >= 1 everywhere and
/// the zero level lies between the two classes. A mask with no feature pixel
/// gives -(width + height) everywhere, one with only feature pixels
/// +(width + height) (more than any toroidal distance). 1 channel.
/// Throws InvalidInputError on an empty mask.
Image signed_distance_field(const Image& mask);

}  // namespace surftex
