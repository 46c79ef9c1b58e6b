// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Wrap-seam ratio: how visible the seams of an image are when it is repeated
// as a tile. The mean colour jump (Euclidean norm over channels) across the
// wrap -- between column W-1 and column 0, and between row H-1 and row 0 --
// divided by the mean jump between horizontal and vertical neighbours inside
// the image. About 1 for a seamless tile (the wrap looks like any other
// neighbour pair), clearly above 1 for an image that does not tile.
// Used to check the tileable tiles of Ray et al. 2009 section 1 (T_0, T_M).
//
// Limitation: on sparse textures the jump of one line depends on whether it
// grazes a feature, so the two wrap lines are a small, noisy sample; the
// figure follows the phase of the features, not seam quality. Phase-robust
// variants below: every line against its orientation's mean
// (line_jump_profile, rolled_wrap_seam_ratio) and against the exemplar's own
// jumps at the same sources (source_matched_line_profile). The measurements:
// docs/decisions/306-wrap-seam-ratio.md.

#include <vector>

#include "geometry/image.h"

namespace surftex {

/// The colour jump between pixels (x0, y0) and (x1, y1) of `img`: the
/// Euclidean norm of their difference over all channels. Every figure in
/// this header (and choose_torus_cut) is built from it. No bounds check.
double colour_jump(const Image& img, int x0, int y0, int x1, int y1);

/// The exemplar's own jump for an output pair copied from exemplar pixels
/// a = (ax, ay) and b = (bx, by), the pair's step being (dx, dy): the mean
/// of the jumps a -> a + (dx, dy) and b - (dx, dy) -> b over those inside the
/// exemplar, or `fallback` when neither is (the reference of
/// source_matched_line_profile and of graph-cut's straight-seam repair).
double source_natural_jump(const Image& exemplar, int ax, int ay, int bx, int by, int dx, int dy,
                           double fallback);

struct WrapSeamStats {
  double wrap_mean = 0.0;    ///< mean jump over the H left-right and W top-bottom wrap pairs
  double inside_mean = 0.0;  ///< mean jump over the (W-1)H + W(H-1) interior pairs
  double ratio = 1.0;        ///< wrap_mean / inside_mean (1 if both are 0, +inf if only inside is 0)
};

/// Throws InvalidInputError if the image is empty or smaller than 2x2.
WrapSeamStats wrap_seam_stats(const Image& img);

/// wrap_seam_stats(img).ratio.
double wrap_seam_ratio(const Image& img);

// Whether the wrap of an image is invisible, for the texture's own structure
// (subdivision synthesis's --wrap auto; docs/decisions/207-wrap-verdict.md).
// The plain ratio above is fooled when a feature of the texture runs along
// the wrap (decision 306): a brick wall cut along its mortar tiles, yet its
// wrap row jumps like a mortar line, far above the mean. Two checks replace
// it there, each a comparison with the image itself:
// 1. lines: the mean jump across each wrap line (column line 0, row line 0)
//    is no larger than across the most contrasted interior line of the same
//    orientation (the wrap looks like some line of the texture);
// 2. windows: the window x window neighbourhoods straddling the wrap have
//    as close a match among the image's interior windows as interior
//    windows have among the others (a period that does not divide the
//    image, e.g. stripes cut mid-period, passes 1 but makes a neighbourhood
//    found nowhere inside: a stripe of double width).

/// Windows straddling the wrap against interior windows: the mean, over
/// windows_per_line windows evenly spread along each wrap line (the seam in
/// their middle, read wrapping), of the mean squared colour difference to
/// the nearest window lying wholly inside the image; and the same for an
/// 8 x 8 grid of interior windows. Candidates overlapping the query on the
/// torus are left out for both, so no window is matched to itself.
struct WrapWindowStats {
  double wrap_nn = 0.0;      ///< mean nearest-neighbour distance of the wrap windows
  double interior_nn = 0.0;  ///< the same for the interior windows
  double ratio = 1.0;        ///< wrap_nn / interior_nn (1 if both are 0, +inf if only interior_nn is)
};

/// Throws InvalidInputError if window < 1 or the image is smaller than
/// 2 window + 1 on a side (no candidate would remain).
WrapWindowStats wrap_window_stats(const Image& img, int window, int windows_per_line = 32);

struct WrapVerdict {
  double seam_ratio = 1.0;             ///< wrap_seam_ratio
  bool lines_within_interior = false;  ///< check 1
  double window_ratio = -1.0;          ///< check 2's ratio; -1 when not computed
  bool seamless = false;  ///< seam_ratio <= threshold, or checks 1 and 2 (window_ratio <= threshold)
};

/// The verdict for `img` (at least 2x2): the windows are only compared when
/// the plain ratio is above `threshold` (> 0) and the lines pass, and when
/// the image is at least 2 window + 1 on each side (else not seamless).
WrapVerdict wrap_verdict(const Image& img, double threshold, int window);

// Worst-line ratio: every line of the torus (column line x: pairs (x-1, x)
// mod W; row line y likewise), its mean jump over the mean jump of all pairs
// of its orientation (per orientation, for anisotropic textures; unchanged by
// rolling). About 1 on a seamless image; compare with the exemplar's own
// line_jump_profile(ex, false), as aligned sparse features raise it.
struct LineJumpProfile {
  std::vector<double> column;  ///< W entries: mean jump across column line x (pairs (x-1, x))
  std::vector<double> row;     ///< H entries: mean jump across row line y (pairs (y-1, y))
  double column_mean = 0.0;    ///< mean of `column` (mean horizontal-pair jump)
  double row_mean = 0.0;       ///< mean of `row` (mean vertical-pair jump)
  /// max over lines of line jump / mean of its orientation (0/0 counts as 1,
  /// x/0 as +inf).
  double worst_ratio = 1.0;
  bool worst_is_column = true;  ///< orientation of the worst line
  int worst_index = 0;          ///< its x (column line) or y (row line)
  /// The worst column and row line ratios (compare each with the exemplar's).
  double worst_column_ratio = 1.0, worst_row_ratio = 1.0;
  /// Ratio of the lines of the image's own wrap (column line 0, row line 0),
  /// each against its orientation's mean (periodic only; 1 when not periodic).
  double wrap_column_ratio = 1.0, wrap_row_ratio = 1.0;
  bool periodic = true;  ///< as passed to line_jump_profile
};

/// The jump profile of every column and row line. `periodic` true: the
/// image is a torus (W column lines including x = 0, the wrap; H row lines).
/// false: only interior lines (column lines 1..W-1, row lines 1..H-1; entry 0
/// of each vector is 0 and left out of the means), e.g. for an exemplar as a
/// reference of how uneven its own lines are. Throws InvalidInputError if the
/// image is smaller than 2x2 (3x3 when not periodic).
LineJumpProfile line_jump_profile(const Image& img, bool periodic = true);

/// line_jump_profile(img, true).worst_ratio.
double worst_line_ratio(const Image& img);

// Source-matched line ratio (graph-cut outputs, sources known): each pair's
// jump over the exemplar's own jump at its sources (source_natural_jump); a
// verbatim pair has ratio 1 whatever the content. Per line: summed jump over
// summed exemplar jump (1 when both are 0, +inf when only the latter is).
struct SourceMatchedLineProfile {
  std::vector<double> column;  ///< W entries: ratio of column line x (pairs (x-1, x) mod W)
  std::vector<double> row;     ///< H entries: ratio of row line y
  /// The two wrap lines (column line 0, row line 0) pooled: summed jump over
  /// summed exemplar jump of their W + H pairs.
  double wrap_ratio = 1.0;
  double worst_ratio = 1.0;     ///< max over the W + H lines
  bool worst_is_column = true;  ///< orientation of the worst line
  int worst_index = 0;          ///< its x or y
  int seam_pairs = 0;           ///< pairs whose sources are not exemplar neighbours
};

/// The source-matched line profile of `img` (periodic, W x H) whose pixel
/// (x, y) was copied from exemplar pixel (source_x[i], source_y[i]),
/// i = y W + x. Throws InvalidInputError if the image is smaller than 2x2,
/// the source vectors do not have W H entries, a source lies outside the
/// exemplar, or the channel counts differ.
SourceMatchedLineProfile source_matched_line_profile(const Image& img, const Image& exemplar,
                                                     const std::vector<int>& source_x,
                                                     const std::vector<int>& source_y);

/// The wrap_seam_ratio of the periodic image of `p` rolled so its wrap lies on
/// column line `x` and row line `y`, exactly, in O(1). Throws
/// InvalidInputError for a non-periodic profile or an index out of range.
double rolled_wrap_seam_ratio(const LineJumpProfile& p, int x, int y);

}  // namespace surftex
