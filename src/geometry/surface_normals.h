// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Face and vertex normals of a triangle mesh (the first differential quantity
// of Ray et al. 2009, section 2, used by every field on the surface).
//
// Face normal: the normalised cross product of two edges of the (triangle)
// face; a zero-area face gets the normal of the best non-degenerate corner, and
// (0,0,1) only if the face is fully collapsed, so no normal is ever NaN.
// Vertex normal: weighted sum of the incident face normals, normalised.
//   - kArea:  weight = face area (smooth on regular meshes; the default, and
//             the meaning of kVertexNormal in properties.h),
//   - kAngle: weight = the face's corner angle at the vertex (Thuermer-Wuethrich;
//             independent of how a fan is triangulated).
// A vertex without faces (or whose weighted sum vanishes) falls back to the
// unweighted sum, then to (0,0,1).
//
// Writes kFaceNormal / kVertexNormal (or the maps given). Throws
// InvalidInputError if the mesh has a non-triangle face.

#include "geometry/mesh_fwd.h"

namespace surftex {

enum class NormalWeighting { kArea, kAngle };

struct VertexNormalOptions {
  NormalWeighting weighting = NormalWeighting::kArea;
};

/// Writes unit face normals into the "f:normal" map (created if absent).
void compute_face_normals(Mesh& mesh);

/// Writes unit vertex normals into the "v:normal" map (created if absent).
void compute_vertex_normals(Mesh& mesh, const VertexNormalOptions& options = {});

}  // namespace surftex
