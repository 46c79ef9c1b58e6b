// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Object-space normals per vertex -> the tangent-space normal map a glTF
// viewer needs for the GLB that write_mesh writes of the same atlas mesh
// (issue 16 item 2; shared by the methods whose normals live on the surface:
// subdiv, later material-map). Per atlas texel (bake_vertex_colors'
// raster: texel centres, one-texel band): n = the barycentric blend of the
// corners' object normals; N, T, w = the blend of the glTF vertices' NORMAL
// and TANGENT (geometry/gltf_vertex_frames.h: the file's own attributes),
// N normalised, T made orthogonal to N and normalised, B = cross(N, T) sign(w)
// (MikkTSpace's per-pixel frame); stored n_ts = normalize(n.T, n.B, n.N) as
// (n_ts + 1) / 2. Gutter texels are filled by dilating the charts' values
// (geometry/atlas_gutter.h), as pbr_maps.h does for normals from a height.
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
