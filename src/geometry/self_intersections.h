// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Detection of self-intersecting face pairs of a triangle mesh, with exact
// predicates (CGAL PMP self_intersections over surftex::Kernel = Epick: box
// intersection filter, then exact triangle-triangle do_intersect tests).
// Two faces count as intersecting when they share more than their common
// sub-simplex: adjacent faces that only share an edge or a vertex do not
// count; any other contact (touching, coplanar overlap, a degenerate face
// lying on a neighbour) does. Nothing is removed or changed.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct SelfIntersectionOptions {
  /// Use TBB (CGAL::Parallel_tag). The result is the same either way: pairs
  /// are sorted before they are returned. Default true.
  bool parallel = true;
};

/// A pair of intersecting faces by Surface_mesh face index, first < second.
using FacePair = std::array<std::uint32_t, 2>;

/// All self-intersecting face pairs of `mesh`, sorted lexicographically.
/// Throws InvalidInputError if `mesh` has a face that is not a triangle.
/// Face indices are those of `mesh` as given (removed faces are skipped).
std::vector<FacePair> self_intersecting_faces(const Mesh& mesh,
                                              const SelfIntersectionOptions& opt = {});

/// The intersecting pairs among `faces` (indices of `mesh`'s faces) only,
/// sorted as above: when every other pair is known not to intersect (a
/// recheck after some parts changed), the changed faces and those that may
/// touch them give the whole answer at a fraction of the cost.
std::vector<FacePair> self_intersecting_faces(const Mesh& mesh, const std::vector<std::uint32_t>& faces,
                                              const SelfIntersectionOptions& opt = {});

/// Number of self-intersecting face pairs (same rules and throws as above).
std::size_t count_self_intersections(const Mesh& mesh, const SelfIntersectionOptions& opt = {});

}  // namespace surftex
