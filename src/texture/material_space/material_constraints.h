// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// User constraints of a material-space mapping (Ray et al. 2009, sections 2
// and 4: the brush that fixes the effect area, orientation strokes, scale and
// material picks) read from a JSON file and resolved on a mesh.
//
// Format (every top-level field optional; unknown fields are errors):
//   {
//     "effect_radius": 0.25,        // > 0, mesh units (edge-path distance from the
//                                   // constrained vertices, effect_area.h); absent = whole mesh
//     "strokes": [
//       {"faces": [12, 13, 40], "direction": [1, 0, 0]},   // faces by index, one 3D direction
//       {"polyline": [[0, 0, 1], [0.1, 0, 1], [0.2, 0.05, 1]]}  // >= 2 points, mesh units
//     ],
//     "scale":    [{"point": [0, 0, 1], "value": 0.05}],  // texture period S, mesh units,
//                                   // 1e-6..1e6 times half the mesh box's largest side
//     "material": [{"point": [0, 1, 0], "value": 1.0}]    // m in [0, 1]
//   }
// Every point must lie within one box size of the mesh's bounding box. A
// polyline is sampled along each segment (about one sample per mean edge
// length, at least the segment midpoint, and at most two samples per mesh
// face over all strokes together); each sample's nearest face (the
// incident face, around the nearest vertex, whose centroid is nearest) gets
// the segment's unit tangent as direction (projected on the face plane by the
// direction field; a sample whose tangent is normal to its face is skipped, a
// "faces" direction normal to one of its faces is refused). A face constrained twice keeps its first direction. Scale
// and material points go to their nearest vertex (a later point on the same
// vertex replaces the earlier one).
//
// Errors throw InvalidInputError "FILE: line L: field F: what" (e.g.
// "c.json: line 7: field strokes[1].faces[2]: face 9000 out of range (5120
// faces)"), also for malformed JSON, numbers beyond the double range and
// nesting deeper than 32 (geometry/json_input.h). read_material_constraints
// throws IOError if the file cannot be read or is larger than 16 MiB.

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "geometry/direction_field.h"
#include "geometry/mesh_fwd.h"
#include "geometry/scalar_field_interpolation.h"

namespace surftex {

struct MaterialConstraints {
  std::vector<DirectionConstraint> directions;
  std::vector<ScalarConstraint> scale;
  std::vector<ScalarConstraint> material;
  /// Effect radius in mesh units; +inf when the file gives none.
  double effect_radius = std::numeric_limits<double>::infinity();
  /// Every vertex touched by a constraint (vertices of the constrained faces,
  /// scale and material vertices), sorted and unique: the effect area's seeds.
  std::vector<std::uint32_t> seed_vertices;
  std::size_t strokes = 0;  ///< number of stroke entries in the file
};

/// Parses `text` (the file's content; `source` names it in messages) against
/// `mesh` (a triangle mesh).
MaterialConstraints parse_material_constraints(const std::string& text, const Mesh& mesh,
                                               const std::string& source = "constraints");

/// Reads and parses the file at `path`.
MaterialConstraints read_material_constraints(const std::string& path, const Mesh& mesh);

}  // namespace surftex
