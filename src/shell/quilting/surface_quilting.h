// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh quilting over a curved base mesh (Zhou et al. 2006, section 3.1), as
// a staged driver (surface_quilting.cpp, class SurfaceQuilter; one function
// per stage). The planar grid of section 2.3 is replaced by the base mesh's
// triangles; the loop runs until every base face is processed:
// 1. find_seed: the unprocessed base face with the most processed faces among
//    its vertex neighbours (ties: lowest index).
// 2-3. grow_and_flatten: a disc chart (geometry/disc_chart.h, shared with
//    base_mesh_atlas) grown breadth-first from the seed, a face accepted while
//    its centroid lies within R (patch_radius swatch diagonals, scaled) of the
//    seed's and its normal within max_normal_angle_deg of the seed's, with
//    fewer than max_patch_faces faces; flattened by LSCM. A patch whose
//    per-face area distortion exceeds max_area_distortion (the paper's 4) is
//    regrown with R * 0.7 (at most 8 times); P_out shrinks with it.
// 4. orient: the guidance field at the seed (the projection of `up` on the
//    seed's plane, or the smooth field, or where it vanishes the earlier
//    placements' directions transported) turned onto the swatch's +y; the
//    frame is the patch's uv over the swatch scale, seed centroid at the
//    origin. The swatch's z (its thin axis, Swatch::up_axis) is the height
//    along the base normal: elements stand on the surface, whatever the
//    world axes.
// 4b. align: where earlier placements cover enough of the patch, the frame is
//    turned so that their +y, mapped through this flattening, agree with +y
//    modulo a quarter turn over the whole overlap (our addition; bounded by
//    align_field_max_deg against the field).
// 5. search_turn: frames turned by steps of rotation_step_deg up to
//    rotation_max_deg, the best translation matched in each (eq. 3), the
//    cheapest kept (our addition; the paper searches translations only).
// 6. express: the output elements with a vertex on the patch in the frame
//    (vertices off it projected onto the nearest patch face's plane when that
//    face is within 60 degrees and 2R; elements with vertices that are not
//    enter with their inner part, joined back afterwards).
// 7. merge: quilt_step (quilt_step.h: sections 2.4-2.7, and
//    QuiltStepOptions::resolve_crossings: new elements that would pass
//    through placed ones are dropped or cut), then every new or changed
//    vertex expressed again in local coordinates: base face + barycentric
//    coordinates of its orthogonal projection + height z (swatch units).
//    New elements whose vertex centroid falls off the patch are dropped (in
//    refill rounds, or with trim_new_to_patch, their part on it kept);
//    patch faces under the footprint become processed.
// 8. finish: every location moved onto the base face containing it; elements
//    past a border trimmed there and capped (trim_at_border); shards (an edge
//    longer than max_edge_stretch times the swatch's longest, lifted to its
//    height) cut out or removed; elements that cross when lifted resolved
//    (resolve_crossings: the later one yields).
// 9. refill: the base faces left bare (no element vertex within half the
//    swatch's element spacing) are reopened and the loop runs again
//    (refill_rounds), then finish again.
// 10. emit: elements shifted in z into the output's z range (max_z_growth),
//    written in local coordinates.
// Finally surface_quilt_to_texture expresses every vertex in the base mesh
// atlas's texture space (u, v, w), w = (z - z_min) / (z_max - z_min), ready
// for embed_in_shell (section 3.2); surface_quilt_displaced is the naive
// normal-displacement embedding (for comparison). The measurements behind
// the defaults are in docs/decisions/100-102-quilt-*.md.
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
  /// The "up" vector of Field::kUp in the base mesh's own coordinates
  /// (normalised; non-zero): the swatch's +y follows its projection on each
  /// seed's tangent plane, while the swatch's z always stands on the base
  /// normal. Default +Y, glTF's up axis, which the project adopts for every
  /// method (a mesh modelled Z-up gives {0, 0, 1}).
  std::array<double, 3> up{0, 1, 0};
  /// Below this length of the projected up (|up| = 1, near the field's poles)
  /// the orientation is transported from the earlier placements; in [0, 1],
  /// 0 = always the field. Default 0.5.
  double transport_below = 0.5;
  /// Elements with more than this fraction of their vertices past a border of
  /// the base mesh are trimmed there (trim_at_border) or removed; the others
  /// keep those vertices clamped onto the border. In [0, 1]. Default 0.
  double max_past_border = 0;
  /// true: elements past a border are trimmed at it, each piece's cut loops
  /// (at most two swatch heights across) closed by fans; false: removed whole.
  /// Default true.
  bool trim_at_border = true;
  /// New elements whose vertex centroid falls off the patch: true = their part
  /// on the patch kept, cuts closed; false = dropped (their faces are quilted
  /// again by the refill rounds, which always keep the part). Default false.
  bool trim_new_to_patch = false;
  /// Turn search (step 5): besides the field's direction the frame is tried
  /// turned by +-rotation_step_deg ... up to +-rotation_max_deg; in [0, 90],
  /// 0 = translations only. Defaults 15 and 5 (in (0, 90]).
  double rotation_max_deg = 15.0;
  /// Step 4b: orientation matched over the whole overlap (turn modulo a
  /// quarter turn; weights: area and a Gaussian of sigma align_sigma swatch
  /// diagonals around the seed, > 0, default 0.5) when the covered faces hold
  /// at least align_min_overlap of the weight (in [0, 1], default 0.1) and
  /// the old directions agree. Default true.
  bool align_to_overlap = true;
  /// The alignment's turn bound against the guidance field, degrees in
  /// [0, 45]; 45 = unbounded. Default 45.
  double align_field_max_deg = 45;
  /// Field::kUp: guide by a smooth 4-symmetric field interpolated over the
  /// base (geometry/direction_field.h) from up projected where
  /// |projection| >= field_min_projection (in (0, 1], default 0.95), smoothing
  /// field_smoothing (>= 0, default 1000): no poles. Default false.
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
  /// The stretch bound (issue 17 item 2; the paper removes
  /// "visually-displeasing elements", section 4): an element edge longer,
  /// lifted to its height along the base's normals, than this many times the
  /// swatch's longest edge (scaled) marks a shard (a vertex placed off its
  /// patch by extrapolation, on a curved rim or across a gap); such triangles
  /// (and one ring) are cut out of threads and the pieces capped, compact
  /// elements with one are removed, and the space is refilled (refill_rounds).
  /// >= 0; 0 = no bound. Default 3 (SurfaceQuiltResult::edge_stretch_max
  /// reports what is left; docs/decisions/102-quilt-crossings-shards-coverage.md).
  double max_edge_stretch = 3.0;
  /// Interpenetration (issue 17 item 1): after the loop, the elements are
  /// lifted to their heights and tested against each other exactly; of two
  /// that cross, the later yields (compact ones removed, threads cut at the
  /// crossing, capped), and the space is refilled. This backs up
  /// QuiltStepOptions::resolve_crossings (each step, in the patch frame), which
  /// cannot see elements outside the patch. Default true.
  bool resolve_crossings = true;
  /// Rounds of refilling (issue 17 items 2 and 4): after the loop and the
  /// finish, the base faces left bare (no element vertex within half the
  /// swatch's element spacing, swatch_element_spacing) are quilted again, new
  /// elements off their patch kept trimmed to it. In [0, 8]; 0 = none. Default 3.
  int refill_rounds = 3;
  /// The output's z range is the swatch's widened to the heights the quilt
  /// reached, by at most this many swatch heights on each side; an element
  /// reaching beyond is shifted in z into it (squeezed if taller). In [0, 10];
  /// 0 = the swatch's range. Default 0.
  double max_z_growth = 0;
  /// Scale of the frame: true = the flattening's own scale around the seed;
  /// false = the patch's mean (uv area = 3D area). Default false.
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

/// Local coordinates of an output vertex (section 3.1): base face, barycentric
/// coordinates (1 - b1 - b2, b1, b2) >= -1e-9 of its orthogonal projection for
/// the face's vertices in vertices_around_face(halfedge(f)) order, height z in
/// swatch units. (A vertex made beyond its patch is moved, at the end, onto the
/// face containing it by walking across edges, projecting onto each face's
/// plane; at the mesh border it is clamped to the face.)
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
  /// Per element: compact (a ring, a pebble: is_compact_element in its frame), not a thread.
  std::vector<char> element_compact;
  double scale = 0;              ///< mesh units per swatch unit
  /// The output's z range (swatch units): the swatch's, widened to the
  /// vertices' heights (SurfaceQuiltOptions::max_z_growth); every vertex's z
  /// lies in it.
  double z_min = 0, z_max = 0;
};

struct SurfaceQuiltResult {
  int steps = 0;
  int elements = 0;
  std::size_t faces = 0, vertices = 0;
  int patches_shrunk = 0;      ///< patches regrown smaller for distortion (step 3)
  int patches_transported = 0; ///< patches oriented by the transported direction (step 4)
  /// Patches turned by the whole-overlap alignment (SurfaceQuiltOptions::align_to_overlap)
  /// and the sum of |turn| (degrees).
  int patches_aligned = 0;
  double align_deg_sum = 0;
  /// Over the aligned patches' covered faces (same weights): the angle left
  /// between the old directions and +y after the turn, folded into [0, 45]
  /// degrees; align_residual_sum / align_residual_weight is the mean, what
  /// the surface's curvature between two flattenings leaves to a rigid frame.
  double align_residual_sum = 0, align_residual_weight = 0;
  /// Aligned patches whose turn was clamped to align_field_max_deg.
  int patches_align_bounded = 0;
  /// Drift from the guidance field (a diagnostic): per placement, the angle
  /// between its +y at the seed and the guidance direction there (the
  /// smooth field's, or the projected up where at least 0.2 long), folded by
  /// a quarter turn into [0, 45] degrees; drift_deg_sum / drift_count is the
  /// mean. drift_up_*: the same against the projected up (where at least 0.2
  /// long) in either mode, to compare the two.
  double drift_deg_sum = 0, drift_up_deg_sum = 0;
  int drift_count = 0, drift_up_count = 0;
  double max_patch_distortion = 0;  ///< largest accepted per-triangle area distortion
  /// Range of the frame scale factor around the seeds (SurfaceQuiltOptions::seed_scale; 1 when off).
  double seed_scale_min = 1, seed_scale_max = 1;
  std::size_t dropped_new = 0; ///< new elements dropped (centroid off the patch)
  std::size_t new_trimmed = 0; ///< of those, kept trimmed to the patch (SurfaceQuiltOptions::trim_new_to_patch)
  /// Times an output element touching a patch had a vertex that cannot be
  /// expressed in the patch frame: off the patch, farther than 2R from (or at
  /// more than 60 degrees to) the nearest patch face.
  std::size_t elements_not_expressible = 0;
  /// Of those, the times the element entered the step with its inner part
  /// (triangles with three expressible vertices), and the times its seam did
  /// not come back from the step unchanged, so that the outer part became an
  /// element of its own.
  std::size_t elements_partial = 0, seams_broken = 0;
  /// Elements removed at the end because too much of them lies past a
  /// border of the base mesh (SurfaceQuiltOptions::max_past_border).
  std::size_t elements_past_border = 0;
  /// Elements trimmed at a border instead (SurfaceQuiltOptions::trim_at_border).
  std::size_t elements_trimmed = 0;
  /// Elements with a stretched edge at the finish (SurfaceQuiltOptions::max_edge_stretch), trimmed or removed.
  std::size_t elements_stretched = 0;
  /// The longest element edge of the output (lifted as the stretch bound
  /// measures it) over the swatch's longest edge, scaled.
  double edge_stretch_max = 0;
  /// Of elements_not_expressible, those with no triangle of three expressible
  /// vertices (left out of the step entirely: the final crossing check sees them).
  std::size_t elements_not_expressed = 0;
  /// Elements that crossed an earlier one when lifted and yielded (SurfaceQuiltOptions::resolve_crossings).
  std::size_t crossings_resolved = 0;
  /// Output pieces left out for being smaller than a tenth of the swatch's smallest element.
  std::size_t fragments_removed = 0;
  /// Base faces reopened by the refill rounds, and the bare area fraction at the end (SurfaceQuiltOptions::refill_rounds).
  std::size_t faces_refilled = 0;
  double bare_fraction = 0;
  /// Elements shifted or squeezed in z into the output's z range and their
  /// vertices, and how far the range was widened below / above the swatch's
  /// (swatch units; see SurfaceQuiltOptions::max_z_growth).
  std::size_t z_fitted_elements = 0, z_fitted_vertices = 0;
  double z_grown_below = 0, z_grown_above = 0;
  /// Placements turned away from the field's direction by the rotation
  /// search (SurfaceQuiltOptions::rotation_max_deg), and the sum of |turn|
  /// over all placements (degrees).
  int patches_turned = 0;
  double turn_deg_sum = 0;
  /// Orientation jumps (a diagnostic): over the base faces that a placement
  /// covers and an earlier one had covered, the angle between the two
  /// placements' +y directions on that face, folded by a quarter turn into
  /// [0, 45] degrees (the weave's and chain mail's symmetry), area-weighted:
  /// overlap_turn_sum / overlap_area is the mean jump; overlap_area_over10
  /// the area (mesh units^2, counted once per placement) where it exceeds 10 degrees.
  double overlap_turn_sum = 0, overlap_area = 0, overlap_area_over10 = 0;
  QuiltStepStats stats;
  /// seconds_turn: the rotation search (part of seconds_step).
  double seconds = 0, seconds_patch = 0, seconds_step = 0, seconds_turn = 0, seconds_finish = 0;
};

/// Mesh units per swatch unit (3.1): the swatch's longer side becomes
/// relative_size times the diagonal of the base's bounding box (0 for a base
/// of zero size).
double surface_quilt_scale(const Mesh& base, const Swatch& swatch, double relative_size);

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

}  // namespace surftex
