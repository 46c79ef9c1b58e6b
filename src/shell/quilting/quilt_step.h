// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// One iteration of mesh quilting in a planar frame (Zhou et al. 2006, section
// 2.2 steps 2-5): geometry matching (2.4), element correspondences (2.5),
// element deformation (2.6) and element merging (2.7). Shared by planar
// quilting (mesh_quilting.h), where the frame is the output plane, and by
// quilting on surfaces (surface_quilting.h), where it is the LSCM plane of a
// surface patch. Seed finding (2.3) is the caller's.
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "shell/quilting/element_merging.h"
#include "shell/element_mesh.h"
#include "shell/swatch.h"
#include "shell/triangle_distance.h"

namespace surftex {

/// The 2D grid of the frame: cell (i, j) covers [x0 + i c, x0 + (i+1) c) x [y0 + j c, ...).
struct QuiltGrid {
  double x0 = 0, y0 = 0, cell = 1;
  int nx = 0, ny = 0;
  std::vector<char> processed;  ///< nx*ny, row-major (j * nx + i)
  std::vector<char> subpatch;   ///< nx*ny: the output sub-patch P_out
  /// Cell of a point, or -1 outside the grid.
  int cell_of(double x, double y) const;
};

struct QuiltStepOptions {
  double lambda = 1.0;        ///< eq. 1, >= 0
  double mu = 1.0;            ///< eq. 5-6, > 0
  double prune_factor = 3.0;  ///< section 2.5 distance pruning, in local edge lengths
  /// Translations within this relative margin of the best E(t) are drawn from
  /// at random (the paper takes the minimum). >= 0. Default 0.02.
  double choice_tolerance = 0.02;
  /// Output vertices in P_out used for eq. 3 (evenly subsampled above this); >= 1.
  int max_match_vertices = 600;
  /// An input element whose stitch is refused is dropped (the output one kept)
  /// rather than added on top. Default true.
  bool drop_refused_inputs = true;
  /// With drop_refused_inputs: add its kept part outside the overlap instead,
  /// capped (MergeResult::capped_b); false = drop it whole. Default true.
  bool keep_cut_refused_inputs = true;
  /// Geometric checks of each stitch (MergeOptions::max_loop_offset ...). Default true.
  bool check_stitch_geometry = true;
  /// Options of every merge (section 2.7); its mu is replaced by `mu` above,
  /// and check_stitch_geometry = false turns its geometric checks off.
  MergeOptions merge;
  /// Keep only mutually strongest output-input relations (one partner each);
  /// false = the paper's "any surviving pair". Default true.
  bool one_to_one = true;
  /// Sub-cell refinement of the grid translation (2.4 notes a finer step
  /// helps): a pattern search of this many levels within half a cell. [0, 8];
  /// 0 = grid units only. Default 3 (figures: decision 103).
  int subcell_levels = 3;
  /// No interpenetration (issue 17): an unmerged new element that hits a placed
  /// one (exact test plus `clearance`) is dropped if compact, else trimmed at
  /// the hits and capped. false = added as is. Default true.
  bool resolve_crossings = true;
  /// Touching distance in swatch units; < 0 (default) = half Swatch::min_gap;
  /// 0 = intersections only.
  double clearance = -1;
  /// Rings of triangles removed around the hits of a trimmed element, >= 0. Default 2.
  int trim_rings = 2;
  /// A crossing thread is first pushed over or under by a smooth z bump, kept
  /// so if that clears it. Default true.
  bool push_over_under = true;
};

/// Where quilt_step put the swatch: its bbox min at the corner of cell
/// (oi, oj) shifted by (dx, dy) (frame units, |dx|, |dy| <= cell / 2).
struct QuiltPlacement {
  int oi = 0, oj = 0;
  double dx = 0, dy = 0;
};

struct QuiltStepStats {
  std::size_t candidates = 0;       ///< translations evaluated
  double best_cost = 0;             ///< E(t) of the chosen translation (eq. 3)
  std::size_t pairs = 0, related = 0, pruned_normal = 0, pruned_distance = 0, pruned_projection = 0;
  std::size_t stitched = 0, stitch_refused = 0;  ///< merges (2.7)
  std::size_t stitched_trimmed = 0;  ///< of the stitched, after trimming an overlapping cut end (MergeResult::trimmed)
  /// Refusals by reason: infeasible cut, loops, borders, geometry.
  std::size_t refused_infeasible = 0, refused_loops = 0, refused_border = 0, refused_geometry = 0;
  /// Merges with nothing to stitch (MergeResult::coincident): output kept,
  /// input dropped. Not counted in stitch_refused.
  std::size_t coincident = 0;
  /// Of those, inputs whose end past the overlap was kept capped.
  std::size_t coincident_cut_added = 0;
  /// Refusals by reason text (before ':', numbers as N).
  std::map<std::string, std::size_t> refused_reasons;
  std::size_t out_replaced = 0, in_dropped = 0, in_added = 0;
  /// Refused inputs added as capped kept parts, and their components.
  std::size_t in_cut_added = 0, in_cut_components = 0;
  /// resolve_crossings: new elements that hit, dropped, trimmed (into pieces).
  std::size_t crossing_hits = 0, crossing_dropped = 0, crossing_trimmed = 0, crossing_pieces = 0;
  std::size_t crossing_pushed = 0;  ///< of crossing_hits, threads pushed over or under instead (push_over_under)
  double seconds_resolve = 0;
  double seconds_match = 0, seconds_correspond = 0, seconds_deform = 0, seconds_merge = 0;
  void add(const QuiltStepStats& o);
};

/// The outcome of geometry matching (section 2.4) for one grid.
struct QuiltMatch {
  QuiltPlacement placement;
  double cost = 0;             ///< E(t) (eq. 3) of the chosen translation
  std::size_t vertices = 0;    ///< output vertices of P_out summed in E(t)
  std::size_t candidates = 0;  ///< translations evaluated
};

/// Section 2.4 alone: the translation covering P_out that minimises E(t)
/// (eq. 3) over at most max_match_vertices output vertices, drawn among those
/// within choice_tolerance, sub-cell refined; with `near`, only that grid
/// translation is refined. Throws InvalidInputError on an empty or too large
/// P_out or bad options.
QuiltMatch match_swatch_placement(const Swatch& swatch, const TriangleDistance& swatch_tree, const QuiltGrid& grid,
                                  const std::vector<ElementMesh>& elements, const std::vector<char>& alive,
                                  std::mt19937_64& rng, const QuiltStepOptions& opt,
                                  const QuiltPlacement* near = nullptr);

/// Places the swatch (at match_swatch_placement's or the `given` match),
/// merges it into `elements` (consumed: alive 0; new appended, alive 1; swatch
/// z) and marks the covered cells processed. Throws as match_swatch_placement.
QuiltPlacement quilt_step(const Swatch& swatch, const TriangleDistance& swatch_tree, QuiltGrid& grid,
                          std::vector<ElementMesh>& elements, std::vector<char>& alive, std::mt19937_64& rng,
                          const QuiltStepOptions& opt, QuiltStepStats& stats, const QuiltMatch* given = nullptr);

}  // namespace surftex
