// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh quilting over a curved base mesh (Zhou et al. 2006, section 3.1), as
// a staged driver (surface_quilting.cpp, class SurfaceQuilter; one function
// per stage). The planar grid of 2.3 is replaced by the base's triangles;
// until every base face is processed: find_seed, grow_and_flatten (a disc
// chart within R and max_normal_angle_deg, LSCM, regrown smaller past
// max_area_distortion), orient (guidance field onto the swatch's +y, swatch z
// along the base normal), align and search_turn (our additions), express,
// merge (quilt_step.h, 2.4-2.7); then finish (border trim, shards, misshapen
// and broken compact elements, crossings: an interlinked swatch's crossing
// rings moved clear first), refill bare faces, scatter whole
// compact elements into what stays bare, emit. surface_quilt_to_texture maps the quilt into the
// atlas's (u, v, w) for embed_in_shell (3.2). The stages in detail and the
// figures behind the defaults: docs/decisions/100-102-quilt-*.md.
//
// Reads: the base mesh's points and faces (triangles, no garbage);
// surface_quilt_to_texture reads kCornerUV. Writes: kFaceElement on outputs.
// Throws: InvalidInputError (empty or non-triangle base, bad options, a
// swatch covering fewer than 3 cells: the message names its axes, the cell
// size and --cell / --swatch-up), SolverError (LSCM failure on a patch that
// cannot be shrunk further).
#include <array>
#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "shell/quilting/quilt_step.h"
#include "shell/swatch.h"

namespace surftex {

struct SurfaceQuiltOptions {
  /// The paper's s: the swatch's larger xy side as a fraction of the base
  /// mesh's bounding-box diagonal; in (0, 10]. Default 0.25.
  double relative_size = 0.25;
  enum class Field { kNone, kUp };
  /// Guidance field aligning the swatch's +y (step 4). Default kUp.
  Field field = Field::kUp;
  /// The "up" of Field::kUp in the base mesh's coordinates (non-zero); the
  /// swatch's +y follows its projection on each seed's plane. Default +Y.
  std::array<double, 3> up{0, 1, 0};
  /// Below this length of the projected up (|up| = 1, near the field's poles)
  /// the orientation is transported from the earlier placements; in [0, 1],
  /// 0 = always the field. Default 0.5.
  double transport_below = 0.5;
  /// Fraction of an element's vertices past a border above which it is
  /// trimmed or removed (else clamped onto the border); in [0, 1]. Default 0.
  double max_past_border = 0;
  /// Elements past a border: true = trimmed, cut loops capped; false = removed. Default true.
  bool trim_at_border = true;
  /// New elements off the patch: true = their part on it kept; false = dropped. Default false.
  bool trim_new_to_patch = false;
  /// Turn search (step 5): frames turned by +-rotation_step_deg up to this, in
  /// [0, 90], 0 = translations only. Defaults 15 and 5.
  double rotation_max_deg = 15.0;
  /// Step 4b: turn the frame to match earlier placements over the overlap
  /// (weights: area and a Gaussian of align_sigma diagonals, default 0.5) when
  /// they hold align_min_overlap of the weight (in [0, 1], default 0.1). Default true.
  bool align_to_overlap = true;
  /// The alignment's turn bound against the guidance field, degrees in
  /// [0, 45]; 45 = unbounded. Default 45.
  double align_field_max_deg = 45;
  /// Field::kUp: guide by a smooth 4-symmetric field (direction_field.h) from
  /// up where |projection| >= field_min_projection (default 0.95), smoothing
  /// field_smoothing (default 1000). Default false.
  bool smooth_field = false;
  double field_min_projection = 0.95;
  double field_smoothing = 1000.0;
  double align_min_overlap = 0.1;
  double align_sigma = 0.5;
  /// The turn search's range for aligned patches, in [0, 90]. Default 0.
  double aligned_rotation_max_deg = 0;
  double rotation_step_deg = 5.0;
  /// Output vertices of P_out used to compare the turns; >= 1. Default 150.
  int rotation_match_vertices = 150;
  /// Shard bound (Zhou 4, "visually-displeasing elements"): an element edge
  /// longer, lifted, than this many swatch longest edges is cut out (threads) or
  /// its element removed, then refilled. >= 0, 0 = none. Default 3.
  double max_edge_stretch = 3.0;
  /// The same bound for threads (elements that are not compact: weaves), in
  /// swatch longest edges; 0 = max_edge_stretch. Looser: a thread is cut
  /// where it passes, and the cut loses cover that only the refill rounds
  /// give back (on thin parts they do not), while the embedding relaxes what
  /// stays over its 4 median edges (EmbedSurfaceQuiltOptions::
  /// max_edge_over_median). >= 0. Default 4 (decision 102, session 41).
  double max_thread_stretch = 4.0;
  /// Shape bound for compact elements (rings, pebbles): one that, lifted,
  /// spreads wider than this many times the swatch's largest compact element
  /// (merged with a neighbour, or deformed) is removed, then refilled. >= 0,
  /// 0 = none. Default 1.5.
  double max_shape_ratio = 1.5;
  /// Broken rings (Zhou 2.7 keeps elements whole or merges them): when every
  /// compact swatch element has a handle (tori, chain-mail rings), a compact
  /// output element with fewer handles than the fewest of them (a ring cut open
  /// at a patch border, a crossing or a refused merge: a C-shaped shard) is
  /// removed, then refilled. Default true.
  bool remove_broken_rings = true;
  /// Small pieces of compact elements (a pebble or ring cut at a patch
  /// border, a crossing or a refused merge, then capped: a crumpled cap more
  /// than an element): one with fewer faces than this fraction of the
  /// smallest compact swatch element is removed, then refilled. In [0, 1];
  /// 0 = none. Default 0.4 (decision 102, session 32).
  double min_piece_fraction = 0.4;
  /// When every swatch element is compact and without a handle (pebbles), a
  /// merge zips two cut loops only if they are at most this many loop radii
  /// apart along the cut normal (MergeOptions::max_loop_gap, 2 otherwise): two
  /// pebbles cut further apart were bridged by a neck of long edges. A ring's
  /// cut loops are cross-sections of its tube, as a thread's, and keep 2.
  /// >= 0; 0 = the merge's own max_loop_gap. Default 0.5 (decision 102,
  /// session 33).
  double blob_loop_gap = 0.5;
  /// After the loop, elements that cross when lifted are resolved exactly (the
  /// later yields), backing up QuiltStepOptions::resolve_crossings. Default true.
  bool resolve_crossings = true;
  /// A compact element that crosses when lifted is first moved and kept where
  /// that clears it, instead of removed: along the surface normal (0.1, then
  /// 0.2 swatch heights, up then down, within the swatch's height range), then
  /// along the surface (0.1, then 0.2 of its width, 8 directions); the
  /// scatter fill tries its elements 0.1 and 0.2 swatch heights higher and
  /// lower where they would cross.
  /// -1 = from the swatch: on when it has compact elements and its elements
  /// interlink (two of their bounding boxes overlap: chain mail), off for
  /// separate ones (tori, pebbles). 0 = off, 1 = on.
  int lift_crossing_rings = -1;
  /// Rounds re-quilting the base faces left bare (no element vertex within half
  /// the element spacing). In [-1, 8]; 0 = none; -1 = from the swatch: 3 when
  /// it has compact elements (the scatter fill then places them in what stays
  /// bare; more rounds reopen as many faces as they fill), 6 when it has none
  /// (threads: the rounds are their only fill and converge; 8 would cover
  /// more but take bunny5k past its 60 s). Default -1
  /// (decision 102, session 38). quilt_swatch_on_surface, which fills a
  /// thread swatch's bare spots again after the embedding, sets 3
  /// (kRefillRoundsBeforeEmbeddedFill, session 44).
  int refill_rounds = -1;
  /// Scatter fill after the refills: per face still bare, up to this many
  /// tries to place one compact swatch element (a ring, a pebble; for a
  /// weave a piece of a thread, scatter_thread_parts) there
  /// without crossing or stretching (four quarter turns, then moved by up to
  /// half the element spacing). In [0, 64]; 0 = none. Default 64: the chain
  /// mail's gaps are about a ring wide, and a ring finds its way into one in
  /// few of its tries (16 left 2.3-2.6% bare; decision 102, session 41).
  int scatter_attempts = 64;
  /// The scatter fill tries the faces with at least this many of the bare
  /// measure's four sample points bare (bare_samples), in [1, 4]. Default 1:
  /// the measure counts each bare point as a quarter of its face, and with 2
  /// the faces with one bare point, most of the chain mail's bare area, were
  /// never tried (koala + chain mail 2.13% -> 1.36% bare; decision 102,
  /// session 42). A swatch scattered alone keeps 2.
  int scatter_bare_samples = 1;
  /// A swatch with no compact element (a weave): the scatter fill places
  /// pieces of its threads instead, each thread cut into this many pieces
  /// along its length, the cuts capped (thread_scatter_pieces). In [0, 16];
  /// 0 = threads are not scattered. Default 4: a fish's fins, too small for
  /// whole threads, stayed bare (fish_blub + weave 6.9% -> 2.1% bare;
  /// decision 102, session 43).
  int scatter_thread_parts = 4;
  /// The scatter fill's stretch bound: no lifted edge of a scattered element
  /// longer than this many times its swatch length (a ring bent over a leg or
  /// an ear stretches on its outside). In [1, 10]. Default 2 (1.5 left the
  /// thin parts bare; decision 102, session 32).
  double scatter_max_stretch = 2.0;
  /// The scatter fill's patches take the faces whose normals are within this
  /// angle of the seed's (the quilting patches: max_normal_angle_deg), so a
  /// ring can bend over an ear's or a paw's rim; the stretch bound above
  /// keeps what the wider flattening distorts out. In [1, 180]. Default 120.
  double scatter_max_normal_angle_deg = 120.0;
  /// A swatch of at most this many elements, all compact (a pebble, a wing
  /// nut, a bowl of apples joined into one element by make_swatch, a loaf and
  /// a slice), is placed as whole copies by the scatter fill alone, in the
  /// field's orientation, not quilted: the quilting's matching needs
  /// neighbouring elements, and overlapping copies of so few were cut and
  /// merged into jagged or folded pieces (decision 102, session 35). In
  /// [0, 64]; 0 = always quilt. Default 3.
  int scatter_swatch_elements = 3;
  /// Then (scatter_swatch_elements): scatter passes while a pass still
  /// places an element, [1, 16] (default 3); the gap kept between copies, in
  /// the swatch's larger xy side, [0, 1] (default 0.05: the shell map moves
  /// copies that touch into each other); tries per bare face, [1, 64]
  /// (default 32), and the stretch bound, [1, 10] (default 2.5), in place of
  /// scatter_attempts and scatter_max_stretch: with no quilted patch around
  /// them, thin parts are covered only by bent copies (koala + rock_1 with
  /// 16 and 2: 17% of the lowest band bare; decision 102, session 35).
  /// The scatter fill does not try, in the same pass, a face whose centroid
  /// lies within this fraction of its jitter (half the element spacing) of a
  /// face whose tries all failed: they would try nearly the same places, and
  /// each try flattens a patch (armadillo_52k + rock_1: 36,000 faces tried,
  /// 128 placed, 166 of the scatter's 167 s in the failed ones). In [0, 1];
  /// 0 = every bare face. Default 0: at 0.25 armadillo took 51 s instead of
  /// 174 s, but dragon_25k + rock_1 left 6.8% of a band bare instead of 3.6%
  /// and cow + wingnut 51% instead of 26% (decision 102, session 45).
  double scatter_skip_near_failed = 0;
  int scatter_passes = 3;
  double scatter_clearance = 0.05;
  int scatter_alone_attempts = 32;
  double scatter_alone_max_stretch = 2.5;
  /// The output's z range may grow past the swatch's by this many swatch
  /// heights per side; elements beyond are shifted (squeezed) in. [0, 10], default 0.
  double max_z_growth = 0;
  /// Frame scale: true = the flattening's own at the seed; false = the patch mean. Default false.
  bool seed_scale = false;
  /// Patch radius in swatch diagonals (scaled); > 0. Default 1.
  double patch_radius = 1.0;
  /// Largest angle between a patch face's normal and the seed's (degrees); in (0, 180]. Default 80.
  double max_normal_angle_deg = 80.0;
  /// Largest number of faces in a patch; >= 1. Default 4000.
  int max_patch_faces = 4000;
  /// Largest per-face area distortion of a patch's flattening (the paper's 4); > 1.
  double max_area_distortion = 4.0;
  /// Grid cell side in swatch units; 0 = max(l_in, w_in) / 10. >= 0.
  double cell_size = 0;
  /// P_out half-size in cells; 0 = a quarter of the swatch's smaller side in cells.
  int subpatch_radius = 0;
  /// The planar step's options (quilt_step.h).
  QuiltStepOptions step;
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

/// Local coordinates of an output vertex (3.1): base face, barycentric (1 -
/// b1 - b2, b1, b2) >= -1e-9 of its orthogonal projection (vertices_around_face
/// order), height z in swatch units.
struct SurfaceQuiltVertex {
  int face = -1;
  double b1 = 0, b2 = 0;
  double z = 0;
};

/// The quilted texture in local coordinates.
struct SurfaceQuilt {
  std::vector<SurfaceQuiltVertex> vertices;
  std::vector<Tri> tris;
  std::vector<int> tri_element;  ///< element id per triangle, 0..elements-1
  int elements = 0;
  /// Per element: compact (ring, pebble), not a thread.
  std::vector<char> element_compact;
  double scale = 0;              ///< mesh units per swatch unit
  /// The output's z range (swatch units), holding every vertex.
  double z_min = 0, z_max = 0;
};

struct SurfaceQuiltResult {
  int steps = 0;
  int elements = 0;
  std::size_t faces = 0, vertices = 0;
  int patches_shrunk = 0;      ///< patches regrown smaller for distortion (step 3)
  int patches_transported = 0; ///< patches oriented by the transported direction (step 4)
  /// Patches turned by align_to_overlap and the sum of |turn| (deg).
  int patches_aligned = 0;
  double align_deg_sum = 0;
  /// Aligned patches: angle left to the old directions, in [0, 45] deg (sum / weight = mean).
  double align_residual_sum = 0, align_residual_weight = 0;
  /// Aligned patches whose turn was clamped to align_field_max_deg.
  int patches_align_bounded = 0;
  /// Drift from the guidance field (and drift_up_ from the projected up),
  /// folded into [0, 45] deg; sum / count = mean.
  double drift_deg_sum = 0, drift_up_deg_sum = 0;
  int drift_count = 0, drift_up_count = 0;
  double max_patch_distortion = 0;  ///< largest accepted per-triangle area distortion
  /// Range of the frame scale around the seeds (seed_scale; 1 when off).
  double seed_scale_min = 1, seed_scale_max = 1;
  std::size_t dropped_new = 0; ///< new elements dropped (centroid off the patch)
  std::size_t new_trimmed = 0; ///< of those, kept trimmed to the patch (SurfaceQuiltOptions::trim_new_to_patch)
  /// Elements touching a patch with a vertex not expressible in its frame.
  std::size_t elements_not_expressible = 0;
  /// Of those, entered with their inner part, and whose seam came back changed.
  std::size_t elements_partial = 0, seams_broken = 0;
  /// Elements removed past a border (max_past_border).
  std::size_t elements_past_border = 0;
  /// Elements trimmed at a border instead (SurfaceQuiltOptions::trim_at_border).
  std::size_t elements_trimmed = 0;
  /// Elements with a stretched edge at the finish (SurfaceQuiltOptions::max_edge_stretch), trimmed or removed.
  std::size_t elements_stretched = 0;
  /// Compact elements removed for spreading past max_shape_ratio.
  std::size_t elements_misshapen = 0;
  /// Broken rings removed (remove_broken_rings).
  std::size_t broken_rings_removed = 0;
  /// Small pieces of compact elements removed (min_piece_fraction).
  std::size_t small_pieces_removed = 0;
  /// Longest lifted element edge over the swatch's longest, scaled.
  double edge_stretch_max = 0;
  /// Of elements_not_expressible, those left out of the step entirely.
  std::size_t elements_not_expressed = 0;
  /// Elements that crossed an earlier one when lifted and yielded (SurfaceQuiltOptions::resolve_crossings).
  std::size_t crossings_resolved = 0;
  /// Of those, compact elements kept by a move off the crossing (lift_crossing_rings).
  std::size_t crossings_lifted_clear = 0;
  /// Of scatter_placed, elements placed higher or lower than the swatch has
  /// them (lift_crossing_rings).
  std::size_t scatter_lifted = 0;
  /// SurfaceQuiltOptions::lift_crossing_rings, resolved (0 or 1).
  int lift_crossing_rings = 0;
  /// Elements the finish tested for crossings, summed over the refill rounds
  /// (a round tests only what changed since the previous finish).
  std::size_t finish_elements_checked = 0;
  /// Output pieces left out for being smaller than a tenth of the swatch's smallest element.
  std::size_t fragments_removed = 0;
  /// Refill rounds allowed (SurfaceQuiltOptions::refill_rounds, resolved) and run.
  int refill_rounds = 0, refill_rounds_run = 0;
  /// Base faces reopened by refill_rounds.
  std::size_t faces_refilled = 0;
  /// Single compact elements placed by the scatter fill (scatter_attempts).
  std::size_t scatter_placed = 0;
  /// Bare faces the scatter fill tried (a patch flattened for each), and
  /// those it did not as they lay next to a failed one (scatter_skip_near_failed).
  std::size_t scatter_faces_tried = 0, scatter_faces_skipped = 0;
  /// The swatch's few compact elements were placed by the scatter alone
  /// (SurfaceQuiltOptions::scatter_swatch_elements): no quilting patch.
  bool scatter_only = false;
  /// Bare area fraction at the end: a quarter of a face's area for each of
  /// four sample points (centroid, corner triangles' centroids) with no
  /// element foot within half the swatch's element spacing (issue 17 item 4).
  double bare_fraction = 0;
  /// Elements and vertices fitted into the z range; its growth below / above (swatch units).
  std::size_t z_fitted_elements = 0, z_fitted_vertices = 0;
  double z_grown_below = 0, z_grown_above = 0;
  /// Placements turned by the turn search; sum of |turn| (deg).
  int patches_turned = 0;
  double turn_deg_sum = 0;
  /// Orientation jumps between overlapping placements, folded into [0, 45] deg,
  /// area-weighted (sum / area = mean; area_over10: area above 10 deg).
  double overlap_turn_sum = 0, overlap_area = 0, overlap_area_over10 = 0;
  QuiltStepStats stats;
  /// seconds_turn: the rotation search (part of seconds_step).
  double seconds = 0, seconds_patch = 0, seconds_step = 0, seconds_turn = 0, seconds_finish = 0;
};

/// Mesh units per swatch unit (3.1): the swatch's longer side becomes
/// relative_size times the diagonal of the base's bounding box (0 for a base
/// of zero size).
double surface_quilt_scale(const Mesh& base, const Swatch& swatch, double relative_size);

/// The default relative size (the CLI's, when --scale is not given): 0.25,
/// lowered for swatches of few large compact elements (a single pebble) so
/// that the median compact element's larger xy side is at most 1/16 of the
/// base's diagonal, i.e. 0.0625 * (swatch side / element side), and for
/// swatches of tall elements so that the median element's height (z, along
/// the normal; every element, compact or not) is at most 1/32: lifted along
/// the normals over curved ground an element splays in proportion to its
/// height, so a pebble as tall as it is wide gets smaller than a flat ring of
/// the same width, and standing chain-mail rings (0.148) than lying tori.
/// Threads (elements that are not compact: a weave's) are capped at 1/8 of
/// the diagonal in length: on curved ground a longer thread runs past the
/// patch that can express it and is cut into pieces (decision 102).
double default_surface_quilt_size(const Swatch& swatch);

/// The scatter fill's templates for a swatch of threads: each element that
/// is neither compact nor a ring (no handle) cut, along the longer side of
/// its xy box, into `parts` pieces of equal length (the triangles wholly
/// inside each, capped by trim_and_cap, which leaves out pieces of fewer
/// than 8 triangles or not closed after capping, and open elements), each
/// piece centred in xy.
std::vector<ElementMesh> thread_scatter_pieces(const Swatch& swatch, int parts);

/// The swatch's compact elements (rings, pebbles: is_compact_element), each
/// moved so that its xy centroid is the origin (swatch units, z kept): what
/// the scatter fills place one at a time.
std::vector<ElementMesh> compact_swatch_elements(const Swatch& swatch);

/// Whether the swatch is placed by the scatter fill alone, not quilted: at
/// most scatter_swatch_elements elements, all compact, and the fill on.
bool scattered_alone(const Swatch& swatch, const SurfaceQuiltOptions& opt);

/// The scatter fill's gap to elements already placed (swatch units):
/// scatter_clearance of the swatch's larger side for a swatch scattered
/// alone, else half the swatch's smallest gap between elements.
double scatter_gap(const Swatch& swatch, const SurfaceQuiltOptions& opt);

/// The thread pieces both scatter fills place, the quilt's and the embedded
/// quilt's (embedded_fill.h): thread_scatter_pieces when the swatch has no
/// compact element and the scatter fill runs (scatter_attempts,
/// scatter_thread_parts > 0), else none (both scatter fills place a swatch's
/// compact elements themselves, whole: compact_swatch_elements).
std::vector<ElementMesh> thread_fill_templates(const Swatch& swatch, const SurfaceQuiltOptions& opt);

/// Swatch copies needed to cover `base` at that scale: the base's area over the
/// scaled swatch's xy area (0 when the swatch has no area).
double surface_quilt_placements(const Mesh& base, const Swatch& swatch, double relative_size);

/// Quilts `swatch` over `base`; writes `out`. See the header comment.
SurfaceQuiltResult quilt_surface(const Mesh& base, const Swatch& swatch, SurfaceQuilt& out,
                                 const SurfaceQuiltOptions& opt = {});

/// Mesh whose vertex points are atlas texture coordinates (u, v, w) (kCornerUV
/// of the base faces interpolated; w as in the header); kFaceElement written.
/// Throws InvalidInputError if base lacks kCornerUV or a face index is out of range.
void surface_quilt_to_texture(const Mesh& base, const SurfaceQuilt& quilt, Mesh& out);

/// Naive embedding in the local frame of each vertex's base triangle (the
/// paper's figure 8, left): p = sum b_i x_i + w * height * n_f, n_f the unit
/// normal of the base face (mesh units). kFaceElement written.
void surface_quilt_displaced(const Mesh& base, const SurfaceQuilt& quilt, double height, Mesh& out);

/// The quilt as quilt_surface's finish tests it for crossings: each vertex at
/// (z - z0) * quilt.scale along the base's area-weighted vertex normals,
/// interpolated over its face and normalised (z0: the swatch's lowest z).
/// kFaceElement written. Throws InvalidInputError for a face index out of range.
void surface_quilt_lifted(const Mesh& base, const SurfaceQuilt& quilt, double z0, Mesh& out);

}  // namespace surftex
