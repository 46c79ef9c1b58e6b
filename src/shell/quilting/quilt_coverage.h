// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The bare area of a surface quilt as written (issue 17 item 4): the base
// surface not covered within half an element spacing by the output's
// elements, measured on the output mesh after the embedding (which removes
// and cuts elements the quilt still had), not on the quilt before it.
//
// Definition: a vertex's foot is its closest point on the base; each base
// face has four sample points (its centroid and its corner triangles'
// centroids), each a quarter of its area, bare when no foot lies within
// `radius`. Reads: the base's points and faces (triangles), the quilt's points.
#include <array>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "shell/element_mesh.h"
#include "shell/quilting/foot_grid.h"

namespace surftex {

struct BareArea {
  double overall = 0;                 ///< bare share of the base's area
  std::array<double, 4> by_height{};  ///< in four equal bands of height along `up`, lowest first
};

class TriangleDistance;

/// The feet (closest points on the tree's triangles) of `points`, computed in
/// parallel (each on its own), in a grid of `radius`.
FootGrid feet_on_base(const TriangleDistance& base, const std::vector<P3>& points, double radius);

/// See the header comment. Throws InvalidInputError for radius <= 0 or a
/// base face that is not a triangle. An empty quilt leaves everything bare.
BareArea output_bare_area(const Mesh& base, const Mesh& quilt, double radius, const std::array<double, 3>& up);

}  // namespace surftex
