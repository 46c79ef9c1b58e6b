// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// TetGen adapter: tetrahedralizes the volume enclosed by a closed triangle
// surface (a piecewise linear complex) with TetGen 1.5 (Si 2015), for shells
// given by their closed boundary surface (Zhou et al. 2006, section 3.2: the
// shell space is meshed with tetrahedra; see shell_space.h for the prism path
// and shell_boundary_surface() for a shell's boundary).
//
// The surface becomes a tetgenio PLC (one facet per triangle), tetrahedralized
// with the options' switches ("pQY": no Steiner points on the boundary).
// TetGen's thrown codes become SolverError; the output is checked (tets, 4
// valid corners, non-degenerate) and returned positively oriented. A
// self-intersecting surface is refused first (TetGen 1.5 crashes on it).
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
