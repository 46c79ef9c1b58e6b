// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Chi-square distance between the per-channel value histograms of two images
// (a colour-statistics quality figure for synthesis: output vs exemplar).
// For each channel, values are binned into `bins` equal bins over [lo, hi]
// (values outside are clamped into the end bins) and normalised to sum 1;
// the per-channel distance is 0.5 * sum_b (p_b - q_b)^2 / (p_b + q_b) (bins
// empty in both skipped), in [0, 1]; the result is the mean over channels.
// The images may differ in size, not in channel count.
// Throws InvalidInputError on empty images, different channel counts,
// bins < 1 or hi <= lo.

#include "geometry/image.h"

namespace surftex {

struct HistogramOptions {
  int bins = 32;     ///< bins per channel, >= 1
  double lo = 0.0;   ///< value range (8-bit images map to [0,1])
  double hi = 1.0;
};

double histogram_chi_square(const Image& a, const Image& b, const HistogramOptions& opt = {});

}  // namespace surftex
