// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Textures the project generates itself (for the demo, tests and data/): every
// pattern is periodic over the image (it tiles), RGB in [0,1], and a pure
// function of its parameters and seed.

#include <cstdint>

#include "geometry/image.h"

namespace surftex {

/// Sinusoidal stripes with the given period (pixels) whose crests run along
/// `angle_deg` (0 = horizontal stripes' normal along y ... i.e. the stripes are
/// lines at angle_deg from the x axis, counter-clockwise with y up). To stay
/// periodic the stripe frequency is rounded to an integer number of waves per
/// image along x and y.
Image make_stripes(int size, double period, double angle_deg);

/// Checkerboard with `cells` x `cells` squares.
Image make_checker(int size, int cells);

/// Stochastic texture: periodic value-noise fBm (octaves from `base_cells`
/// cells upward), tinted between two colours.
Image make_noise(int size, int base_cells, std::uint64_t seed);

/// Structured texture: periodic Worley cells (pebbles) with dark mortar, each
/// cell with its own shade. `cells` feature points per side on average.
Image make_cells(int size, int cells, std::uint64_t seed);

}  // namespace surftex
