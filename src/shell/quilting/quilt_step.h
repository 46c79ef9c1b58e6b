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
  /// Translations whose cost E(t) is within this relative margin of the best
  /// are equally good; one of them is drawn with the step's generator (the
  /// paper takes the minimum; with (near-)periodic swatches many translations
  /// tie and a random pick among them avoids visible repetition). >= 0.
  double choice_tolerance = 0.02;
  /// Output vertices in P_out used for eq. 3 (evenly subsampled above this); >= 1.
  int max_match_vertices = 600;
  /// An input element whose stitching to its related output element is
  /// refused is dropped (the output element is kept) instead of being added
  /// on top of it: overlapping duplicates are worse than a small gap. The
  /// paper has no refusals (its merge always succeeds).
  bool drop_refused_inputs = true;
  /// With drop_refused_inputs: add the refused input element's kept part
  /// outside the overlap instead, closed at its cuts (MergeResult::capped_b),
  /// so that the new patch is covered up to the overlap, where the old
  /// elements stay (the two abut there instead of being stitched). Issue #8: on the 5K-face bunny 1,364 of 2,316
  /// placed threads were dropped whole, leaving bare strips. false = drop the
  /// whole input element.
  bool keep_cut_refused_inputs = true;
  /// Geometric checks of each stitch (MergeOptions::max_loop_offset and the
  /// next three, at their defaults): zip only loop pairs that face each other
  /// and refuse stitches that cross themselves. false = off (for
  /// comparisons).
  bool check_stitch_geometry = true;
  /// Options of every merge (section 2.7); its mu is replaced by `mu` above,
  /// and check_stitch_geometry = false turns its geometric checks off.
  MergeOptions merge;
  /// Keep only mutually strongest relations (most vertex-face pairs) between
  /// output and input elements, so that each element is merged with at most
  /// one partner (see strongest_relations in the .cpp); false = the paper's
  /// "any surviving pair relates two elements".
  bool one_to_one = true;
  /// Sub-cell refinement of the chosen grid translation (the paper restricts
  /// t to grid units and notes that a finer discretisation gives a better
  /// placement, section 2.4): a pattern search around the best grid
  /// translation, level 0 over 5 x 5 offsets at steps of c/4, each next level
  /// over 3 x 3 offsets at half the step (the shift stays within half a
  /// cell); 40 more E(t) evaluations with 3 levels. 0 = grid units only. The
  /// grid rarely fits the texture's own period (the default weave: spacing 1,
  /// cell 0.6), and on a surface each patch's grid starts at its seed, not on
  /// the lattice of the texture already placed; grid translations alone then
  /// miss the old elements by up to half a cell (0.3 thread spacings, more
  /// than a thread's radius), and the cuts of section 2.7 cannot pair up
  /// (planar default weave 2x2: 28 merges stitched / 55 refused without, 101
  /// / 34 with). [0, 8].
  int subcell_levels = 3;
  /// No interpenetration by construction (issue 17; the paper's elements do
  /// not pass through each other, sections 2.5-2.7 merge those that
  /// correspond): before an input element that was not merged (2.7's "added
  /// directly", or a refused one's kept part) is added, its triangles are
  /// tested against every element already there (exact triangle-triangle
  /// intersection, element_clearance.h) and against a clearance of
  /// `clearance` (vertex to triangle). One that hits is dropped if it is
  /// compact (a ring, a pebble: is_compact_element) or too little of it
  /// would be left, else trimmed at the hits (trim_rings rings more) and
  /// its cuts capped (a thread crossing an old one at the same height
  /// stops short of it on both sides; the hole is refilled by a later
  /// patch where there is room). false = added as before.
  bool resolve_crossings = true;
  /// Swatch units; the distance under which a new element counts as
  /// touching an old one. Negative = automatic (default): half the swatch's
  /// smallest gap between elements (Swatch::min_gap), so that disjoint
  /// elements keep about their spacing; 0 = intersections only.
  double clearance = -1;
  /// Rings of triangles removed around the hits of a trimmed element, >= 0. Default 2.
  int trim_rings = 2;
  /// With resolve_crossings: a thread (not compact) that hits is first pushed
  /// over or under each crossing by a smooth bump in z (as a woven thread
  /// passes the one it crosses); kept so if that clears it, else trimmed.
  /// Default true.
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
  /// Refusals by reason (MergeResult::reason): an infeasible cut, cuts that
  /// opened no or different numbers of loops (or non-simple borders), a
  /// stitch that would open borders or break closedness, and (geometry)
  /// loop pairs too far apart or turned, or a stitch crossing itself.
  std::size_t refused_infeasible = 0, refused_loops = 0, refused_border = 0, refused_geometry = 0;
  /// Merges with nothing to stitch (MergeResult::coincident: the input
  /// element lies on the output one wherever they meet, e.g. the same
  /// chain-mail ring placed again); the output element is kept whole and the
  /// input one dropped, i.e. the element is completed from one side (section
  /// 2.7 keeps one side whole where an element lies in the overlap). Not
  /// counted in stitch_refused.
  std::size_t coincident = 0;
  /// Of those, the inputs whose end beyond the overlap, away from the output
  /// element, was kept closed at the overlap instead of dropped with the rest
  /// (MergeResult::capped_b of a coincident merge, with
  /// keep_cut_refused_inputs: once a patch's threads lie
  /// on the old ones, a thread continuing an old one past the overlap is a
  /// coincident merge, and dropping it whole left bare strips).
  std::size_t coincident_cut_added = 0;
  /// Refusals by the kind of MergeResult::reason (its text before the first
  /// ':' with every number replaced by N, e.g. "misaligned loops: normals",
  /// "cuts opened N and N loops"): the finer breakdown of the four counts above.
  std::map<std::string, std::size_t> refused_reasons;
  std::size_t out_replaced = 0, in_dropped = 0, in_added = 0;
  /// Refused input elements added as their closed kept parts
  /// (QuiltStepOptions::keep_cut_refused_inputs; not counted in in_dropped),
  /// and the elements (components) this added.
  std::size_t in_cut_added = 0, in_cut_components = 0;
  /// QuiltStepOptions::resolve_crossings: elements that would have hit an
  /// old one, and of them those dropped and those trimmed (into
  /// crossing_pieces pieces).
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

/// Section 2.4 alone: the translation of the swatch (bbox min at the corner
/// of a cell, shifted by less than half a cell if opt.subcell_levels > 0)
/// covering every P_out cell that minimises E(t) (eq. 3) over the output
/// vertices in P_out (at most opt.max_match_vertices, evenly subsampled);
/// among grid translations within opt.choice_tolerance of the best, one is
/// drawn with `rng`. Changes nothing else. With no output vertex in P_out every
/// cost is 0 (and one covering translation is drawn). With `near`, only its
/// grid translation (near->oi, near->oj) is refined (no draw; its dx, dy are
/// ignored): a local search, e.g. for the same texture seen in a slightly
/// turned frame. Throws InvalidInputError on an empty or too large P_out,
/// subcell_levels out of range or max_match_vertices < 1.
QuiltMatch match_swatch_placement(const Swatch& swatch, const TriangleDistance& swatch_tree, const QuiltGrid& grid,
                                  const std::vector<ElementMesh>& elements, const std::vector<char>& alive,
                                  std::mt19937_64& rng, const QuiltStepOptions& opt,
                                  const QuiltPlacement* near = nullptr);

/// Places the swatch where match_swatch_placement puts it (or at `given`, a
/// match computed by the caller for this grid and these elements, e.g. the
/// best of several frame rotations), so that it covers every
/// P_out cell; merges it into `elements` (entries of `alive` set to 0
/// for elements consumed, new elements appended with alive = 1; `z`
/// coordinates are the swatch's). Marks the covered grid cells (oi .. oi + sx
/// - 1, oj .. oj + sy - 1) processed. Throws as match_swatch_placement.
QuiltPlacement quilt_step(const Swatch& swatch, const TriangleDistance& swatch_tree, QuiltGrid& grid,
                          std::vector<ElementMesh>& elements, std::vector<char>& alive, std::mt19937_64& rng,
                          const QuiltStepOptions& opt, QuiltStepStats& stats, const QuiltMatch* given = nullptr);

}  // namespace surftex
