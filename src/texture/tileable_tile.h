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
// TileOptions::choose_cut rolls the finished tile so that its border lies on
// the smoothest row and column pair of the torus (choose_torus_cut): the
// tiling is unchanged, the border moves off texture features (what clamped
// filtering and the material-space key tiles see). The roll does not hide a
// seam; TileResult::worst_line_ratio is the roll-independent check, and
// straight seams inside are repaired by GraphcutOptions::straight_seam_steps.
// Measurements: docs/decisions/306-wrap-seam-ratio.md.

#include <cstdint>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"
#include "texture/graphcut_synthesis.h"
#include "texture/wrap_seam_ratio.h"

namespace surftex {

struct TileOptions {
  /// Patch side in pixels, 0 = automatic: min(7 size / 8, 3/4 of the shorter
  /// exemplar side), at least 4 (few large patches: seams where they cost
  /// least; decision 306). Range 0 or >= 4 (clipped to size - 1).
  int patch_size = 0;
  /// Overlap of the fill patches, 0 = automatic (patch/3). Range >= 0, < patch.
  int overlap = 0;
  /// Seam-repair passes after the tile is filled. Range >= 0.
  int refinement_passes = 4;
  /// Placement temperature (GraphcutOptions::k). Range > 0.
  double k = 0.002;
  PlacementMode placement = PlacementMode::SubPatch;
  /// GraphcutOptions::repetition_penalty. Default 0 here (0.3 for graph-cut
  /// synthesis): a tile is judged by its seams (decision 306). Range >= 0.
  double repetition_penalty = 0.0;
  /// Roll the finished tile so its border lies on the smoothest row and column
  /// of the torus (choose_torus_cut); same tiling and seam cost. Default true.
  bool choose_cut = true;
  /// GraphcutOptions::straight_seam_steps: repairs of straight seams inside the
  /// tile (lines above straight_seam_ratio). Range >= 0, 0 = off.
  int straight_seam_steps = 32;
  /// GraphcutOptions::straight_seam_ratio. Range > 1.
  double straight_seam_ratio = 1.3;
  /// GraphcutOptions::straight_seam_cost_tolerance: allowed rise of the tile's
  /// eq.-1 seam cost (1 = it may double). Range >= 0.
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
  /// wrap_seam_ratio of `tile`; with choose_cut the minimum over lines (biased
  /// low): for seam quality read wrap_seam_ratio_at_synthesis_cut and seam_cost.
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
  /// worst_line_ratio of the tile (the same for every roll).
  double worst_line_ratio = 0;
  /// Rank of the synthesis cut among the torus lines: fraction of column (row)
  /// lines with a lower jump; 0 = smoothest, 1 = roughest.
  double synthesis_column_percentile = 0, synthesis_row_percentile = 0;
  /// source_matched_line_profile of the tile as synthesised: the wrap lines'
  /// and the worst line's jump over the exemplar's own (phase-robust).
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
