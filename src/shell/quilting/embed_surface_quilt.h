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
// Mapping a vertex (section 3.2: a texture point goes through the tet that
// contains it, by barycentric coordinates): its (u, v) is its face's
// barycentric combination of the face's atlas corners, w = (z - z_min) /
// (z_max - z_min). Our choices:
// * The barycentric coordinates are clamped onto the face first (negatives to
//   0, renormalised): quilt_surface accepts locations down to -1e-9, and on a
//   chart-border edge such a (u, v) lies in the atlas gap next to the chart,
//   in no tet (on the 6.6K-face bunny_6k quilt, 1,907 vertices; they were
//   extrapolated to within 1.3e-10 mesh units of where the clamped point maps).
// * The containing tet is found by walking from the vertex's own prism
//   (ShellMap::locate_texture_from), so it is always a tet of the face's own
//   chart: after the stretch minimisation moved offset-surface (u, v), it may
//   be a tet of a neighbouring prism. Every point of a chart's texture slab
//   (its uv region x [0, 1]) lies in some tet of the chart: the minimisation
//   keeps every texture tet positive and the lateral boundary fixed
//   (shell_stretch.h), so the chart's tets still tile the slab.
// * A vertex found in no tet (w outside [0, 1]) is extrapolated by the affine
//   map of the tet of its own prism with the largest smallest barycentric
//   coordinate, not by the nearest tet anywhere (which can be in another
//   chart: long spikes); it is counted in outside_below / above / uv.
// Reads: the base mesh's points (a copy gets the atlas; `base` is unchanged).
// Writes: `out` (cleared first): the embedded quilt, kFaceElement.
// Throws: InvalidInputError (bad options), and what the stages throw
// (TopologyError, SolverError from the atlas and the shell).
#include <cstddef>

#include "geometry/base_mesh_atlas.h"
#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "shell/embed_in_shell.h"
#include "shell/embed_outside_shell.h"
#include "shell/shell_stretch.h"
#include "shell/quilting/surface_quilting.h"

namespace surftex {

struct EmbedSurfaceQuiltOptions {
  /// Shell thickness in units of the scaled swatch height (z_max - z_min) * scale; > 0.
  double shell_height = 1.0;
  /// The base mesh atlas; its normal cone defaults to 30 degrees here (not
  /// the atlas' 50): the bottom of the shell keeps the atlas' distortion, which
  /// the stretch minimisation cannot remove (on the 5K-face bunny the mean area
  /// distortion drops from 1.12 to 1.01, about 100 -> 280 charts).
  BaseMeshAtlasOptions atlas = [] {
    BaseMeshAtlasOptions a;
    a.max_normal_angle_deg = 30.0;
    return a;
  }();
  MinimizeStretchOptions stretch;
  /// Run the exact self-intersection count on the embedded mesh.
  bool check_self_intersections = true;
  /// Issue 17 item 1, the last stage: the faces of the embedded mesh that
  /// still intersect (exact; the shell map bends elements a little otherwise
  /// than quilt_surface's lifted check assumed) are resolved before the
  /// count: of two elements the later yields; a compact element
  /// (SurfaceQuilt::element_compact) with such faces is removed, another has
  /// them and one ring cut out and its pieces capped. The count then reports
  /// what is left. Default true.
  bool resolve_crossings = true;
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
  /// The outside vertices by cause: w below 0 / above 1 (the quilt's height
  /// left the swatch's z range), or w in [0, 1] with no tet of the face's
  /// chart containing (u, v, w) (0 unless the chart's tets do not tile its
  /// slab: a broken invariant; before the clamping above, the vertices beside
  /// chart-border edges).
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
  /// Elements cut or removed by EmbedSurfaceQuiltOptions::resolve_crossings.
  std::size_t crossing_elements = 0;
  /// Embedded vertices outside the geometric shell (the union of the shell's
  /// 3D tets; embed_outside_shell.h), with how far; empty unless measured.
  OutsideShellResult outside_shell;
  bool outside_shell_measured = false;
  double seconds_atlas = 0, seconds_shell = 0, seconds_stretch = 0, seconds_map = 0, seconds_embed = 0;
};

/// Embeds `quilt` (made by quilt_surface on `base`) into the shell over `base`; see the header comment.
EmbedSurfaceQuiltResult embed_surface_quilt(const Mesh& base, const SurfaceQuilt& quilt, Mesh& out,
                                            const EmbedSurfaceQuiltOptions& opt = {});

}  // namespace surftex
