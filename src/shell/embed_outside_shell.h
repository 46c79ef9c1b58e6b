// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Containment check of embedded points in the geometric shell (Zhou et al.
// 2006, section 3.2: the shell map sends texture space into "a thin volume
// between M_base and one offset of it"; a vertex placed outside that volume is
// an embedding defect the paper's construction excludes).
//
// Definition (ours; the paper gives none): the geometric shell is the union of
// the shell-space tetrahedra of a ShellSpace, i.e. the prisms between the base
// surface (layer 0) and its clamped offset (layer 1). A point is outside when
// its Euclidean distance to that union exceeds tolerance * shell.height. The
// distance is computed only for points that ShellMap::locate_shell does not
// find inside a tet, as the distance to the nearest boundary triangle of the
// union: bottom triangles (base surface), top triangles (offset surface) and
// lateral walls on mesh borders (walls between two charts coincide in 3D and
// are inside the union: they are left out). The side of an outside point is
// the layer of that nearest triangle: below (under the base surface), above
// (over the offset surface) or side (beyond a mesh-border wall).
// Because the distance is to the nearest shell triangle, a point is measured
// against the shell where it is, not against the prism it was meant for.
//
// Reads: shell.shell_points, tets, tet_face, chart, base_vertex, layer, height.
// Throws: InvalidInputError (empty shell, tolerance < 0 or not finite).

#include <cstddef>
#include <vector>

#include "shell/shell_map.h"
#include "shell/shell_space.h"

namespace surftex {

struct OutsideShellOptions {
  /// Distance, in units of the nominal shell height, beyond which a point
  /// counts as outside (absorbs rounding of points on the shell's surface); >= 0.
  double tolerance = 1e-6;
};

struct OutsideShellResult {
  std::size_t points = 0;        ///< points checked
  std::size_t outside = 0;       ///< of which outside the geometric shell
  std::size_t below = 0, above = 0, side = 0;  ///< outside ones by nearest shell surface
  double max_distance = 0;       ///< largest distance to the shell (mesh units), 0 if none outside
  double mean_distance = 0;      ///< mean distance over the outside points (mesh units)
  std::vector<int> outside_points;  ///< indices (into the input) of the outside points, ascending
  std::vector<int> nearest_face;    ///< per outside point: base face of the prism owning the nearest shell triangle
};

/// Checks every point of `points` (3D, mesh units) against the geometric shell of `shell`
/// (`map` must be built from `shell`); see the header comment.
OutsideShellResult measure_outside_shell(const std::vector<Vec3>& points, const ShellSpace& shell,
                                         const ShellMap& map, const OutsideShellOptions& opt = {});

}  // namespace surftex
