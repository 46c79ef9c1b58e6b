// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Element merging (Zhou et al. 2006, section 2.7): two partially overlapping
// elements A (e.g. C_out) and B (C_in) are cut by graph cuts on their dual
// graphs and stitched into one connected element.
//
// Cut of A against B (cut_element): a graph cut on A's dual graph with the
// n-links of eq. 7, (1 + |v_i - v_j|)(1 + Dist(v_i, B) + Dist(v_j, B));
// SOURCE: A's triangles in A's own outside (a Region function and a Side per
// element make "outside the overlap" precise); SINK: triangles around a vertex
// of A whose closest face of B is outside or borders a face with "no
// corresponding vertex in A" (read in the continuous sense, round-trip test).
// Keeping wins where both infinite rules hit. The cut of B is found the same
// way plus finite guide links towards A's cut, so that the cut paths meet.
// Islands are then removed and unpaired seams restored (our reading). Stitch:
// the opened loops paired by nearest centroids, zipped by a triangle strip,
// then deformed (eq. 5, "average boundary points") with vertices outside the
// overlap locked; a stitch crossing itself more than its parts is refused
// (after one retry with B's overlapping end trimmed). Every graph cut goes
// through geometry/graph_cut.h. Each rule and why it reads the paper so:
// docs/decisions/103-element-merging.md.
#include <functional>
#include <string>
#include <vector>

#include "shell/element_mesh.h"

namespace surftex {

/// Where a point lies with respect to the current quilting step.
enum class Region { kOld = -1, kOverlap = 0, kNew = 1, kNone = 2 };
using RegionFn = std::function<Region(const P3&)>;
/// Which outside region an element owns: kOld (output), kNew (input), kOverlap = both.
using Side = Region;

struct MergeOptions {
  /// Distance under which surfaces count as corresponding (mesh units); 0 =
  /// automatic: 3 x the mean edge length of A and B. >= 0.
  double match_distance = 0;
  /// Weight of B's guide links, in units of the largest n-link weight; >= 0.
  double guide_factor = 100;
  /// Guide links also by the closest faces of B's vertices, not only of its
  /// centroids (our addition), so that B's kept part starts just past A's cut.
  /// false = the centroid only. Default true.
  bool guide_by_vertices = true;
  /// Round-trip tolerance of "face g of B has a corresponding vertex in A", in
  /// mean edge lengths of B; > 0. Default 0.25.
  double round_trip_edges = 0.25;
  /// The SINK rule's "no corresponding vertex" only for uncovered faces of B
  /// whose uncovered region reaches B's own outside (our reading of 2.7). Default true.
  bool uncovered_must_escape = true;
  /// Apply the SINK rule also to A's vertices past the overlap into the other
  /// side, not only to those in it. false = overlap only. Default true.
  bool delete_past_overlap = true;
  /// mu of the stitching deformation (eq. 5); > 0.
  double mu = 1.0;
  /// "Average boundary points" (2.7) only across each loop pair's axis, so the
  /// zip strip bridges the gap between the cuts (our reading). false = full
  /// averages. Default true.
  bool average_across_axis_only = true;
  /// Geometric test of every zipped loop pair (ours; the paper asks only that
  /// cut paths be "close"): centroids at most max_loop_offset x the larger radius
  /// apart sideways and max_loop_gap x it along the cut normal, radii within
  /// max_loop_radius_ratio, normals at most max_loop_angle_deg apart. 0
  /// disables a test. Defaults 1, 2, 2, 60.
  double max_loop_offset = 1.0;
  double max_loop_gap = 2.0;
  double max_loop_radius_ratio = 2.0;
  double max_loop_angle_deg = 60.0;
  /// Refuse a stitch whose result (after the stitching deformation) has more
  /// self-intersecting face pairs (exact predicates) than the two kept parts
  /// had: a zip that folds over or runs through the element.
  bool refuse_self_intersecting = true;
  /// On a refused self-crossing stitch, retry once with B's kept part trimmed
  /// back behind A's cut where the cut ends overlap (our addition). Default true.
  bool trim_overlapping_ends = true;
};

struct ElementCut {
  std::vector<char> keep;  ///< per triangle of A: 1 = kept (SOURCE side)
  double cost = 0;         ///< sum of eq. 7 weights of the n-links cut
  bool feasible = false;   ///< false if the infinite links conflict
  std::size_t forced_keep = 0, forced_delete = 0;  ///< triangles with infinite links
  /// Per triangle: +1 infinite link to SOURCE, -1 to SINK, 2 both (conflict), 0 none.
  std::vector<signed char> terminal;
};

/// Graph cut of A against B (see header). `b_keep` (optional, per triangle of
/// B) adds the guide links. match_distance 0 = automatic. Throws
/// InvalidInputError for round_trip_edges <= 0 or match_distance < 0.
ElementCut cut_element(const ElementMesh& a, Side side_a, const ElementMesh& b, Side side_b, const RegionFn& region,
                       const MergeOptions& opt = {}, const std::vector<char>* b_keep = nullptr);

/// Sum of eq. 7 weights over the edges of A whose two triangles have different
/// `keep` labels (the cost of any labelling, for comparisons).
double cut_cost(const ElementMesh& a, const ElementMesh& b, const std::vector<char>& keep);

struct MergeResult {
  bool stitched = false;   ///< true: `merged` is the stitched element
  ElementMesh merged;
  int loops = 0;           ///< boundary loops zipped
  double cost_a = 0, cost_b = 0;
  std::string reason;      ///< why stitching was refused (stitched == false)
  /// Refused because neither cut opened a loop: the elements coincide where they
  /// meet; the caller keeps one whole.
  bool coincident = false;
  /// Stitched after trimming B's overlapping cut end (MergeOptions::trim_overlapping_ends).
  bool trimmed = false;
  /// When refused with both cuts feasible and B closed: B's kept part in its
  /// own outside, split into components; those with exactly one cut loop and at
  /// least a tenth of B's triangles, the loop capped by a fan. The caller may
  /// add them instead of dropping B (QuiltStepOptions::keep_cut_refused_inputs).
  std::vector<ElementMesh> capped_b;
};

/// Cuts A and B and stitches them. Refuses (stitched = false, reason set,
/// `merged` empty) on an infeasible cut, unequal or no loops, more border
/// edges, a non-manifold result, a misaligned loop pair (reason "misaligned")
/// or more self-intersections than its parts ("self-intersecting"). Throws as
/// cut_element.
MergeResult merge_elements(const ElementMesh& a, Side side_a, const ElementMesh& b, Side side_b, const RegionFn& region,
                           const MergeOptions& opt = {});

}  // namespace surftex
