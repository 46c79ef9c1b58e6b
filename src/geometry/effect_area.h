// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The effect area of a constraint edit (Ray et al. 2009, section 2.1): the
// region grown greedily around the constraint, visiting vertices by increasing
// geodesic distance along edges (Dijkstra) from the constraint's seed vertices,
// until the distance exceeds `radius` and/or the region holds `max_faces`
// faces. Every later step (scalar and direction interpolation, PGP) changes
// only the free elements of the area; everything else is locked to its
// current value, so a local edit leaves the rest of the mesh bit for bit
// unchanged ("all variables m, S, s, t associated to the boundary are fixed").
//
// Reached: Dijkstra edge-path distance <= radius; a face is in the area when
// its three vertices are reached (within the face budget); a vertex is free
// when all its faces are in it, else locked boundary. (Our reading: the paper
// leaves the distance and the budget open.)

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct EffectArea {
  std::vector<char> face_free;    ///< per face index: 1 = in the area
  std::vector<char> vertex_free;  ///< per vertex index: 1 = variable
  std::size_t free_faces = 0;
  std::size_t free_vertices = 0;
  /// Whole mesh free (initialisation).
  static EffectArea whole(const Mesh& mesh);
};

struct EffectAreaOptions {
  /// Maximal edge-path distance from the seeds, in mesh units; +inf = no limit.
  double radius = std::numeric_limits<double>::infinity();
  /// Maximal number of faces in the area; 0 = no limit.
  std::size_t max_faces = 0;
};

/// Grows the area from `seed_vertices` (vertex indices). Throws
/// InvalidInputError if a seed is out of range, radius < 0 / NaN, or no seed.
EffectArea compute_effect_area(const Mesh& mesh, const std::vector<std::uint32_t>& seed_vertices,
                               const EffectAreaOptions& options = {});

}  // namespace surftex
