// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// sqrt(2)-subdivision of polygon meshes (Li, Ma & Bao 2004, "sqrt(2)
// subdivision for quadrilateral meshes"), as used by Bangay & Morkel 2006,
// section 3.2.1 (figure 4), and its selective form for adaptive subdivision
// (section 3.2.2, figure 5).
//
// Topology: a face point per face; an interior edge (a, b) becomes the quad
// (a, g*, b, f*), a border edge the triangle (a, b, f*): V + F vertices, E
// faces; old vertices keep their index, face point of f = V + rank(f).
// Geometry (Li et al.'s weights were not available; a documented averaging
// rule): f* = face centroid, v' = (1 - beta) v + beta mean(f*), border
// vertices fixed; smooth = false keeps every old vertex. Carried when set:
// kVertexColor, kVertexSweep, kVertexDirection (averaged, not normalised);
// other properties dropped. In full: docs/decisions/206.
//
// Throws InvalidInputError (empty mesh, vertex_weight outside [0,1]),
// TopologyError (an edge with the same face on both sides, or the rebuilt
// mesh refuses a face: non-manifold input).

#include <cstddef>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct Sqrt2SubdivideOptions {
  /// Move old vertices by the approximating rule (true) or keep them (false).
  bool smooth = true;
  /// beta of the vertex rule, in [0, 1]. Default 0.5.
  double vertex_weight = 0.5;
  /// Carry kVertexColor / kVertexSweep / kVertexDirection if present.
  bool carry_color = true;
  bool carry_sweep = true;
  bool carry_direction = true;
};

struct Sqrt2SubdivideResult {
  std::size_t old_vertices = 0;     ///< V before
  std::size_t face_points = 0;      ///< vertices added (= faces refined)
  std::size_t quads = 0;            ///< new quads (one per interior edge between refined faces)
  std::size_t triangles = 0;        ///< new triangles (border edges and transitions)
  std::size_t faces_kept = 0;       ///< unrefined faces kept as they were (selective only)
};

/// Uniform sqrt(2) subdivision of `mesh` in place (see header comment).
Sqrt2SubdivideResult sqrt2_subdivide(Mesh& mesh, const Sqrt2SubdivideOptions& opt = {});

/// Selective split (3.2.2): only faces with refine[f] != 0 get a face point;
/// edges to unrefined faces become transition triangles; stays manifold (and
/// closed). Old vertices do not move (opt.smooth ignored). Throws
/// InvalidInputError unless `refine` has one entry per face index.
Sqrt2SubdivideResult sqrt2_subdivide_selected(Mesh& mesh, const std::vector<char>& refine,
                                              const Sqrt2SubdivideOptions& opt = {});

}  // namespace surftex
