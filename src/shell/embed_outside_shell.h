// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Containment check of embedded points in the geometric shell (Zhou et al.
// 2006, section 3.2: the shell map sends texture space into "a thin volume
// between M_base and one offset of it"; a vertex placed outside that volume is
// an embedding defect the paper's construction excludes).
//
// Definition (ours): the geometric shell is the union of the shell-space
// tets; a point is outside when farther than tolerance * shell.height from
// it, measured (only for points locate_shell does not place) to the nearest
// boundary triangle: bottom (below), top (above) or a mesh-border wall
// (side); walls between charts are inside. In full: decision 104.
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
