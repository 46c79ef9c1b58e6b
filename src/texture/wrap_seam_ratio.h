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
// Limitation (measured, not corrected here): on sparse textures -- isolated
// features on a flat background -- the jump of one line of pixels depends
// mostly on whether it grazes a feature edge, so the wrap lines (one row, one
// column) are a tiny, noisy sample. Example: a 128x128 graph-cut tile of
// shared/data/textures/dots_large_208x168.png has total seam cost 0 (every
// cut runs through flat background) and 122 of its 128 row-wrap pairs are
// exemplar neighbours copied verbatim, yet its ratio is 1.69 because a dot's
// edge lies along the wrap row (a grazing row like the densest interior ones).
// Further measurement (128x128 tiles, seed 1): with patch sides 64 / 96 / 112
// the dots_large tile's ratio is 1.69 / 0.85 / 1.60 and dots_purple's 1.40 /
// 1.86 / 0.89 while the total seam cost is 0 in all six: the figure follows
// the phase of the dots relative to the one wrap line, not seam quality.
// Small tiles make it worse: a 32x32 key tile of material_tile (32x32
// resample of cracked_mud_100, seed derive_seed(5, 1001)) has ratio 1.64
// while its wrap column holds no graph-cut seam (all 32 pairs are exemplar
// neighbours copied verbatim); a crack of the exemplar runs along it (that
// column's jump is 2.27x the mean, the column before it 2.08x). Over 18
// such 32-px tiles (3 textures x 6 seeds) the seam cost on the wrap lines
// equals that of an average line (18.3 vs 17.0; test
// TileableTile.At32PxTheWrapLinesCarryNoMoreSeamThanOtherLines).
// Same at 128 px: the default 128x128 tile (seed 1) of water_caustics_300
// has ratio 1.71; its wrap row holds 2 seam pairs of 128 (the rest are
// exemplar neighbours) and ranks 4th of the tile's 128 rows, behind rows of
// verbatim caustic edges, its wrap column (2 seam pairs) ranks 25th.
// Phase-robust variants: the wrap line against the distribution of per-line
// means (line_jump_profile, rolled_wrap_seam_ratio) and against the
// exemplar's jumps at the same sources (source_matched_line_profile, below).
// Since the border of a periodic tile is a free choice (any roll is the
// same tiling), make_tileable_detailed moves it onto the smoothest row and
// column of the torus (texture/tileable_tile.h, TileOptions::choose_cut):
// both tiles above then measure 0.09 and 0.26. That figure is the minimum
// over the lines of the torus, biased low by construction; TileResult keeps
// the ratio at the synthesis cut beside it (1.60 and 1.74 for these two
// with the error-region refinement).
// Is the synthesis cut a special line? No (128-px tiles of the 28
// non-constant shared textures, seeds 1-6, line_jump_profile): line 0's jump
// ranks at percentile 0.48 +- 0.02 among the 128 lines of its orientation
// (uniform: 0.5; columns 0.480, rows 0.480), its mean ratio to the mean line
// is 0.97, 9.5% of line-0 samples exceed 1.3 against 13% of all lines, and
// the patch-edge lines of the 2x2 fill grid (0, 48, 64, 112) sit at
// percentiles 0.48-0.54 (they carry 1.5x the seam pairs of other lines, at
// no higher jump). Over the 29 seed-1 tiles, the expected number of ratios
// above 1.3 at a cut drawn uniformly among the 128 x 128 rolls
// (rolled_wrap_seam_ratio) is 2.68; 3 are observed at the synthesis cut.
// The three (dots_large, ink_a, water_caustics) have their wrap row at
// percentile 0.98, 0.92, 0.98 of their rows: a draw from their own line
// spread (seeds 2-6 give 0.72-1.16, 0.90-1.31, 0.74-1.45), not a seam (their
// wrap rows hold 0, 16 and 3 seam pairs of 128). Their source-matched wrap
// ratios (below) are 1.000, 1.075 and 1.029; over the 29 seed-1 tiles
// 0.991-1.075: no wrap carries a seam. Seams do lie along straight lines
// inside some tiles (source-matched worst line: wood_512 3.18 on a column
// that shows a visible straight seam, ink_b_400 6.0 on a row, ink_a 2.2,
// water_caustics 1.7, brick_gray 1.7): the defect a roll to the smoothest
// line could hide, and the figure to watch for it. Repaired since by
// GraphcutOptions::straight_seam_steps (tiles: 28/29 with every line <= 1.3;
// ink_b 1.62 left; bench/bench_graphcut.cpp).

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

// Worst-line ratio: the roll-independent check that a periodic image holds no
// straight seam anywhere. The wrap-seam ratio looks at one row and one column
// (where the image happens to start); any cyclic shift of a periodic tile is
// the same tiling, so a straight seam may as well lie inside. Here every line
// of the torus is measured: column line x is the H pairs between columns x-1
// and x (mod W), row line y the W pairs between rows y-1 and y (mod H). Each
// line's mean jump is divided by the mean jump of all pairs of the same
// orientation on the torus (horizontal pairs for column lines, vertical pairs
// for row lines; both include the wrap pairs, so the figure does not change
// when the image is rolled). Per orientation, because an anisotropic texture
// (horizontal wood grain, stripes) has different jumps across rows and
// across columns without any seam. Seamless: about 1 on the mean line, and
// the maximum over the W + H lines is above 1 by the spread of one line's
// sample (a sparse texture whose features are aligned in rows, e.g. a dot
// lattice, reaches 1.5 or more on the rows grazing its features; compare
// with the same figure of the exemplar: line_jump_profile(ex, false)).
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
  /// The worst column line's and the worst row line's ratio (worst_ratio is
  /// their maximum): compare each with the same figure of the exemplar, as a
  /// texture's two orientations can differ (wood grain: rough rows, even columns).
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

// Source-matched line ratio: a phase-robust line check for a periodic image
// made of exemplar pixels (graph-cut synthesis: the source of every pixel is
// known). For each neighbour pair (s, t) of the torus, its jump |I(s)-I(t)|
// is compared with the jump the exemplar itself has there: the mean of
// |E(a) - E(a + d)| and |E(b - d) - E(b)| (a, b the exemplar sources of s, t,
// d the pair's direction; the terms whose pixel falls outside the exemplar
// are left out, the pair's own jump used when both do). A pair copied
// verbatim (b = a + d) has ratio exactly 1, whatever the content: a line
// running along dot edges or caustics is not penalised, a line along which
// the sources change with a colour step is. Per line: summed jump over
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

/// The wrap_seam_ratio the periodic image of profile `p` (line_jump_profile
/// with periodic = true) has when rolled so that its wrap lies on column line
/// `x` and row line `y` (i.e. of crop(img, x, y, W, H, true)), exactly, in
/// O(1): over all W x H rolls this is the distribution a wrap-seam ratio
/// taken at an arbitrary cut is drawn from. Throws InvalidInputError for a
/// non-periodic profile or a line index out of range.
double rolled_wrap_seam_ratio(const LineJumpProfile& p, int x, int y);

}  // namespace surftex
