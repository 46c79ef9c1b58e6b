// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Graph-cut texture synthesis (Kwatra, Schoedl, Essa, Turk, Bobick 2003,
// "Graphcut Textures: Image and Video Synthesis Using Graph Cuts").
//
// The output is built from patches of the exemplar. Each new patch is pasted
// with a seam found by a minimum s-t cut (section 3) over its footprint:
//  - matching-quality cost of a neighbour pair (s,t) between patches A and B
//    (eq. 1): M(s,t,A,B) = ||A(s)-B(s)|| + ||A(t)-B(t)|| (Euclidean norm over
//    channels); optionally divided by the gradient term of eq. 5,
//    ||A(s)-A(t)|| + ||B(s)-B(t)|| + 1e-3 (GraphcutOptions::gradient_normalized).
//    A patch is a translation of the exemplar, so A(t) is read from the
//    exemplar next to A's source of s; where that falls outside the exemplar
//    the one available term is counted twice.
//  - old seams are kept (section 3.3): a pair whose two pixels come from
//    different earlier patches gets a seam node joined to both pixels (costs
//    M(s,t,A_s,B), M(s,t,B,A_t)) and to the new patch (cost M(s,t,A_s,A_t)),
//    so a later patch can remove or replace an earlier seam.
//  - pixels not yet covered (and forced pixels) must take the new patch:
//    they are left out of the graph and their links to free pixels become
//    terminal costs, so the graph spans only the overlap; pairs between the
//    footprint and untouched pixels around it become terminal costs too (old
//    seam kept vs new seam made).
// Every cut goes through surftex::GraphCut (Boost.Graph Boykov-Kolmogorov).
//
// Placement (section 4): the output is first filled in scan order with
// patches overlapping by `overlap` pixels. Candidate offsets are drawn with
// probability proportional to exp(-C / (k sigma^2)) (section 4) where C is the
// SSD over the overlap divided by the overlap area (plus the repetition term
// of GraphcutOptions::repetition_penalty) and sigma^2 the summed per-channel
// variance of the exemplar. Matching costs for every offset come from FFT
// correlations (section 4.1, texture/masked_ssd_fft.h).
// Refinement (section 4, "we then iterate over regions of high seam cost"):
// `refinement_passes` passes, each of as many steps as the fill placed
// patches. A step takes the error region -- the error_region x error_region
// window of the output with the highest summed seam error (pair costs M of
// its pixels), recomputed after every change -- and chooses a patch by
// sub-patch matching: the output window of side 3 error_region centred on
// the region is matched against every exemplar offset, the region's own
// pixels left out of the match (they hold the bad seam to be replaced); the
// patch pasted is the exemplar around the match, up to the patch size, and
// the cut (old seams kept, section 3.3) decides how much of it is used. If
// the cut keeps every old pixel, the whole patch-size window around the
// region is matched instead (sub-patch matching with the largest sub-patch).
// The region is not forced to take the new patch: the free cut is the best
// labelling of the footprint among all, including those that would force
// it, so a step never increases the total seam cost. Within a pass, regions
// centred in an error region or in the central half of a footprint already
// tried in that pass are skipped, so a pass spreads over the worst seams.
// Periodic output (Ray et al. 2009 section 1, tileable tiles T_0, T_M): all
// output indexing is modulo the size, patches wrap across the edges and the
// seams across the wrap are optimised like any other.
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
  /// Side of a (square) patch in pixels, 0 = automatic: 3s/4 clamped to
  /// [64, 192], at most s, where s = min(exemplar width, exemplar height)
  /// (few, large patches: fewer seams, larger verbatim regions; FFT matching
  /// makes their size free, section 4.1); always clipped to the
  /// exemplar and output sizes. With patch_size and overlap both automatic
  /// and a non-periodic output, each side is then lowered to the largest
  /// 3 L / (2n + 1) (L = output side) not above it, so that n patches
  /// overlapping by a third cover the output exactly instead of the last one
  /// being pushed back over its neighbour (a 256 output: 154, not 192
  /// overlapping by 128). Ignored
  /// by EntirePatch (the patch is the exemplar). Range 0 or >= 4.
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
  /// Weight lambda of the repetition term added to a candidate offset's
  /// matching cost: C + lambda sigma^2 R, where R is the mean, over the
  /// exemplar window the patch would copy, of how many output pixels outside
  /// the target window already show each exemplar pixel, divided by the
  /// average such count max(1, output area / exemplar area). 0 = Kwatra's
  /// cost alone. Not in Kwatra et al.; the occurrence penalty of texture
  /// optimisation (Kaspar et al. 2015, "Self tuning texture optimization")
  /// applied to patch offsets: an output that shows the same exemplar region
  /// twice shows less of the rest (lower completeness, Simakov et al. 2008).
  /// Cost per placement: one pass over the output and one over the
  /// exemplar (figures behind 0.3: decision 502). Range >= 0.
  double repetition_penalty = 0.3;
  /// Divide the matching cost by the gradient term (Kwatra eq. 5).
  bool gradient_normalized = false;
  /// Toroidal output: the result tiles seamlessly left-right and top-bottom.
  bool periodic_output = false;
  /// Straight-seam repair of a periodic output (not in Kwatra et al.; only
  /// with periodic_output, ignored otherwise): after the refinement passes,
  /// up to this many targeted attempts at the lines of the torus whose
  /// source-matched ratio (texture/wrap_seam_ratio.h
  /// source_matched_line_profile: a line's jump over the exemplar's own jump
  /// at the same sources) exceeds straight_seam_ratio. Eq.-1 cuts can leave
  /// two large patches meeting along a straight overlap edge, a seam the eye
  /// follows, and the refinement above never raises the eq.-1 cost. Each
  /// attempt pastes a repair patch centred on the worst stretch of the worst
  /// line, forced across the line, cut freely elsewhere, and is kept only if
  /// it lowers the lines' excess without raising the worst line, the seam
  /// cost (straight_seam_cost_tolerance) or the output's own wrap lines
  /// (the steps in detail: decision 502). Cost: one FFT match and up to 8
  /// small cuts per attempt.
  /// Range >= 0; 0 = off.
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
  /// The side x side window with the highest sum of `error_map` (a
  /// seam_error_map, possibly updated by the caller), Kwatra et al. 2003
  /// section 4's "error region": windows wrap across the edges when the
  /// canvas is periodic, else lie inside the output (side clipped to it).
  /// Windows whose centre pixel (x + side/2, y + side/2) is nonzero in
  /// `skip` (width*height, or empty) are not considered; ties keep the first
  /// in scan order. cost 0 (and x = y = 0) if no window has any error.
  /// Throws InvalidInputError for side < 1 or a map of the wrong size.
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
