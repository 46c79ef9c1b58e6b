// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// TetGen adapter: tetrahedralizes the volume enclosed by a closed triangle
// surface (a piecewise linear complex) with TetGen 1.5 (Si 2015), for shells
// given by their closed boundary surface (Zhou et al. 2006, section 3.2: the
// shell space is meshed with tetrahedra; see shell_space.h for the prism path
// and shell_boundary_surface() for a shell's boundary).
//
// The surface's vertices and triangles become a tetgenio PLC (one facet per
// triangle); `tetrahedralize(switches, in, out)` is called with the switches
// of the options ("pQY" by default: p = tetrahedralize a PLC, Q = quiet, Y =
// keep the boundary as given, no Steiner points on it). TetGen reports failure
// by throwing an int (1 out of memory, 2 internal error, 3 self-intersecting
// input, 4 very small input feature, 5 close facets, 10 input error); any such
// throw, or any other exception, becomes a SolverError naming the code. The
// output is checked: at least one tet, 4 corners each, indices in range, every
// tet non-degenerate. Tets are returned positively oriented (CGAL::orientation
// exact predicate on Epick points; TetGen's own convention is the opposite
// sign, so most tets are reordered: swap of the first two corners).
// The surface is first checked for self-intersections (exact predicates):
// TetGen 1.5 was seen to crash outright on such input, so it is refused.
// Throws: InvalidInputError (surface not closed, not triangles or
//         self-intersecting; bad switches),
//         SolverError (TetGen failed, or returned a degenerate/invalid mesh).

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct TetGenOptions {
  /// TetGen switches; must contain 'p' (PLC input) and must not contain 'o2'
  /// (second-order tets) or 'r' (refinement of an existing mesh).
  std::string switches = "pQY";
};

struct TetMeshResult {
  std::vector<std::array<double, 3>> points;  ///< input vertices first (same order), then Steiner points
  std::vector<std::array<int, 4>> tets;       ///< positively oriented (CGAL::orientation == POSITIVE)
  std::size_t input_points = 0;
  std::size_t steiner_points = 0;             ///< points TetGen added
  std::size_t reoriented = 0;                 ///< tets whose corner order was swapped
};

/// Tetrahedralizes the inside of the closed, outward or inward oriented triangle surface `boundary`.
TetMeshResult tetrahedralize_closed_surface(const Mesh& boundary, const TetGenOptions& opt = {});

}  // namespace surftex
