// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh quilting over a curved base mesh (Zhou et al. 2006, section 3.1).
//
// The planar grid of section 2.3 is replaced by the base mesh's triangles:
// 1. Seed: the unprocessed base triangle with the most processed triangles
//    among its vertex neighbours (ties: lowest face index).
// 2. Surface patch: breadth-first growth over edges from the seed, accepting a
//    triangle while its centroid lies within R of the seed's centroid (3D),
//    its normal within max_normal_angle_deg of the seed's, the patch stays a
//    topological disc (as in base_mesh_atlas.h) and has fewer than
//    max_patch_faces faces. R = patch_radius * (diagonal of the scaled
//    swatch's xy rectangle), so that the swatch placed anywhere around the
//    seed lies on the patch.
// 3. Flattening: LSCM (CGAL Surface_mesh_parameterization), mirrored if
//    needed, scaled so that the uv area equals the 3D area. If a patch face's
//    area distortion max(A_uv/A_3d, A_3d/A_uv) exceeds max_area_distortion
//    (the paper's factor 4), R is multiplied by 0.7 and the patch regrown
//    (at most 8 times); P_out shrinks with it.
// 4. Orientation: with Field::kUp the projection of `up` on the seed
//    triangle is mapped through the seed's flattening and the patch rotated so
//    that it points along +y of the swatch (the paper's guidance vector field,
//    here a projected constant vector). Where the projection is shorter than
//    transport_below (|up| = 1; near the field's poles) or with Field::kNone,
//    the +y directions of the earlier placements on the patch's faces are
//    projected on the seed's plane, averaged by area and used instead (a
//    discrete parallel transport from the neighbouring texture, our choice
//    for the field's singularities); with no earlier placement there, the
//    up projection if longer than 0.2, else the LSCM orientation.
//    With SurfaceQuiltOptions::smooth_field the guidance is instead a smooth
//    4-symmetric direction field over the whole base mesh, interpolated once
//    from the projected up (geometry/direction_field.h; Ray et al. 2009,
//    section 2.2): it has no poles where the projection vanishes, so no
//    transport is needed; of its cross at the seed the direction nearest the
//    projected up (else nearest the earlier placements') is taken.
//    Then, where earlier placements cover enough of the patch around the
//    seed, the frame is turned so that their +y directions, each mapped
//    through this patch's own flattening face by face, agree with +y modulo
//    a quarter turn over the whole overlap (area- and distance-weighted
//    circular mean; SurfaceQuiltOptions::align_to_overlap, issue #8 session
//    5, our choice): the field then orients only patches with no texture
//    around them, and the threads of neighbouring patches run along each
//    other instead of meeting at the angle by which the field and the
//    flattenings turn between two seeds. That turn is bounded by
//    align_field_max_deg (issue #8, session 6): unbounded, the first
//    patch's orientation was carried over the surface and the texture
//    drifted from the field (SurfaceQuiltResult::drift_deg_sum).
// 5. Frame: patch uv divided by the swatch scale (mesh units per swatch unit),
//    times the flattening's own scale around the seed (seed_scale), seed
//    centroid at the origin (a cell centre); a grid of cells (as in
//    mesh_quilting.h) over it; processed cells as in step 6. P_out = cells
//    within subpatch_radius (Chebyshev) of the seed cell whose centre lies on
//    the patch. Then the frame is turned about the seed centroid by the angle
//    (within +-rotation_max_deg of the field's direction, our choice: the
//    paper searches translations only) whose best translation matches the
//    texture already placed best (eq. 3, mean per vertex of P_out); the grid
//    and P_out turn with the frame (SurfaceQuiltOptions::rotation_max_deg).
// 6. Output elements with a vertex on a patch triangle are expressed in the
//    frame (vertices on other triangles: projected onto the plane of the
//    patch triangle with the nearest centroid, barycentric coordinates
//    extrapolated; of an element with a vertex farther than 2R from that
//    triangle or on a face at more than 60 degrees to it only the triangles
//    with three expressible vertices enter the step, the others are joined
//    back afterwards at their unchanged seam vertices, see
//    SurfaceQuiltResult::elements_partial), processed cells are those where
//    points of earlier footprints fall (kept per base face at sub-face
//    resolution), quilt_step (quilt_step.h, with sub-cell refinement of the
//    translation) runs, and new or changed
//    vertices are expressed again in local coordinates: base triangle +
//    barycentric coordinates of the orthogonal projection (the flattening's
//    triangle containing the frame point; outside the patch the triangle whose
//    extrapolated barycentric coordinates are least negative) + height (the
//    swatch z). Vertices that did not move keep their local coordinates
//    exactly. New elements whose vertex centroid falls outside the patch are
//    dropped (their base triangles are quilted later). Patch triangles whose
//    centroid lies in the placed swatch's footprint, and the seed, become
//    processed.
// At the end every location is moved onto the base face that contains it
// (walking across edges); elements with more than max_past_border of their
// vertices past a border of the base mesh are trimmed at the border, their
// cuts closed (trim_at_border), or removed (issue #8: our choice, the paper
// does not treat borders; see SurfaceQuiltResult::elements_past_border);
// elements with a stretched edge are removed (max_edge_stretch), and elements
// reaching above or below the output's z range are shifted into it
// (max_z_growth), so that every vertex has w in [0, 1] in the shell (issue #8).
// A refused stitch no longer drops the new patch's element whole: its end
// beyond the overlap is kept, closed at the cut
// (QuiltStepOptions::keep_cut_refused_inputs).
// Finally surface_quilt_to_texture expresses every vertex in the base mesh
// atlas's texture space (u, v, w), w = (z - z_min) / (z_max - z_min) of the
// swatch, ready for embed_in_shell (section 3.2); surface_quilt_displaced is
// the naive normal-displacement embedding (for comparison).
//
// Reads: the base mesh's points and faces (triangles, no garbage);
// surface_quilt_to_texture reads kCornerUV. Writes: kFaceElement on outputs.
// Throws: InvalidInputError (empty or non-triangle base, bad options, a
// swatch covering fewer than 3 cells), SolverError (LSCM failure on a patch
// that cannot be shrunk further).
#include <array>
#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "shell/quilt_step.h"
#include "shell/swatch.h"

namespace surftex {

struct SurfaceQuiltOptions {
  /// The paper's s: the swatch's larger xy side as a fraction of the base
  /// mesh's bounding-box diagonal; in (0, 10].
  double relative_size = 0.25;
  enum class Field { kNone, kUp };
  /// Guidance field aligning the grid (see header).
  Field field = Field::kUp;
  /// The constant "up" vector of Field::kUp (normalised here; non-zero).
  std::array<double, 3> up{0, 0, 1};
  /// Field::kUp: below this length of the projected up vector the patch's
  /// orientation is transported from the earlier placements (see header,
  /// step 4); in [0, 1], 0 = always the field (issue #8: 0.5).
  double transport_below = 0.5;
  /// Elements with more than this fraction of their vertices past a border
  /// of the base mesh are removed at the end; the others keep those vertices
  /// clamped onto the border (issue #8). In [0, 1]; 1 = keep all, clamped.
  /// Default 0: on the open cylinder of the tests, 0.1 kept 2 more elements
  /// and 303 more intersecting face pairs within elements (their tips).
  double max_past_border = 0;
  /// The elements past a border by more than max_past_border (issue #8,
  /// session 6): true = trimmed at the border (their triangles with a vertex
  /// past it removed, each remaining connected piece whose cut loops are
  /// small, at most two swatch heights across, closed by a fan over each
  /// loop and kept; see SurfaceQuiltResult::elements_trimmed); false =
  /// removed whole (the state before). Default true: on the 20 x 8 helix
  /// cylinder of the tests, removal threw away 2/3 of the quilt's faces
  /// (stitched threads are long, and every oblique one crosses an open end)
  /// and left 8.75% of the base bare, all of it along the ends.
  bool trim_at_border = true;
  /// New elements whose vertex centroid falls off the patch (step 6; issue
  /// #8, session 6): true = their part on the patch is kept (triangles with
  /// a vertex off the patch removed, the pieces closed as trim_at_border
  /// does; SurfaceQuiltResult::new_trimmed); false = dropped whole (the
  /// state before). The patch faces under the footprint are marked processed
  /// either way, so a dropped thread is never placed again there.
  /// Default false: on the 5K-face bunny (bench_quilt "trim_new", one run,
  /// load 5-6) it covered the bare stripe on the ear (bare area of the top
  /// height band 3.7% -> 0.55%, overall 1.0% -> 0.5%; 100 of 402 dropped
  /// elements kept trimmed), but the intersecting pairs
  /// between / within elements rose 83,070 -> 96,360 / 17,685 -> 21,887
  /// and 27 vertices left the shell.
  bool trim_new_to_patch = false;
  /// Rotation of each placement (issue #8; our choice, the paper's section 2.4
  /// searches translations only and section 3.1 takes the patch's frame from
  /// the guidance field): besides the field's direction (step 4) the frame is
  /// tried turned by +-rotation_step_deg, +-2 rotation_step_deg, ... up to
  /// +-rotation_max_deg about the seed centroid, the best translation found
  /// for each (section 2.4, eq. 3, over at most rotation_match_vertices
  /// output vertices), and the turn whose mean cost per vertex is lowest is
  /// kept (ties: the smaller turn). The field's direction at the seed and the
  /// direction the neighbouring texture actually runs in differ on curved
  /// surfaces (each earlier patch was aligned at its own seed, and the LSCM
  /// flattening turns the field by the surface's holonomy in between), so
  /// translated threads meet the old ones at an angle and cannot be stitched.
  /// Defaults: 15 degrees in steps of 5 (7 turns). rotation_max_deg in [0, 90],
  /// 0 = translations only (the state before); rotation_step_deg in (0, 90].
  double rotation_max_deg = 15.0;
  /// Orientation matched over the whole overlap (issue #8, session 5; our
  /// choice): before the turn search, the frame is turned so that the
  /// earlier placements' +y directions on the patch's faces (each mapped
  /// through this patch's flattening; weighted by area and by a Gaussian of
  /// the distance to the seed, sigma align_sigma swatch diagonals) agree with +y
  /// modulo a quarter turn (the weave's and chain mail's symmetry), when the
  /// covered faces hold at least align_min_overlap of that weight and the old
  /// directions agree (quarter-turn resultant >= 0.3). The field then only
  /// orients patches without earlier texture around them; the turn search
  /// (rotation_max_deg) runs around the aligned frame. Default true.
  bool align_to_overlap = true;
  /// The alignment's turn is bounded relative to the guidance field (issue
  /// #8, session 6): |turn| <= align_field_max_deg (degrees, in [0, 45]; 45
  /// = unbounded, the state before; 0 = the field alone). The frame before
  /// the turn follows the field at the seed, so this bounds each aligned
  /// placement's drift from the field (SurfaceQuiltResult::drift_deg_sum).
  /// Default 45: on the 5K-face bunny (bench_quilt, one run each, load
  /// 4-6) every bound traded the overlap jump for the drift: unbounded,
  /// drift 16.7 deg, jump 7.5 deg, 83,070 intersecting pairs between
  /// elements; 10 deg: drift 9.2, jump 10.0, 88.5K; with the smooth field,
  /// 10 deg: drift 6.6-6.9, jump 10.0-10.8, 88-93K; 20 deg: drift 12.1,
  /// jump 9.1, 97.6K; 25 deg: drift 12.8, jump 8.4, 89.6K. The bunny's curvature turns the field against the
  /// neighbours' threads by more than a rigid frame can follow (mean
  /// alignment turn 16.6 deg). On the helix cylinder, where a smooth field
  /// can be nearly parallel, the smooth field with a bound of 10 gives
  /// drift 1.5 and jump 0 (see the tests).
  double align_field_max_deg = 45;
  /// Field::kUp: the guidance field is a smooth 4-symmetric direction field
  /// over the base mesh (geometry/direction_field.h), interpolated from up
  /// projected on the faces where |projection| >= field_min_projection
  /// (constraints_from_constant_vector; in (0, 1]) and smoothed
  /// (DirectionFieldOptions::smoothing = field_smoothing, >= 0): it varies
  /// smoothly and has no poles where the projected up vanishes (the
  /// interpolation fills them; singularities emerge where the geometry
  /// needs them). false = the projected up at each seed, transported from
  /// the earlier placements where it is shorter than transport_below (the
  /// state before; transport_below is not used with the smooth field).
  /// Default false (the bunny figures at align_field_max_deg: no better
  /// there; unbounded with it: drift 17.9, jump 8.4, 93.7K pairs between
  /// elements vs 16.7, 7.5, 83.1K without, one run each).
  /// field_min_projection default 0.95, field_smoothing 1000: only where up
  /// lies nearly in the surface is the field prescribed, elsewhere it is the
  /// smoothest interpolation, and so turns little between seeds (on the
  /// helix cylinder at bound 10: drift 1.5, jump 0; with 0.3 and 1, every
  /// face's projected up kept: drift 6.3, jump 14.7).
  bool smooth_field = false;
  double field_min_projection = 0.95;
  double field_smoothing = 1000.0;
  /// In [0, 1]; see align_to_overlap. Default 0.1.
  double align_min_overlap = 0.1;
  /// Sigma of align_to_overlap's distance weight, in (scaled) swatch
  /// diagonals; > 0. Default 0.5.
  double align_sigma = 0.5;
  /// The turn search's range (as rotation_max_deg, which also bounds it) for
  /// patches aligned to the overlap; in [0, 90]. Default 0: on the 5K-face
  /// bunny the search (+-15 degrees, matched on P_out) turned 112 of 161
  /// aligned patches away again: overlap jump 10.4 degrees with it, 7.5
  /// without (11.9 before the alignment), stitched 103 vs 104, user CPU 88 s
  /// vs 68 s (one run each under load 4-5).
  double aligned_rotation_max_deg = 0;
  double rotation_step_deg = 5.0;
  /// Output vertices of P_out used to compare the turns (evenly subsampled;
  /// the chosen turn's translation is then matched with step.max_match_vertices); >= 1.
  int rotation_match_vertices = 150;
  /// Elements with an edge longer than this many times the swatch's longest
  /// edge (scaled; measured between the edge's feet on the base mesh, with
  /// the height difference) are removed at the end (issue #8, our choice,
  /// like the paper's removal of "visually-displeasing elements", section 4):
  /// a vertex moved beyond its patch and walked onto a distant face (across
  /// the gap between the bunny's ears) made long spikes. >= 0; 0 = keep all.
  /// Default 12: on the 5K-face bunny 53 elements go and the intersecting
  /// pairs within / between elements drop 30.2K -> 18.6K / 150K -> 101K;
  /// at 6, 122 went (10.5K / 76K) but so did threads on the ears, whose
  /// patches stretch the flattening most (bare ears in the render).
  double max_edge_stretch = 12.0;
  /// The output's z range (SurfaceQuilt::z_min, z_max: the shell's w = 0
  /// and 1) is the swatch's widened to the heights the quilt's vertices
  /// reached (the element deformations and stitches of sections 2.6-2.7 move
  /// vertices a little above or below the swatch), by at most this many
  /// swatch heights on each side; an element reaching beyond is shifted in z
  /// into it (squeezed if taller than it; counted in
  /// SurfaceQuiltResult::z_fitted_elements). Issue #8: with the swatch's
  /// range and nothing fitted, 8,240 of the bunny's vertices had w outside
  /// [0, 1] and were extrapolated out of the shell. In [0, 10]; 0 = the
  /// swatch's range. Default 0: the shell's thickness follows the range, and
  /// at 0.5 (the range reached its limit) the bunny's shell stretch rose from
  /// 1.037 to 1.129 (limit 1.05). (Clamping each vertex instead, as first
  /// tried, flattened whole threads lifted past the top into degenerate
  /// ribbons: 35K -> 58K intersecting pairs within elements.)
  double max_z_growth = 0;
  /// Scale of the patch frame (our choice; step 5): true = the flattening's
  /// own scale around the seed (3D area over uv area of the patch faces whose
  /// centroid lies within the P_out radius of the seed's), so that the
  /// texture already placed keeps its size where the new swatch is matched
  /// against it; false = the patch's mean (uv area = 3D area over the whole
  /// patch, the state before). LSCM is conformal but not area-preserving: a
  /// patch accepted at area distortion 4 is up to 2x longer or shorter
  /// around its seed than on average, and the old threads, seen at that
  /// scale, ran at other spacings than the swatch's. Default false: on the
  /// bunny (one run each, load 4-9) it did not stitch more (73 stitched with
  /// it, 94 without; the frame scale around the seeds ranged 0.86 - 1.57).
  bool seed_scale = false;
  /// Patch radius in swatch diagonals (scaled); > 0.
  double patch_radius = 1.0;
  /// Largest angle between a patch triangle's normal and the seed's (degrees); in (0, 180].
  double max_normal_angle_deg = 80.0;
  /// Largest number of triangles in a patch; >= 1.
  int max_patch_faces = 4000;
  /// Largest per-triangle area distortion of a patch's flattening (the paper's 4); > 1.
  double max_area_distortion = 4.0;
  /// Grid cell side in swatch units; 0 = max(l_in, w_in) / 10. >= 0.
  double cell_size = 0;
  /// P_out half-size in cells; 0 = a quarter of the swatch's smaller side in cells.
  int subpatch_radius = 0;
  /// The planar step's options (subcell_levels matters here: each patch's
  /// grid starts at its seed, not on the lattice of the texture already placed).
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
  /// Elements removed at the end for a stretched edge (SurfaceQuiltOptions::max_edge_stretch).
  std::size_t elements_stretched = 0;
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
  double seconds = 0, seconds_patch = 0, seconds_step = 0, seconds_turn = 0;
};

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
