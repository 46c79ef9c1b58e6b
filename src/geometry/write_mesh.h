// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh output in formats that open in Blender, MeshLab and glTF viewers:
// OBJ (+MTL, per-corner UVs, texture image), binary PLY (vertex colours) and
// glTF 2.0 binary (.glb: positions, normals, UVs, vertex colours, embedded
// PNG texture). Every writer is atomic (temporary + rename).

#include <string>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

struct WriteMeshOptions {
  /// Use the mesh's kCornerUV map (per-corner UVs) if present.
  bool write_uvs = true;
  /// Use the mesh's kVertexColor map if present.
  bool write_colors = true;
  /// Use kVertexNormal if present, else compute smooth normals (glTF, OBJ).
  bool write_normals = true;
  /// Texture image for OBJ (written as <stem>.png beside it, referenced by the
  /// .mtl) and glTF (embedded). Ignored if empty.
  const Image* texture = nullptr;
  /// Extra per-vertex scalar written as a PLY property / glTF attribute
  /// "_<name>" (e.g. the material coordinate m). Empty = none.
  std::string vertex_scalar_property;
  bool overwrite = true;
};

/// Format by extension: .obj, .ply, .glb, .off. Throws IOError / InvalidInputError.
void write_mesh(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt = {});

}  // namespace surftex
