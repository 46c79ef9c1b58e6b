// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Gaussian pyramid and Gaussian stack of an image.
//
// - gaussian_pyramid: Burt-Adelson style. Level 0 is the input; level l+1 is
//   level l blurred with the separable 5-tap binomial filter [1 4 6 4 1]/16
//   (variance 1 pixel^2) and subsampled by 2 (even pixels kept), so its size is
//   ceil(w/2) x ceil(h/2). Borders clamp, or wrap with `toroidal`.
// - gaussian_stack (Lefebvre & Hoppe 2005, "Parallel controllable texture
//   synthesis", section 3.1): every level has the input's size; level l+1 is
//   level l blurred with the same binomial filter dilated by 2^l ("a trous":
//   taps at -2s, -s, 0, s, 2s with s = 2^l), so the blur radius doubles per
//   level and level l carries a total Gaussian-like blur of variance
//   (4^l - 1) / 3 pixel^2. Boundaries are toroidal by default, as the stack
//   serves periodic exemplars.
// Both throw InvalidInputError on an empty image or a negative level count.

#include <vector>

#include "geometry/image.h"

namespace surftex {

/// The 5-tap binomial blur, taps `step` pixels apart (step >= 1), separable,
/// applied to every channel. Borders clamp, or wrap when `toroidal`.
Image binomial_blur(const Image& img, int step = 1, bool toroidal = false);

struct PyramidOptions {
  /// Number of levels including the input; 0 = until the coarsest level is
  /// 1 pixel on its shorter side (1 + floor(log2(min(w, h)))).
  int levels = 0;
  /// Wrap around the borders when blurring (periodic images). Default off.
  bool toroidal = false;
};

/// Levels from fine (index 0, the input) to coarse.
std::vector<Image> gaussian_pyramid(const Image& img, const PyramidOptions& opt = {});

struct StackOptions {
  /// Number of levels including the input; 0 = 1 + floor(log2(min(w, h))).
  int levels = 0;
  /// Wrap around the borders (default on: Lefebvre-Hoppe stacks are toroidal).
  bool toroidal = true;
};

/// Levels from fine (index 0, the input) to coarse, all of the input's size.
std::vector<Image> gaussian_stack(const Image& img, const StackOptions& opt = {});

}  // namespace surftex
