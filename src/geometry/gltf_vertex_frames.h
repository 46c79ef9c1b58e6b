// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The vertices of a glTF export and their shading frames, as write_mesh's
// .glb writes them (one definition, shared by the writer and by bakers that
// must agree with what a viewer reconstructs from the file, e.g.
// texture/tangent_space_bake.h):
// - normals per mesh vertex: kVertexNormal if present, else the normalised
//   sum of the Newell normals (twice the vector area) of its faces;
// - one glTF vertex per distinct (mesh vertex, corner uv), numbered in first
//   use, TEXCOORD_0 = (u, 1 - v) (glTF's origin is the top-left);
// - TANGENT per glTF vertex: geometry/vertex_tangents.h on the float
//   positions, the normals and the uv with v up, over the triangles in the
//   order the file lists them.

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

/// Unit normals per vertex, in mesh.vertices() order (kVertexNormal if the
/// mesh has it, else area-weighted Newell normals; (0, 0, 1) for a vertex
/// whose faces have no area).
std::vector<std::array<float, 3>> export_vertex_normals(const Mesh& mesh);

/// glTF vertices: one per distinct (vertex, uv) pair.
class GltfVertexSplit {
 public:
  /// The glTF vertex of compact mesh vertex `vertex` at corner uv (v up).
  std::uint32_t id(std::size_t vertex, const std::array<double, 2>& uv);
  std::size_t size() const { return source_.size(); }
  const std::vector<std::size_t>& source() const { return source_; }           ///< glTF -> mesh vertex
  const std::vector<std::array<float, 2>>& texcoord() const { return texcoord_; }  ///< (u, 1 - v)

 private:
  std::vector<std::size_t> source_;
  std::vector<std::array<float, 2>> texcoord_;
  std::map<std::pair<std::size_t, std::array<double, 2>>, std::uint32_t> key_to_id_;
};

/// TANGENT (xyz unit, w = +-1) per glTF vertex of `split`; `positions` and
/// `normals` per compact mesh vertex, `triangles` = glTF vertex indices.
std::vector<std::array<float, 4>> gltf_vertex_tangents(const std::vector<std::array<double, 3>>& positions,
                                                       const std::vector<std::array<float, 3>>& normals,
                                                       const GltfVertexSplit& split,
                                                       const std::vector<std::uint32_t>& triangles);

/// The frames a viewer reads from the .glb of `mesh` (one material, faces fanned in order).
struct GltfVertexFrames {
  std::vector<std::uint32_t> corner;            ///< per halfedge index: glTF vertex of that face corner (its target)
  std::vector<std::array<float, 3>> normal;     ///< per glTF vertex
  std::vector<std::array<float, 4>> tangent;    ///< per glTF vertex (w = +-1)
};

/// Reads kCornerUV (required: throws InvalidInputError without it) and
/// kVertexNormal (optional). The mesh must have no removed elements.
GltfVertexFrames gltf_vertex_frames(const Mesh& mesh);

}  // namespace surftex
