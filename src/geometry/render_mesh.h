// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Builds the rasterizer's RenderMesh (geometry/rasterizer.h) from a surftex
// Mesh: positions, fan-triangulated faces, and on request per-vertex colours,
// per-corner texture coordinates and smooth vertex normals.
//
// Properties read (only those asked for in the options, never picked up just
// because they exist): kVertexColor (v:color), kCornerUV (h:uv). Nothing is written.

#include "geometry/mesh_fwd.h"
#include "geometry/rasterizer.h"

namespace surftex {

struct RenderMeshOptions {
  /// Copy kVertexColor into RenderMesh::vertex_colors. Throws
  /// InvalidInputError if the mesh has no such property.
  bool vertex_colors = false;
  /// Copy kCornerUV into RenderMesh::corner_uvs (3 per triangle). Throws
  /// InvalidInputError if the mesh has no such property.
  bool corner_uvs = false;
  /// Area-weighted vertex normals (smooth shading, consistent with the face
  /// winding); false leaves them empty so the rasterizer shades each triangle
  /// with its face normal (flat shading). Default true.
  bool smooth_normals = true;
};

/// Vertices are renumbered densely in iteration order (removed elements are
/// skipped); a polygon with corners c0..c(n-1) becomes the fan (c0, ck, ck+1);
/// triangle_face holds the source face index. Throws InvalidInputError if the
/// mesh has no faces, a non-finite coordinate, or a requested property is
/// missing.
RenderMesh make_render_mesh(const Mesh& mesh, const RenderMeshOptions& options = {});

}  // namespace surftex
