// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Gutters of a texture atlas for mip-mapped lookups (issue 16 item 3): every
// chart keeps 2^K texels of its own colours, K the halvings from the atlas
// side to `min_mip_size`, and charts stay twice that apart (decision 302).
// dilate_charts fills every empty texel ring by ring (Chebyshev), each taking
// the majority label of its inner 8-neighbours (ties: lower) and their mean,
// so charts 2g+1 apart own every texel within g. No CGAL here.

#include <vector>

#include "geometry/image.h"

namespace surftex {

/// 2^K for K = floor(log2(size / min_mip_size)) halvings (1 when size <=
/// min_mip_size). Throws InvalidInputError for size or min_mip_size < 1.
int atlas_gutter_texels(int size, int min_mip_size = 64);

/// Smallest power of two >= n (n >= 1), at most 16384; throws InvalidInputError above.
int next_power_of_two(int n);

/// Fills the texels whose label is < 0 (labels: one per texel, row-major;
/// label >= 0 = chart id) and relabels them with the chart they now belong
/// to. Returns the number of rings. Throws InvalidInputError if the sizes
/// disagree or no texel is labelled.
int dilate_charts(Image& image, std::vector<int>& label);

/// Texels within Chebyshev distance `gutter` of a chart texel (chart_label >=
/// 0) whose final label (after dilate_charts) is another chart or none: 0 for
/// an atlas whose every chart owns its gutter.
std::size_t gutter_violations(const std::vector<int>& chart_label, const std::vector<int>& final_label, int width,
                              int height, int gutter);

}  // namespace surftex
