// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Loading a user's mesh for a texturing method (docs/DESIGN.md data flow step 1:
// "load -> validate -> repair (or refuse with a precise error)").
//
// Every method reads its base mesh through this: read and soup-repaired
// (read_mesh.h), then repaired as `surftex repair` does by default
// (repair_mesh.h); a mesh the repair cannot make valid is refused with its
// reason. keep_polygons (sqrt(2)-subdivision): polygons kept when no face is
// degenerate and no vertex isolated, else triangulated and repaired.

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
