// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Self-intersection test of a triangle mesh with exact predicates (CGAL PMP
// self_intersections on the Epick kernel: the intersection tests are exact
// predicates on the double coordinates). Faces sharing a vertex or an edge
// count only if they overlap beyond that shared element (CGAL's rule).
// Used to validate embedded geometric textures (Zhou et al. 2006, section 3.2,
// figure 8) and in tests. This is the project's one heavy PMP-intersection TU.
// Throws InvalidInputError if the mesh has non-triangle faces.

#include <cstddef>
#include <utility>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

/// Number of intersecting face pairs; pairs (face indices, first < second) in `pairs` if given.
std::size_t count_self_intersections(const Mesh& mesh, std::vector<std::pair<int, int>>* pairs = nullptr);

}  // namespace surftex
