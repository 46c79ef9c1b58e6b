// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Object-space normals per vertex -> the tangent-space normal map a glTF
// viewer needs for the GLB that write_mesh writes of the same atlas mesh
// (issue 16 item 2; shared by the methods whose normals live on the surface:
// subdiv, later material-map). Per atlas texel: n = the blend of the corners'
// object normals, N, T, w the blend of the GLB's NORMAL and TANGENT
// (gltf_vertex_frames.h), B = cross(N, T) sign(w) (MikkTSpace per pixel);
// stored (normalize(n.T, n.B, n.N) + 1) / 2, gutters dilated.
//
// Reads kCornerUV, kFacePatch (charts, optional), kVertexNormal (optional,
// else area-weighted normals as the GLB's). Throws InvalidInputError
// (non-triangle face, no uv, sizes).

#include <array>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

/// `object_normals`: one per vertex index (need not be unit). `size` = atlas side, 1..16384.
Image tangent_space_normal_map(const Mesh& atlas_mesh, const std::vector<std::array<float, 3>>& object_normals,
                               int size);

}  // namespace surftex
