// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Loading a user's mesh for a texturing method (docs/DESIGN.md data flow step 1:
// "load -> validate -> repair (or refuse with a precise error)").
//
// Every method subcommand (patches, material-map, subdiv, quilt) reads its
// base mesh through this: the file is read and its polygon soup repaired
// (read_mesh.h), then the mesh is repaired as by `surftex repair` with its
// defaults (repair_mesh.h: stitching, zero-area faces, needles and caps,
// non-manifold vertices, isolated vertices, outward orientation; no hole
// filling, no component removal, no self-intersection count). A mesh the
// repair cannot make valid (for instance one whose faces all have zero area)
// is refused with the repair's reason instead of failing deep inside a
// method with a solver or parameterization error.
//
// keep_polygons (sqrt(2)-subdivision takes polygons): a mesh with
// non-triangle faces is kept as it is when none of its faces is degenerate
// (every face has three corners that are not collinear, exact predicate) and
// none of its vertices is isolated; otherwise it is triangulated and repaired
// like a triangle mesh.

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "geometry/read_mesh.h"
#include "geometry/repair_mesh.h"

namespace surftex {

struct LoadInputOptions {
  /// Keep valid non-triangle faces (see the file comment). Default false:
  /// the mesh is all triangles on return.
  bool keep_polygons = false;
  ProgressCallback progress;
};

struct LoadInputReport {
  SoupRepairCounts soup;  ///< what reading the file repaired (read_mesh.h)
  RepairReport repair;    ///< what repair_mesh found and did (if it ran)
  bool repair_ran = false;
  /// Elements the mesh repair changed (faces removed, collapsed, flipped,
  /// vertices split or removed, components reoriented, edges stitched).
  std::size_t repair_changes = 0;
  /// One line for the terminal, empty when nothing needed repair, e.g.
  /// "removed 3 zero-area faces, split 2 non-manifold vertices".
  std::string summary;
};

/// Reads `path` into `mesh` (cleared first) and repairs it (see the file
/// comment). Throws IOError / InvalidInputError for unreadable files (as
/// read_mesh) and TopologyError naming the file and the reason when the mesh
/// cannot be repaired into a valid one.
LoadInputReport load_input_mesh(const std::string& path, Mesh& mesh,
                                const LoadInputOptions& opt = {});

/// {"soup": {...}, "repair": {...} (repair_mesh_json.h) or null, "summary": s}.
nlohmann::json to_json(const LoadInputReport& report);

}  // namespace surftex
