// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Repair of degenerate input meshes (docs/DESIGN.md data flow step 1: "load ->
// validate -> repair (or refuse with a precise error)"), built from CGAL 5.5
// Polygon Mesh Processing steps:
// Steps: 0. triangulate (faces it cannot: deleted, counted); 1. until stable
// (max_rounds): stitch borders, remove zero-area faces, collapse needles /
// flip caps, split non-manifold vertices, remove isolated vertices; 2. fill
// holes (optional) and step 1 again; 3. orient closed components outward;
// 4. keep the largest component (optional); 5. count self-intersections;
// 6. validate (valid = false and `refusal` naming the failed check). A step
// that throws is recorded in step_errors and skipped; repair_mesh throws only
// InvalidInputError for bad options. Each step's PMP call:
// docs/decisions/603-hostile-input-limits.md.
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
