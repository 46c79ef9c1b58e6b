// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Tileable (periodic) texture tiles, the T_0 / T_M of Ray, Nivoliers, Lefebvre,
// Levy 2009 "Material-space texturing", section 1: "tileable versions of them
// T_0 and T_M ... can be done by using the graph-cut algorithm [KdE*03]".
// Graph-cut synthesis (texture/graphcut_synthesis.h) on the torus: every
// index is taken modulo the tile size, patches wrap across the edges, and the
// seams across the wrap are cut like any other seam, so the tile repeats
// without a visible border left-right and top-bottom (check with
// texture/wrap_seam_ratio.h).
//
// Where to cut the torus (TileOptions::choose_cut): a periodic tile is a
// torus, and any cyclic shift (roll by dx, dy) of it is the same tiling, so
// the row and the column where the image "starts" are a free choice. The
// synthesis leaves them wherever the fill grid began; make_tileable_detailed
// then rolls the tile so that its border lies on the row pair and the column
// pair of the torus whose neighbouring pixels differ least (choose_torus_cut).
// The repeated texture is unchanged pixel for pixel; only the border moves,
// onto the smoothest line, which is also the best place for it where the
// border is not wrapped: mip-mapping or bilinear filtering with clamped
// borders, and the material-space T_0 / T_M key tiles (Ray et al. 2009
// section 1), whose feature masks are computed after the roll.
// The synthesis cut itself is not a worse line than any other (measured:
// its jump ranks at percentile 0.48 among the torus lines over 29 textures x
// 6 seeds; texture/wrap_seam_ratio.h), so the roll does not hide a seam the
// synthesis puts at the start of its fill grid; it only moves the border off
// lines that happen to run along texture features. Because the roll picks
// the minimum over lines, neither wrap-seam ratio proves that no straight
// seam lies inside: TileResult::worst_line_ratio (every line of the torus,
// roll-independent) is the figure for that, to be read against the same
// figure of tile-sized windows of the exemplar (bench/bench_graphcut.cpp).
// Straight seams inside (TileOptions::straight_seam_steps): the eq.-1 cut
// can leave two large patches meeting along a straight overlap edge
// (wood_512, 128 px, seed 1: column line 86, source-matched ratio 3.18);
// the graph-cut synthesis then repairs the lines of the torus whose
// source-matched ratio exceeds 1.3 with small targeted patches
// (GraphcutOptions::straight_seam_steps), measured 22/29 -> 28/29 tiles with
// every line <= 1.3 at +6% summed seam cost.

#include <cstdint>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"
#include "texture/graphcut_synthesis.h"
#include "texture/wrap_seam_ratio.h"

namespace surftex {

struct TileOptions {
  /// Patch side in pixels, 0 = automatic: min(7 size / 8, 3/4 of the shorter
  /// exemplar side), at least 4 (3/4: several offsets remain to choose from,
  /// as in graph-cut synthesis). Large patches: a periodic tile holds few of them, so each
  /// exemplar structure (wood grain, a check pattern's period) is copied over
  /// long stretches and the few seams can be placed where they cost least
  /// (measured at size 128: wood_512 seam cost 50 -> 24 and wrap-seam ratio
  /// 1.34 -> 0.63 against the earlier min(64, size/2)). No floor on the
  /// band left outside a patch was added: the 32-px key tiles of
  /// material_tile (32-px resampled exemplars) already get 24 px (3/4 of the
  /// exemplar, overlap 8), and the 1.64 wrap ratio of the mud key there is a
  /// crack of the exemplar along the wrap column, which holds no seam
  /// (texture/wrap_seam_ratio.h). 24 vs 28 px for 32-px tiles of full-size
  /// exemplars is not measured on all textures yet. Range 0 or >= 4
  /// (clipped to size - 1).
  int patch_size = 0;
  /// Overlap of the fill patches, 0 = automatic (patch/3). Range >= 0, < patch.
  int overlap = 0;
  /// Seam-repair passes after the tile is filled. Range >= 0.
  int refinement_passes = 4;
  /// Placement temperature (GraphcutOptions::k). Range > 0.
  double k = 0.002;
  PlacementMode placement = PlacementMode::SubPatch;
  /// GraphcutOptions::repetition_penalty. Default 0 here (0.3 for graph-cut
  /// synthesis): a tile is judged by its seams more than by how much of the
  /// exemplar it shows. Measured at 128 px (seed 1, the 29 shared
  /// textures): summed tile seam cost 2145 with 0, 2178 with 0.3
  /// (red_checked_384 13 -> 23, ink_b_400 16 -> 28). Range >= 0.
  double repetition_penalty = 0.0;
  /// Roll the finished tile so that its border (wrap row and column) lies on
  /// the smoothest row and column pair of the torus (choose_torus_cut).
  /// Default true. The tiling is unchanged: the result is a cyclic shift of
  /// the synthesised tile, same seam cost; only wrap_seam_ratio changes
  /// (it can only decrease: TileResult keeps both figures).
  bool choose_cut = true;
  /// GraphcutOptions::straight_seam_steps: targeted repairs of the straight
  /// seams the eq.-1 cut leaves inside a tile (lines of the torus whose
  /// source-matched ratio exceeds straight_seam_ratio). Only tiles holding
  /// such a line change (7 of the 29 shared textures at 128 px, seed 1;
  /// figures in bench/bench_graphcut.cpp). Range >= 0, 0 = off.
  int straight_seam_steps = 32;
  /// GraphcutOptions::straight_seam_ratio. Range > 1.
  double straight_seam_ratio = 1.3;
  /// GraphcutOptions::straight_seam_cost_tolerance: how much the tile's eq.-1
  /// seam cost may rise to remove its straight seams (1 = it may double; the
  /// tiles concerned have low costs: wood_512 23.9, ink_b_400 15.9). 0.1 and
  /// 0.3 left wood_512 at 2.24 and 1.98. Range >= 0.
  double straight_seam_cost_tolerance = 1.0;
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

/// A cut of a periodic image: the image rolled so that pixel (x, y) of the
/// result is pixel ((x + shift_x) mod W, (y + shift_y) mod H) of the input.
/// The wrap pairs of the result are the input's columns (shift_x - 1,
/// shift_x) and rows (shift_y - 1, shift_y) (indices mod W, H).
struct TorusCut {
  int shift_x = 0, shift_y = 0;
  double column_jump = 0;  ///< mean jump over the chosen column pair (H pairs)
  double row_jump = 0;     ///< mean jump over the chosen row pair (W pairs)
};

/// The column pair and the row pair of the torus `periodic` with the least
/// summed jump (Euclidean norm over channels, as texture/wrap_seam_ratio.h)
/// between neighbouring pixels. Ties keep the smaller shift (0 = the current
/// cut unless another line is strictly smoother). Throws InvalidInputError
/// for an image smaller than 2x2.
TorusCut choose_torus_cut(const Image& periodic);

/// The same cut from the image's line_jump_profile (periodic = true), for a
/// caller that already has it. Throws InvalidInputError for a non-periodic
/// profile.
TorusCut choose_torus_cut(const LineJumpProfile& periodic_profile);

struct TileResult {
  Image tile;                  ///< size x size, exemplar channels, periodic (after the cut choice)
  /// texture/wrap_seam_ratio.h of `tile`. With choose_cut it is taken at the
  /// smoothest line, the minimum over lines rather than an arbitrary one, so
  /// it is biased low: a cut-placement figure; for seam quality look at
  /// wrap_seam_ratio_at_synthesis_cut and seam_cost.
  double wrap_seam_ratio = 0;
  /// wrap_seam_ratio of the tile as synthesised, before the roll (equal to
  /// wrap_seam_ratio without choose_cut).
  double wrap_seam_ratio_at_synthesis_cut = 0;
  /// The roll applied (TorusCut of the synthesised tile; 0, 0 without
  /// choose_cut): tile(x, y) = synthesised((x + shift_x) mod size, (y + shift_y) mod size).
  int shift_x = 0, shift_y = 0;
  /// The exemplar pixel every tile texel was copied from (after the roll),
  /// row-major size x size: tile(x, y) = exemplar(source_x[i], source_y[i]),
  /// i = y size + x. Other maps of the exemplar follow the colour through them.
  std::vector<int> source_x, source_y;
  double seam_cost = 0;        ///< final total seam cost (graph-cut units, unchanged by the roll)
  /// texture/wrap_seam_ratio.h worst_line_ratio of the tile: the highest
  /// line jump of the torus over the mean of its orientation, the same for
  /// every roll (the check that no straight seam lies anywhere).
  double worst_line_ratio = 0;
  /// Where the synthesis cut (column line 0, row line 0 of the synthesised
  /// tile) ranks among the lines of the torus: the fraction of the W column
  /// lines (H row lines) whose jump is below it, 0 = smoothest, 1 = roughest.
  /// Measured to be uniform (no line of the fill grid is special, see
  /// texture/tileable_tile.h).
  double synthesis_column_percentile = 0, synthesis_row_percentile = 0;
  /// texture/wrap_seam_ratio.h source_matched_line_profile of the tile as
  /// synthesised (the sources are known): the wrap lines' jump over the
  /// exemplar's own jump at the same sources (1 = copied verbatim or as
  /// smooth as the exemplar there), and the worst line of the torus (the same
  /// for every roll). Phase-robust: a line along texture features is not
  /// penalised, a line along which the sources change with a step is.
  double source_matched_wrap_ratio_at_synthesis_cut = 0;
  double source_matched_worst_line_ratio = 0;
};

/// The graph-cut options make_tileable_detailed runs for `exemplar`, `size`
/// and `options` (automatic patch side resolved, periodic_output = true), so
/// that a caller can run graphcut_synthesize_detailed itself (e.g. for the
/// source maps) without copying the defaults. Throws InvalidInputError as
/// make_tileable_detailed for invalid options.
GraphcutOptions tileable_graphcut_options(const Image& exemplar, int size, const TileOptions& options = {});

/// A size x size periodic tile grown from `exemplar`. Throws InvalidInputError
/// naming the option for size < 8, an empty exemplar or an invalid option.
TileResult make_tileable_detailed(const Image& exemplar, int size, const TileOptions& options = {});

/// make_tileable_detailed(...).tile.
Image make_tileable(const Image& exemplar, int size, const TileOptions& options = {});

}  // namespace surftex
