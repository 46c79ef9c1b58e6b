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
// Definitions (indices are Surface_mesh indices, `.idx()`):
//   - a vertex is reached when its Dijkstra distance <= radius (seeds have 0);
//   - a face is in the area (free: its direction may change) when its three
//     vertices are reached (and the face budget is not exhausted);
//   - a vertex is free (its S, m, s, t may change) when all its incident faces
//     are in the area; reached vertices with a face outside form the locked
//     boundary. A vertex on a mesh border whose faces are all in the area is free.
// The paper leaves open whether distance is measured on faces or vertices and
// what a "budget" is: we measure edge-path distance between vertices (a
// careful, cheap approximation of geodesic distance) and count whole faces.

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
