// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Masked sum of squared differences of a template against every translation
// of a larger image, computed with FFT correlations (Kwatra et al. 2003,
// "Graphcut Textures", section 4.1 "Accelerated patch search"):
//
//   SSD(u) = sum_i mt(i) mb(u+i) |B(u+i) - T(i)|^2
//          = corr(mb*|B|^2, mt) - 2 sum_c corr(mb*B_c, mt*T_c) + corr(mb, mt*|T|^2)
//
// where corr(f, g)(u) = sum_i f(u+i) g(i) is one product in frequency space.
// MaskedSsdMatcher keeps the big image's spectra: a query costs (channels + 2)
// forward and one or two inverse FFTs (entire- and sub-patch matching).
//
// Masks are per-pixel weights (normally 0/1); an empty mask means all ones.
// Units: whatever the images hold (floats), squared and summed over channels.
// Throws InvalidInputError on mismatched sizes or channel counts.

#include <vector>

#include "geometry/image.h"

namespace surftex {

/// SSD and overlap weight for every admissible translation u = (ux, uy) of
/// the template's top-left corner in the big image.
/// Non-periodic: ux in [0, big.width - tmpl.width], uy likewise.
/// Periodic (wrap): ux in [0, big.width), uy in [0, big.height), indices mod size.
struct SsdMap {
  int nx = 0, ny = 0;
  std::vector<double> ssd;      // nx * ny, row-major (uy * nx + ux); >= 0
  std::vector<double> overlap;  // sum_i mt(i) mb(u+i), same layout
  double ssd_at(int ux, int uy) const { return ssd[static_cast<std::size_t>(uy) * nx + ux]; }
  double overlap_at(int ux, int uy) const {
    return overlap[static_cast<std::size_t>(uy) * nx + ux];
  }
};

class MaskedSsdMatcher {
 public:
  /// `big` is the searched image, `big_mask` its weights (width*height, or
  /// empty = all ones), `wrap` makes translations periodic (torus).
  MaskedSsdMatcher(const Image& big, std::vector<float> big_mask, bool wrap);
  ~MaskedSsdMatcher();
  MaskedSsdMatcher(const MaskedSsdMatcher&) = delete;
  MaskedSsdMatcher& operator=(const MaskedSsdMatcher&) = delete;

  /// SSD of `tmpl` (weights `tmpl_mask`, width*height or empty) at every
  /// translation. The template must have the big image's channel count and
  /// fit inside it (tmpl.width <= big.width, same for height).
  SsdMap match(const Image& tmpl, const std::vector<float>& tmpl_mask) const;

 private:
  struct Impl;
  Impl* impl_;
};

/// Direct O(N * M) evaluation of the same quantity (reference for tests).
SsdMap masked_ssd_brute_force(const Image& big, const std::vector<float>& big_mask,
                              const Image& tmpl, const std::vector<float>& tmpl_mask, bool wrap);

}  // namespace surftex
