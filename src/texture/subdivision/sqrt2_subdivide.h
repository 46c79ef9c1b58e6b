// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// sqrt(2)-subdivision of polygon meshes (Li, Ma & Bao 2004, "sqrt(2)
// subdivision for quadrilateral meshes"), as used by Bangay & Morkel 2006,
// section 3.2.1 (figure 4), and its selective form for adaptive subdivision
// (section 3.2.2, figure 5).
//
// Topology (the sqrt(2) split): a face point is added for every face; every
// interior edge (a, b) with faces f (left of a->b) and g becomes the quad
// (a, g*, b, f*); a border edge becomes the triangle (a, b, f*). The old faces
// are removed. So the result has V + F vertices and E faces, all quads except
// one triangle per border edge. Old vertices keep their index: vertex i of the
// input is vertex i of the output (attributes of coarse vertices carry over
// directly, section 3.2.1); face point of face f gets index V + (rank of f).
//
// Geometry (approximating rule). Li et al.'s smoothing weights are derived
// from 4-8 subdivision and are valence dependent; their paper was not
// available to us, so this implementation uses a plain averaging rule in the
// same spirit (documented choice):
//   face point   f* = centroid of the face's corners (old positions),
//   old interior vertex  v' = (1 - beta) v + beta * mean(f* of incident faces),
//     beta = Options::vertex_weight (default 1/2). On a regular quad grid
//     this is the mask v' = 5/8 v + 1/16 sum(edge neighbours) + 1/32
//     sum(diagonal neighbours); the weights sum to one and are positive, so
//     the rule is a convex averaging (approximating, never interpolating).
//   old border vertex: kept in place (the border curve is not shrunk).
// With smooth = false every old vertex keeps its position (topology only).
//
// Per-vertex properties carried (only when the flag is set and the map exists):
// kVertexColor, kVertexSweep, kVertexDirection (face points get the average
// over the face's corners; directions are averaged, not normalised: callers
// re-project them, see turk_orientation_field.h). Other properties of the
// input are dropped (the mesh is rebuilt).
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

/// Selective sqrt(2) split (section 3.2.2): only faces with refine[face index]
/// != 0 get a face point. An edge between two refined faces becomes a quad as
/// above; an edge between a refined face f and an unrefined face (or the
/// border) becomes the transition triangle (a, b, f*); unrefined faces are kept
/// unchanged. The result stays manifold, and closed if the input was. Old
/// vertices are NOT moved (their unrefined neighbours would change shape);
/// `opt.smooth` is ignored. `refine` must have one entry per face index
/// (mesh.number_of_faces() after collect_garbage); throws InvalidInputError
/// otherwise.
Sqrt2SubdivideResult sqrt2_subdivide_selected(Mesh& mesh, const std::vector<char>& refine,
                                              const Sqrt2SubdivideOptions& opt = {});

}  // namespace surftex
