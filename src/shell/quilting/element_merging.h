// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Element merging (Zhou et al. 2006, section 2.7): two partially overlapping
// elements A (e.g. C_out) and B (C_in) are cut by graph cuts on their dual
// graphs and stitched into one connected element.
//
// Cut of A against B (cut_element): one node per triangle of A; for two
// triangles sharing the edge (v_i, v_j) an n-link of weight (eq. 7)
//   (1 + |v_i - v_j|)(1 + Dist(v_i, B) + Dist(v_j, B)).
// SOURCE (kept) with infinite weight: triangles of A whose centroid lies
// outside the overlap region. SINK (deleted) with infinite weight: all
// triangles around a vertex v of A (with Dist(v, B) <= match_distance and v in
// the overlap region, by default also past it: MergeOptions::delete_past_overlap) whose closest face f of B lies outside the overlap
// region, or has an edge-neighbour face with "no corresponding vertex in A".
// "Outside the overlap region" is made precise with a Region function and a
// side per element: region(p) = kOld (processed before this step, outside the
// new patch), kOverlap, kNew (not processed yet); A's own outside is its side
// (output elements: kOld, input elements: kNew, a merged element: both).
// Elements are kept whole, so an element can poke a little past the cell-
// rounded overlap region into the other side; such triangles are not forced
// either way. Where both infinite rules hit one triangle, keeping wins (the
// paper's rules would otherwise make every such cut infinite).
// The paper's correspondence is per vertex (a vertex of A and its closest
// face of B); with meshes of similar resolution most faces are nobody's
// closest face, so we read "face g has a corresponding vertex in A" in the
// continuous sense: the point q of A closest to g's centroid c is within
// match_distance, and c is (within MergeOptions::round_trip_edges mean edges
// of B) the point of B closest to q, i.e. some point of A has g as its
// closest face. This is what the rule is after: B continues where A does
// not. (A plain "c within match_distance of A" also covers B's faces past
// A's end, e.g. beyond a thread's end cap, so A's end was never deleted and
// tubes opened no loop.) By default an uncovered face counts only where B
// runs on uncovered into its own outside (MergeOptions::uncovered_must_escape):
// B's own end lying beside A is uncovered too, but A continues there.
// The cut of B is "found using the exact same approach"; to make the two cut
// paths meet (the paper only asks that they be close) the cut of B also gets
// finite guide links: a triangle of B within match_distance of A is pulled to
// SINK if its closest face of A was kept and to SOURCE if it was deleted, with
// weight guide_factor * the largest n-link weight (by default also to SINK if
// the closest face of any of its vertices was kept: MergeOptions::guide_by_vertices).
// After the two cuts (issue #8): islands are removed (kept components with
// no SOURCE-forced triangle deleted, deleted components with no SINK-forced
// triangle kept again), and where the cuts open different numbers of seams
// the deleted components behind seams with no partner (paired greedily by
// distance) are restored (our reading: the paper's merge always succeeds and
// does not discuss the case).
// Stitching: the boundary loops the cuts opened are paired (nearest
// centroids), each pair zipped by a triangle strip (advancing on the loop
// whose next diagonal is shorter, orientations consistent with both sides),
// then the merged element is deformed with eq. 5 constraints "average boundary
// points" (each loop vertex pulled to the midpoint with its nearest vertex on
// the paired loop; by default only across the loop pair's axis, see
// MergeOptions::average_across_axis_only), vertices outside the overlap
// region locked. A stitch that
// crosses itself more than its parts did is refused; before refusing, it is
// retried once with B's kept part trimmed back behind A's cut where the two
// cut ends overlap (MergeOptions::trim_overlapping_ends, our addition).
// Where neither cut opens a loop the elements coincide wherever they meet
// (MergeResult::coincident): nothing to stitch, the caller keeps one whole.
// Every graph cut goes through geometry/graph_cut.h.
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
  /// Guide links by vertices (our addition): a triangle
  /// of B is pulled to SINK if its centroid's closest face of A or the
  /// closest face of any of its vertices (within match_distance) was kept,
  /// so that B's kept part starts just past A's cut (a gap of at most one
  /// row of B's triangles) instead of reaching up to a third of a row behind
  /// it. With the centroid alone the two kept ends overlapped by about a
  /// hundredth of a thread spacing on the planar weave: tubes of slightly
  /// different radius running through each other, 56% of the refusals
  /// ("self-intersecting stitch"). false = the centroid only.
  bool guide_by_vertices = true;
  /// Round-trip tolerance of "face g of B has a corresponding vertex in A"
  /// (see the header), in mean edge lengths of B; > 0. Was 0.5: with rows of
  /// B about one edge long, the row just past A's end then often counted as
  /// covered, no vertex of A's end was forced to SINK and A was not cut
  /// ("cuts opened 0 and 1 loops").
  double round_trip_edges = 0.25;
  /// The SINK rule's "adjacent face with no corresponding vertex in A" only
  /// for uncovered faces whose connected uncovered region of B reaches B's
  /// own outside region (our reading of section 2.7):
  /// B continues past A there. The start of B lying along A (its end cap
  /// beside A's middle) is uncovered too, but A continues there; deleting A
  /// at B's start as well as at its own end put A's cut at the far side of
  /// the overlap from B's ("misaligned loops: centroids ... along").
  bool uncovered_must_escape = true;
  /// Apply the SINK rule of section 2.7 also to A's vertices that poke past
  /// the overlap region into the other side (not A's own outside, not off
  /// the grid), not only to those in the overlap.
  /// Elements are kept whole, so an old thread can end a little past the
  /// processed cells; its end then had no infinite SINK link, the cut kept
  /// all of A and the merge was refused ("cuts opened 0 and 1 loops",
  /// "misaligned loops" on cuts through odd places). false = overlap only.
  bool delete_past_overlap = true;
  /// mu of the stitching deformation (eq. 5); > 0.
  double mu = 1.0;
  /// The stitching constraints "average boundary points" (section 2.7)
  /// averaged only across the axis of each loop pair (the line from A's cut
  /// towards B's kept part, from the loops' area vectors): each loop vertex
  /// moves halfway to its nearest vertex of the paired loop sideways but
  /// keeps its place along the axis, so that the zip strip bridges the gap
  /// between the cuts with its width. Our reading: averaged in full, two
  /// facing loops a fraction of a row apart are pulled onto one another and
  /// the strip between them collapses into slivers that cross each other
  /// (the paper's mesh merging [Yu et al. 2004] fuses the two boundaries
  /// instead of bridging them). false = full averages.
  bool average_across_axis_only = true;
  /// Geometric test of every zipped loop pair (section 2.7 stitches two
  /// elements whose cut paths are "close to each other"; the paper has no
  /// threshold, these are ours): the loops' centroids at most
  /// `max_loop_offset` x the larger loop radius apart sideways (across the
  /// cut normal) and twice that along it, their mean radii within
  /// a factor `max_loop_radius_ratio`, and their normals (Newell area vectors,
  /// B's reversed as zipped) at most `max_loop_angle_deg` apart. 0 disables a
  /// test. Loops that fail are threads of different elements or of one
  /// element misaligned across a patch seam: zipping them kinks the element
  /// and makes it cross itself.
  double max_loop_offset = 1.0;
  double max_loop_radius_ratio = 2.0;
  double max_loop_angle_deg = 60.0;
  /// Refuse a stitch whose result (after the stitching deformation) has more
  /// self-intersecting face pairs (exact predicates) than the two kept parts
  /// had: a zip that folds over or runs through the element.
  bool refuse_self_intersecting = true;
  /// When a stitch is refused for crossing itself, retry once with B's kept
  /// part trimmed back behind A's cut where the two cut ends overlap (B's
  /// kept triangles within two loop radii of a loop pair's axis whose
  /// centroid lies less than half a mean edge of B in front of A's loop):
  /// the ends then abut and the zip bridges a gap. Our addition (issue #8:
  /// on curved surfaces most stitches refused for crossing themselves had
  /// well-aligned loops whose kept parts already crossed each other).
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
  /// Refused because neither cut opened a loop: wherever the two elements
  /// meet they coincide (within match_distance) and neither continues past
  /// the other there, so there is nothing to stitch (e.g. one chain-mail ring
  /// seen by two overlapping patches); the caller keeps one of them whole.
  bool coincident = false;
  /// Stitched after trimming B's overlapping cut end (MergeOptions::trim_overlapping_ends).
  bool trimmed = false;
  /// When refused with both cuts feasible and B closed (coincident too, then
  /// only the components with at most a quarter of their vertices within
  /// the match distance of A, i.e. an end running on past A):
  /// B's kept part (trimmed back as in MergeOptions::trim_overlapping_ends
  /// when the stitch crossed itself) restricted to the triangles whose
  /// centroid lies in B's own outside region (side_b, e.g. kNew: not in the
  /// overlap, where A and the other old elements stay), split into connected
  /// components; the components with exactly one cut loop (an element's end,
  /// e.g. a thread running on past the overlap; not an arc of a ring or a
  /// middle piece) and at least a tenth of B's triangles are kept, the loop
  /// closed by a fan around its centroid, so that each is closed again. Empty if nothing or everything of B is
  /// kept. The caller may add these instead of dropping B (issue #8:
  /// dropping a whole refused thread left bare strips; keeping B's whole
  /// kept part, overlap included, put it on top of misaligned old threads:
  /// see QuiltStepOptions::keep_cut_refused_inputs).
  std::vector<ElementMesh> capped_b;
};

/// Cuts A and B and stitches them. Refuses (stitched = false, reason set,
/// `merged` empty) when a cut is infeasible, the cuts open different numbers of
/// loops or none, the result would have more border edges than A and B had
/// (so elements closed in the swatch stay closed), or would not be manifold
/// (a directed edge used twice, a pinched vertex: possible when A or B has
/// borders of its own, e.g. the inner part of a long element on a surface),
/// when a loop pair fails the geometric test (MergeOptions::max_loop_offset
/// and the next two; reason starts with "misaligned") or when the stitched
/// element crosses itself more than its parts did (reason starts with
/// "self-intersecting"). Throws as cut_element.
MergeResult merge_elements(const ElementMesh& a, Side side_a, const ElementMesh& b, Side side_b, const RegionFn& region,
                           const MergeOptions& opt = {});

}  // namespace surftex
