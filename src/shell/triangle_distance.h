// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Closest-point queries against the triangles of an ElementMesh, accelerated
// with a bounding-volume hierarchy (Zhou et al. 2006, section 2.4: "we
// obtained a significant speed-up ... by building an octree data structure
// for the input texture"; the hierarchy over the triangles plays that role).
// Queries are const and thread-safe once built (the tree is built eagerly).
// Exact up to floating-point rounding; among triangles at the same distance
// the one first in the mesh wins.
#include <cstddef>
#include <memory>

#include "shell/element_mesh.h"

namespace surftex {

class TriangleDistance {
 public:
  /// Builds the tree over `mesh.tris` (copied; the mesh need not outlive this).
  /// An empty mesh gives an object whose queries return tri = -1.
  explicit TriangleDistance(const ElementMesh& mesh);
  ~TriangleDistance();
  TriangleDistance(TriangleDistance&&) noexcept;
  TriangleDistance& operator=(TriangleDistance&&) noexcept;

  struct Hit {
    int tri = -1;          ///< index into mesh.tris, -1 if the mesh is empty
    double distance = 0;   ///< Euclidean distance to the closest point
    P3 point{0, 0, 0};     ///< the closest point
    P3 bary{0, 0, 0};      ///< its barycentric coordinates in tri (alpha, beta, gamma)
  };
  /// The closest point of the triangles to q. `hint` (a triangle index, or
  /// -1) is tried first: the previous hit of a query nearby bounds the search
  /// from the start (a mesh's vertices in order, a pattern's neighbouring
  /// shifts). The result does not depend on it.
  Hit closest(const P3& q, int hint = -1) const;
  /// closest(q, hint) when that hit lies within `radius` (>= 0; the same
  /// triangle, distance, point and barycentrics), else tri = -1 and distance
  /// infinity; a hit a hair past the radius may still be returned, so callers
  /// compare the distance themselves. Cheaper: farther boxes are skipped from
  /// the start. Throws InvalidInputError for a negative or NaN radius.
  Hit closest_within(const P3& q, double radius, int hint = -1) const;
  /// Adds a grid over the triangles' box (plus a margin of two cells) whose
  /// every cell lists the triangles that can be closest to a point in it; a
  /// query inside reads that list instead of walking the tree, outside it
  /// walks the tree. For a mesh queried many times (a swatch, Zhou et al.
  /// 2006 s.2.4's matching). Cells of about `cell` (> 0), at most
  /// `max_cells` of them (the cell grows to fit). Same hits as without.
  void build_cell_lists(double cell, std::size_t max_cells = std::size_t(1) << 17);
  /// Squared distance from q to the bounding box of the triangles, a lower
  /// bound of closest(q).distance squared (0 for an empty mesh).
  double box_squared_distance(const P3& q) const;
  bool empty() const;

 private:
  Hit closest_below(const P3& q, int hint, double start) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surftex
