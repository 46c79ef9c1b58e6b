// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Graph-cut texture synthesis (Kwatra, Schoedl, Essa, Turk, Bobick 2003,
// "Graphcut Textures: Image and Video Synthesis Using Graph Cuts").
//
// Patches of the exemplar pasted with seams from a minimum s-t cut (3): cost
// M = ||A(s)-B(s)|| + ||A(t)-B(t)|| (eq. 1; optionally over eq. 5's gradient
// term), old seams kept as seam nodes (3.3), uncovered and forced pixels
// bound to the new patch, so the graph spans only the overlap. Cuts go
// through surftex::GraphCut. Placement (4): a scan-order fill with offsets
// drawn by exp(-C / (k sigma^2)), C from FFT correlations (4.1); then
// refinement over the error regions of highest seam cost by sub-patch
// matching, a free cut, so a step never raises the total seam cost. Periodic
// output (Ray et al. 2009, 1): indexing modulo the size. The details:
// docs/decisions/502-graphcut-bench-history.md.
//
// Deterministic: every random choice from a std::mt19937_64 seeded with
// Options::seed; the same inputs give the same bytes for any thread count.

#include <cstdint>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"

namespace surftex {

enum class PlacementMode {
  Random,       ///< random exemplar offset (section 4, "random placement")
  EntirePatch,  ///< the whole exemplar (clipped to the output) is translated over the
                ///< output; the translation covering the next target pixel is matched
                ///< against everything already there (section 4, "entire patch matching")
  SubPatch      ///< a patch_size window of the output is matched against every exemplar
                ///< offset (section 4, "sub-patch matching")
};

struct GraphcutOptions {
  PlacementMode placement = PlacementMode::SubPatch;
  /// Patch side in pixels, 0 = automatic: 3s/4 clamped to [64, 192], at most
  /// s = the exemplar's smaller side (lowered so that patches cover a
  /// non-periodic output exactly); clipped to the exemplar and output.
  /// Ignored by EntirePatch. Range 0 or >= 4.
  int patch_size = 0;
  /// Overlap between neighbouring patches of the fill pass in pixels, 0 =
  /// automatic: max(2, patch/3). Must be < patch size. Range >= 0.
  int overlap = 0;
  /// Refinement passes after the output is filled (each tries as many error
  /// regions as the fill pass placed patches, see the file comment). Range >= 0.
  /// (Figures: docs/decisions/502-graphcut-bench-history.md.)
  int refinement_passes = 1;
  /// Side of the error region of the refinement in pixels (Kwatra et al.
  /// 2003 section 4), 0 = automatic: max(3, overlap/4), at most the patch.
  /// Range >= 0.
  int error_region = 0;
  /// Temperature k of the placement probability exp(-C/(k sigma^2)): small =
  /// nearly always the best match, large = nearly random. Range > 0.
  double k = 0.002;
  /// Weight lambda of the repetition term C + lambda sigma^2 R (R: how often the
  /// exemplar window is already shown, over the average; Kaspar et al. 2015's
  /// occurrence penalty, not in Kwatra). 0 = off. Range >= 0 (decision 502).
  double repetition_penalty = 0.3;
  /// Divide the matching cost by the gradient term (Kwatra eq. 5).
  bool gradient_normalized = false;
  /// Toroidal output: the result tiles seamlessly left-right and top-bottom.
  bool periodic_output = false;
  /// Straight-seam repair of a periodic output (ours): up to this many repair
  /// patches on the torus lines whose source-matched ratio (wrap_seam_ratio.h)
  /// exceeds straight_seam_ratio, each kept only if it lowers the excess without
  /// raising the seam cost past the tolerance (decision 502). Range >= 0; 0 = off.
  int straight_seam_steps = 0;
  /// Source-matched line ratio above which a line is repaired. Range > 1.
  double straight_seam_ratio = 1.3;
  /// Allowed relative rise of the total eq.-1 seam cost over the whole
  /// straight-seam stage (of the output's own cost). Range >= 0.
  double straight_seam_cost_tolerance = 1.0;
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

/// One patch placement: the exemplar window [ex_x, ex_x+width) x [ex_y, ex_y+height)
/// is pasted with its top-left at output pixel (out_x, out_y) (wrapped when
/// the output is periodic; clipped to the output otherwise).
struct PatchPlacement {
  int out_x = 0, out_y = 0;
  int ex_x = 0, ex_y = 0;
  int width = 0, height = 0;
};

/// The state of a graph-cut synthesis: for every output pixel, the exemplar
/// pixel it was copied from (or none yet). Exposed as a small class so that
/// callers (tileable tiles, tests) can place patches one by one.
class GraphcutCanvas {
 public:
  /// Throws InvalidInputError for an empty exemplar or a non-positive size.
  GraphcutCanvas(const Image& exemplar, int width, int height, bool periodic,
                 bool gradient_normalized = false);

  int width() const { return w_; }
  int height() const { return h_; }
  bool periodic() const { return periodic_; }
  bool covered(int x, int y) const { return sx_[idx(x, y)] >= 0; }
  bool complete() const;
  /// Exemplar coordinates of output pixel (x, y); (-1, -1) if not covered.
  int source_x(int x, int y) const { return sx_[idx(x, y)]; }
  int source_y(int x, int y) const { return sy_[idx(x, y)]; }

  /// Pastes `p` with a minimum-cost seam. Uncovered pixels and `forced`
  /// pixels (output coordinates inside the footprint) take the new patch.
  /// Returns the number of pixels whose source changed. Throws
  /// InvalidInputError if the exemplar window is not inside the exemplar.
  int place_graphcut(const PatchPlacement& p, const std::vector<std::pair<int, int>>& forced = {});
  /// Pastes `p` over its whole footprint (a straight-boundary paste).
  void place_straight(const PatchPlacement& p);

  /// Sum of M over all neighbour pairs whose pixels are both covered (zero
  /// where both come from the same translation); includes the wrap pairs
  /// when periodic.
  double seam_cost() const;
  /// Sum of the seam costs of the pairs touching pixel (x, y) (4 neighbours).
  double pixel_seam_error(int x, int y) const;
  /// pixel_seam_error of every output pixel (width*height, row-major).
  std::vector<double> seam_error_map() const;

  /// A square window of the output and its summed seam error.
  struct ErrorRegion {
    int x = 0, y = 0;   ///< top-left output pixel (wrapped when periodic)
    int side = 0;       ///< window side in pixels
    double cost = 0.0;  ///< sum of `error_map` over the window
  };
  /// The side x side window with the highest sum of `error_map` (Kwatra 4's
  /// error region; wrapping when periodic), skipping windows centred on nonzero
  /// `skip`; ties: first in scan order; cost 0 if none. Throws InvalidInputError
  /// for side < 1 or a map of the wrong size.
  ErrorRegion worst_error_region(const std::vector<double>& error_map, int side,
                                 const std::vector<char>& skip = {}) const;
  /// The output image (uncovered pixels are 0).
  Image render() const;

 private:
  friend class GraphcutSynthesizer;
  std::size_t idx(int x, int y) const { return static_cast<std::size_t>(y) * w_ + x; }
  double pair_cost(int sx, int sy, int tx, int ty, int dx, int dy) const;
  bool neighbour(int x, int y, int dx, int dy, int& nx, int& ny) const;
  double footprint_cost(const PatchPlacement& p) const;
  void check_placement(const PatchPlacement& p) const;

  Image ex_;
  int w_, h_;
  bool periodic_, gradient_normalized_;
  std::vector<int> sx_, sy_;
};

struct GraphcutResult {
  Image image;                       ///< width x height, exemplar channels
  std::vector<int> source_x, source_y;  ///< exemplar pixel of each output pixel
  double seam_cost_after_fill = 0;   ///< total seam cost when the output was first full
  double seam_cost_final = 0;        ///< after the refinement passes
  int patch_width = 0, patch_height = 0;  ///< patch side used (after the automatic choice)
  int fill_patches = 0;              ///< patches placed by the fill pass
  int refinement_tried = 0;          ///< refinement patches tried (cuts made)
  int refinement_accepted = 0;       ///< ... that changed the output (never raising the seam cost)
  double seam_cost_before_straight = 0;  ///< seam cost before the straight-seam stage
  int straight_seam_tried = 0;       ///< straight-seam attempts (stretches of lines targeted)
  int straight_seam_accepted = 0;    ///< ... whose paste was kept
};

/// Synthesizes a width x height image from `exemplar`. Throws
/// InvalidInputError naming the option for an invalid option or size.
GraphcutResult graphcut_synthesize_detailed(const Image& exemplar, int width, int height,
                                            const GraphcutOptions& options = {});

/// As graphcut_synthesize_detailed, returning only the image.
Image graphcut_synthesize(const Image& exemplar, int width, int height,
                          const GraphcutOptions& options = {});

}  // namespace surftex
