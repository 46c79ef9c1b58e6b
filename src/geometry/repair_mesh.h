// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Repair of degenerate input meshes (docs/DESIGN.md data flow step 1: "load ->
// validate -> repair (or refuse with a precise error)"), built from CGAL 5.5
// Polygon Mesh Processing steps:
//   0. triangulate non-triangle faces (PMP::triangulate_faces; faces it
//      cannot triangulate are deleted and counted);
//   1. repeated until nothing changes (at most RepairOptions::max_rounds):
//      stitch coincident borders (PMP::stitch_borders), remove zero-area faces
//      (PMP::remove_degenerate_faces; collinearity is an exact predicate),
//      collapse needles / flip caps (PMP::is_needle_triangle_face /
//      is_cap_triangle_face + Euler::collapse_edge / flip_edge, only when the
//      change flips no neighbouring face), delete degenerate faces that are
//      left, split non-manifold vertices (PMP::duplicate_non_manifold_vertices),
//      remove isolated vertices;
//   2. optionally fill holes up to max_hole_edges (PMP::triangulate_hole),
//      then step 1 again on the filled mesh;
//   3. orient every closed component outward (signed volume > 0);
//   4. optionally keep the largest component (PMP::keep_largest_connected_components);
//   5. report self-intersecting face pairs (exact predicates; not removed);
//   6. validate: CGAL::is_valid_polygon_mesh, all triangles, no degenerate
//      face (exact collinearity), no non-manifold vertex, every closed
//      component outward, something left. If any check fails, `valid` is
//      false and `refusal` says which check and how many elements.
// Every step runs under a guard: an exception (CGAL::Failure_exception or any
// std::exception) inside a step is recorded in RepairDone::step_errors and
// the step is skipped; the final validation decides. repair_mesh itself does
// not throw for bad geometry; it throws InvalidInputError for bad options.
// Properties: none read; vertex/face properties of removed elements are
// dropped (Surface_mesh garbage is collected), new elements get defaults.

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"

namespace surftex {

struct RepairOptions {
  /// Fill boundary loops (holes) with triangles. Default false: open
  /// surfaces are legitimate input.
  bool fill_holes = false;
  /// Holes with more boundary edges than this are left open (counted as
  /// skipped). Range >= 3, default 200 (filling is up to cubic in this size).
  std::size_t max_hole_edges = 200;
  /// Keep only the connected component with most faces. Default false.
  bool keep_largest_component = false;
  /// A triangle is a needle when longest / shortest edge length exceeds this
  /// ratio; its shortest edge is collapsed. Range >= 1, default 1000.
  double needle_threshold = 1000.0;
  /// A triangle is a cap when the cosine of its largest angle is below this
  /// value; the edge opposite that angle is flipped. Range [-1, 0], default
  /// -0.9998 (about 178.85 degrees).
  double cap_threshold = -0.9998;
  /// Rounds of the cleanup loop (step 1). Range >= 1, default 8.
  int max_rounds = 8;
  /// Detect self-intersections (step 5). Default true.
  bool detect_self_intersections = true;
  /// Use TBB where CGAL offers it (self-intersection detection). The result
  /// does not depend on it. Default true.
  bool parallel = true;
  ProgressCallback progress;
};

/// What was wrong with the mesh as given (before any step changed it).
struct RepairFound {
  std::size_t vertices = 0, faces = 0;
  std::size_t non_triangle_faces = 0;
  std::size_t duplicate_vertices = 0;  ///< vertices at a position already taken
  std::size_t zero_area_faces = 0;     ///< exactly collinear corners
  std::size_t needle_faces = 0;        ///< per needle_threshold (not zero-area)
  std::size_t cap_faces = 0;           ///< per cap_threshold (not zero-area, not needle)
  std::size_t non_manifold_vertices = 0;
  std::size_t border_edges = 0, boundary_loops = 0;
  std::size_t components = 0;
  std::size_t isolated_vertices = 0;
  std::size_t inward_components = 0;   ///< closed components with negative volume
};

/// What each step changed.
struct RepairDone {
  std::size_t faces_triangulated = 0;          ///< non-triangle faces split
  std::size_t untriangulable_faces_removed = 0;
  std::size_t stitched_edges = 0;              ///< halfedge pairs stitched
  std::size_t degenerate_faces_removed = 0;    ///< net face count drop of remove_degenerate_faces
  std::size_t needles_collapsed = 0;
  std::size_t caps_flipped = 0;
  std::size_t degenerate_faces_deleted = 0;    ///< left by the above, deleted outright
  std::size_t non_manifold_vertices_split = 0; ///< vertices created by the split
  std::size_t isolated_vertices_removed = 0;
  std::size_t holes_filled = 0, holes_skipped = 0, faces_added_by_filling = 0;
  std::size_t components_reoriented = 0;
  std::size_t components_removed = 0;
  int rounds = 0;                              ///< cleanup rounds run
  /// "step: message" for every step that threw and was skipped.
  std::vector<std::string> step_errors;
};

struct RepairReport {
  RepairFound found;
  RepairDone done;
  /// Self-intersecting face pairs of the result (exact predicates), or 0 if
  /// detection was off (see self_intersections_checked).
  std::size_t self_intersecting_pairs = 0;
  bool self_intersections_checked = false;
  /// The result.
  std::size_t vertices = 0, faces = 0, components = 0, boundary_loops = 0;
  bool closed = false;
  /// Final verdict: true when every validation check of step 6 passed.
  bool valid = false;
  /// Empty when valid, else the first failed check with counts.
  std::string refusal;
  /// Wall-clock seconds per step, in order.
  std::vector<std::pair<std::string, double>> seconds;
};

/// Repairs `mesh` in place (see the file comment for the steps). Throws
/// InvalidInputError if an option is out of range; geometry problems never
/// throw but end in report.valid == false with report.refusal set.
RepairReport repair_mesh(Mesh& mesh, const RepairOptions& opt = {});

/// Signed volume enclosed by the closed components of `mesh` (sum over all
/// faces of det(p0, p1, p2) / 6, so open components count too); > 0 when
/// outward oriented. Units: mesh units cubed.
double signed_volume(const Mesh& mesh);

}  // namespace surftex
