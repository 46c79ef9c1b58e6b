// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Gutters of a texture atlas for mip-mapped lookups (issue 16 item 3): a
// viewer samples level k of the mip chain, whose texel averages 2^k x 2^k
// base texels; a chart whose neighbourhood holds other charts' texels or an
// empty background bleeds them into its seams at that level. So every chart
// keeps a gutter of at least 2^K texels, K = the number of halvings from the
// atlas side down to `min_mip_size` (64 px by default: 2048 -> 32 texels,
// 1024 -> 16), filled with the chart's own colours, and the packing keeps
// charts apart by twice that.
//
// dilate_charts fills every empty texel (no background is left, so no black):
// rings of growing Chebyshev distance around the charts, breadth first; a
// texel of ring r takes the label that most of its ring-(r-1) 8-neighbours
// carry (ties: the lower label) and the mean of those neighbours' values.
// Charts spaced 2g+1 texels apart therefore own every texel within g of them.
// No CGAL here.

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
