// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh output in formats that open in Blender, MeshLab and glTF viewers:
// OBJ (+MTL, per-corner UVs, texture image), binary PLY (vertex colours) and
// glTF 2.0 binary (.glb: positions, normals, UVs, vertex colours, embedded
// PNG texture). Every writer is atomic (temporary + rename).

#include <string>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "geometry/mesh_material.h"

namespace surftex {

struct WriteMeshOptions {
  /// Use the mesh's kCornerUV map (per-corner UVs) if present.
  bool write_uvs = true;
  /// Use the mesh's kVertexColor map if present.
  bool write_colors = true;
  /// Use kVertexNormal if present, else compute smooth normals (glTF, OBJ).
  bool write_normals = true;
  /// Texture image for OBJ (written as <stem>.png beside it, referenced by the
  /// .mtl) and glTF (embedded): one material for every face. Ignored if empty.
  const Image* texture = nullptr;
  /// Several materials instead (not with `texture`): faces choose theirs by
  /// kFaceMaterial (all faces the first when the mesh has no such map; faces
  /// with -1 or an index past the list get a white "surftex_default"). Each
  /// is written with its name (blanks become '_'), base colour and decoded
  /// texture (MeshMaterial::texture; empty = none). Not owned.
  const std::vector<MeshMaterial>* materials = nullptr;
  /// PBR maps beside the base colour (issue 16 item 2), each ignored if null
  /// or empty. Tangent-space normal map (+Y up, encoded (n+1)/2): glTF
  /// normalTexture with a TANGENT attribute (geometry/vertex_tangents.h,
  /// MikkTSpace-style, w = +1 where cross(N, T) points along +v), OBJ `norm`
  /// and `map_Bump` (<stem>_normal.png).
  const Image* normal_texture = nullptr;
  /// Height map in [0,1], OBJ only: `disp` <stem>_height.png as 16-bit PNG
  /// (glTF 2.0 has no height slot).
  const Image* height_texture = nullptr;
  /// glTF metallicRoughnessTexture (G = roughness, B = metallic), OBJ
  /// `map_Pr` <stem>_roughness.png (its G channel).
  const Image* metallic_roughness_texture = nullptr;
  /// Sampler wrap of the glTF textures: REPEAT (periodic tiles) or
  /// CLAMP_TO_EDGE (atlases: charts end in gutters). Default true.
  bool texture_repeat = true;
  /// glTF attribute of kVertexColor: "COLOR_0" (multiplies the base colour
  /// in viewers) or an application name such as "_COLOR" to carry vertex
  /// colours beside a texture that already holds them. Default "COLOR_0".
  std::string color_attribute = "COLOR_0";
  /// Extra per-vertex scalar written as a PLY property / glTF attribute
  /// "_<name>" (e.g. the material coordinate m). Empty = none.
  std::string vertex_scalar_property;
  bool overwrite = true;
};

/// Format by extension (case-insensitive):
/// - .obj: `v x y z [r g b]` (colours if kVertexColor and write_colors), `vt`
///   per distinct corner UV of kCornerUV (v as stored: origin bottom-left),
///   `vn` per vertex, `f v/vt/vn`. With a texture or materials: `mtllib
///   <stem>.mtl`, faces grouped under `usemtl NAME`, and <stem>.mtl (newmtl,
///   Kd, map_Kd) with the textures beside it: <stem>.png when one material has
///   a texture, <stem>_<k>.png for material k otherwise. The files are renamed
///   into place together at the end.
/// - .ply: binary little-endian, float x/y/z, optional uchar red/green/blue,
///   optional float <vertex_scalar_property>, face list uchar (uint if a face
///   has > 255 corners) int vertex_indices.
/// - .off: OFF (COFF with 0-255 colours when colours are written), positions
///   in shortest round-trip decimal.
/// - .glb: glTF 2.0 binary, one triangle primitive (polygons fanned):
///   POSITION (with min/max), NORMAL, TEXCOORD_0 (vertices split at UV seams,
///   one glTF vertex per distinct (vertex, uv); stored as (u, 1 - v) since
///   glTF's UV origin is top-left), COLOR_0 (float RGB), "_<scalar>"; one
///   primitive per material used (all sharing the vertex attributes), one
///   PBR material (metallic 0, roughness 1, double-sided, baseColorFactor)
///   per material with its texture embedded as PNG as its base colour. A
///   texture on a mesh without kCornerUV is refused (InvalidInputError).
/// Properties read: kVertexColor, kCornerUV, kFaceMaterial, kVertexNormal (else computed,
/// area-weighted), the named scalar. Throws InvalidInputError (unknown
/// extension, no faces, non-finite position, missing scalar property) or
/// IOError (cannot write; output exists and !overwrite). A failed write
/// leaves no file behind. Returns the paths of the files written (`path`
/// first, then an OBJ's .mtl and texture images), for the run's report.
std::vector<std::string> write_mesh(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt = {});

}  // namespace surftex
