// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Final embedding of a surface quilt (Zhou et al. 2006, section 3.2, applied
// to the output of quilt_surface, section 3.1): builds the base mesh's
// multi-chart texture atlas (base_mesh_atlas.h), expresses the quilt in that
// texture space (surface_quilt_to_texture), builds the shell
// (shell_space.h) of thickness shell_height * (swatch height * quilt scale),
// minimises its stretch (shell_map_minimize_stretch, eq. 8-9) and maps every
// vertex through the shell map into 3D, with the exact
// self-intersection count of the result split into pairs within one element
// and pairs between two elements, and the count of embedded vertices outside
// the geometric shell (embed_outside_shell.h).
//
// A vertex maps through the tet containing its (u, v, w) (3.2); our choices:
// its barycentrics are clamped onto its face first; the tet is found by
// walking from its own prism within its chart; one in no tet is extrapolated
// by its own prism's best tet and counted (outside_below / above / uv). Why,
// with the figures: docs/decisions/104-shell-space.md.
// Reads: the base mesh's points (a copy gets the atlas; `base` is unchanged).
// Writes: `out` (cleared first): the embedded quilt, kFaceElement.
// Throws: InvalidInputError (bad options), and what the stages throw
// (TopologyError, SolverError from the atlas and the shell).
#include <cstddef>
#include <vector>

#include "geometry/base_mesh_atlas.h"
#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "shell/embed_in_shell.h"
#include "shell/embed_outside_shell.h"
#include "shell/shell_stretch.h"
#include "shell/quilting/embedded_fill.h"
#include "shell/quilting/surface_quilting.h"

namespace surftex {

struct EmbedSurfaceQuiltOptions {
  /// Shell thickness in units of the scaled swatch height (z_max - z_min) * scale; > 0.
  double shell_height = 1.0;
  /// The base mesh atlas; its normal cone defaults to 30 degrees here (the
  /// atlas' own is 50): the shell keeps the atlas' distortion (decision 104).
  BaseMeshAtlasOptions atlas = [] {
    BaseMeshAtlasOptions a;
    a.max_normal_angle_deg = 30.0;
    return a;
  }();
  MinimizeStretchOptions stretch;
  /// Run the exact self-intersection count on the embedded mesh.
  bool check_self_intersections = true;
  /// Issue 17 item 1: faces still intersecting after the embedding are resolved
  /// before the count (the later element yields: compact ones removed, others
  /// cut and capped; what still crosses after crossing_trim_rounds such
  /// rounds is removed whole, so none is left). Default true.
  bool resolve_crossings = true;
  /// Before the first resolution round: an element other than a compact one
  /// that crosses itself in more pairs than swatch_self_crossings (a thread
  /// the shell map crumpled where it was squashed in the quilt) is smoothed
  /// where it crosses until it no longer does (smooth_out_crossings), and
  /// kept whole; one that still crosses is resolved as below. Default true
  /// (decision 102, session 37: bunny + weave 2.95% -> 2.15% bare).
  bool untangle_folds = true;
  /// Rounds that cut and cap crossing threads before the removal; 0..8, default 3.
  int crossing_trim_rounds = 3;
  /// The swatch's own crossings (Swatch::element_self_crossings): an element
  /// with at most this many self-intersecting pairs within itself keeps them
  /// (every copy of a swatch element carries the element's); one with more is
  /// resolved as above. quilt_swatch_on_surface sets it; default 0.
  std::size_t swatch_self_crossings = 0;
  /// The swatch's elements (swatch_element_meshes; quilt_swatch_on_surface
  /// sets them): a compact element of the quilt with the same triangles as one
  /// of these (a whole copy, vertices numbered in order of first use) is placed
  /// by the affine map that best fits the shell map at its vertices (least
  /// squares), lifted out of the base, not by each vertex's own image
  /// (place_whole_copies_affinely). Empty (default): every vertex through the map.
  std::vector<ElementMesh> whole_copy_sources;
  /// The shard bound held again on the embedded elements, mesh units (0 =
  /// none, the default): an element with a longer edge (the shell map
  /// stretches what was within the bound lifted) is removed if compact, else
  /// those triangles are cut out and the pieces capped, before the crossings
  /// are resolved (whose cut pieces are held to it too). quilt_swatch_on_surface
  /// sets SurfaceQuiltOptions::max_edge_stretch times the swatch's longest
  /// edge, scaled.
  double max_edge = 0;
  /// The shard bound also in the output's own terms (issue 17's shard: an
  /// element edge longer than 4 median edges of the output): when max_edge
  /// > 0, the embedded elements' median edge times this where that is lower,
  /// but not below min_edge_bound (a swatch whose own longest edge is many
  /// median edges, a CAD part, keeps its elements). 0 = none. Default 4
  /// (decision 102, session 41).
  double max_edge_over_median = 4.0;
  /// The floor of that bound, mesh units; quilt_swatch_on_surface sets 1.5
  /// times the swatch's longest edge, scaled. Default 0.
  double min_edge_bound = 0;
  /// An element over the bound is first relaxed (its long edges shortened by
  /// moving their ends, the excess spread to its shorter edges) and kept when
  /// that brings it within; cut or removed otherwise. Default true.
  bool relax_stretched = true;
  /// Cap centres moved back to the middle of their caps (recentre_fans) on the
  /// embedded elements, before the shard bound and the crossings. Default true.
  bool recentre_caps = true;
  /// Last: pieces placed into what the output leaves bare (embedded_fill.h;
  /// no templates, the default: none). quilt_swatch_on_surface sets the
  /// templates (compact_swatch_elements placed rigidly, else
  /// thread_fill_templates), scale, heights and radius; the shard bound is
  /// held to embedded_edge_bound too.
  EmbeddedFillOptions fill;
  /// Check every embedded vertex against the geometric shell (embed_outside_shell.h).
  bool measure_outside_shell = true;
  OutsideShellOptions outside_shell;
  ProgressCallback progress;
};

struct EmbedSurfaceQuiltResult {
  BaseMeshAtlasResult atlas;
  MinimizeStretchResult stretch;  ///< stretch_before / stretch_after (normalised eq. 9)
  std::size_t tets = 0, clamped_vertices = 0;
  std::size_t unfolded_vertices = 0;  ///< base vertices moved to undo a fold (shell_space.h)
  double shell_height = 0;        ///< nominal absolute shell height (mesh units)
  EmbedInShellResult embed;       ///< outside vertices, self-intersecting pairs (all)
  /// Outside vertices by cause: w below 0 / above 1, or (u, v, w) in no tet of
  /// its chart (0 unless an invariant broke).
  std::size_t outside_below = 0, outside_above = 0, outside_uv = 0;
  /// Quilt vertices whose barycentric coordinates in their base face were
  /// negative (quilt_surface settles locations up to -1e-9) and were clamped
  /// onto the face, and the most negative such coordinate (0 if none).
  std::size_t locations_clamped = 0;
  double most_negative_barycentric = 0;
  /// The self-intersecting pairs split by element: both faces in one element
  /// (what the swatch's elements may already have, and deformation adds) and
  /// faces of two different elements (overlapping elements: a quilting defect).
  std::size_t self_intersections_within = 0, self_intersections_between = 0;
  /// Elements that crossed themselves and were smoothed out (untangle_folds).
  std::size_t elements_untangled = 0;
  /// Elements cut or removed by EmbedSurfaceQuiltOptions::resolve_crossings.
  std::size_t crossing_elements = 0;
  /// Of those, removed whole because they still crossed after the trimming rounds.
  std::size_t crossing_elements_removed_last = 0;
  /// Elements that kept their own crossings (EmbedSurfaceQuiltOptions::swatch_self_crossings),
  /// counted at the last check.
  std::size_t elements_self_crossing_kept = 0;
  /// Whole copies placed by one affine map (EmbedSurfaceQuiltOptions::whole_copy_sources).
  std::size_t elements_placed_affine = 0;
  /// Elements with an embedded edge over max_edge, removed or cut.
  std::size_t elements_stretched_embedded = 0;
  /// The bound held on the embedded elements: max_edge, or max_edge_over_median
  /// median edges when that is lower (mesh units; 0 = none), and that median.
  double embedded_edge_bound = 0, embedded_median_edge = 0;
  /// Elements over the bound brought within it by relax_stretched (not cut).
  std::size_t elements_relaxed_embedded = 0;
  /// Cap centres moved by recentre_caps.
  std::size_t caps_recentred = 0;
  /// The fill of the embedded quilt's bare faces (EmbedSurfaceQuiltOptions::fill).
  EmbeddedFillResult fill;
  /// Elements in `out` (the quilt's, less those the shard bound and the
  /// crossing resolution removed, plus the pieces they cut and the fill's).
  std::size_t elements = 0;
  /// Vertices the shell map put outside the geometric shell (the union of the
  /// shell's 3D tets; embed_outside_shell.h), with how far; empty unless measured.
  OutsideShellResult outside_shell;
  /// The same check on the vertices of the copies placed affinely (after
  /// their lift): above the shell's top is by design (the copy keeps its
  /// height where the shell is thinner), below it they dip into the base.
  OutsideShellResult affine_outside_shell;
  bool outside_shell_measured = false;
  double seconds_atlas = 0, seconds_shell = 0, seconds_stretch = 0, seconds_map = 0, seconds_embed = 0;
};

/// Embeds `quilt` (made by quilt_surface on `base`) into the shell over `base`; see the header comment.
EmbedSurfaceQuiltResult embed_surface_quilt(const Mesh& base, const SurfaceQuilt& quilt, Mesh& out,
                                            const EmbedSurfaceQuiltOptions& opt = {});

}  // namespace surftex
