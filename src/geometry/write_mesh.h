// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh output in formats that open in Blender, MeshLab and glTF viewers:
// OBJ (+MTL, per-corner UVs, texture image), binary PLY (vertex colours) and
// glTF 2.0 binary (.glb: positions, normals, UVs, vertex colours, embedded
// PNG texture). Every writer is atomic (temporary + rename).

#include <map>
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
  /// Several materials instead (not with `texture`), chosen by kFaceMaterial
  /// (-1 or past the list: a white "surftex_default"). Not owned.
  const std::vector<MeshMaterial>* materials = nullptr;
  /// Tangent-space normal map (+Y up, (n+1)/2): glTF normalTexture with TANGENT
  /// (vertex_tangents.h), OBJ `norm` / `map_Bump`. Ignored if null or empty.
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
  /// PNG bytes of some of the images above, encoded ahead (encode_png): an
  /// OBJ's texture file or a GLB's embedded image of such an image takes
  /// these bytes instead of encoding it again (an OBJ and a GLB of one asset
  /// share their maps). Not owned; null = encode every image.
  const std::map<const Image*, std::string>* encoded_png = nullptr;
};

/// The 8-bit PNG file bytes of each image (side by side), keyed by image, for
/// WriteMeshOptions::encoded_png. `beside` names the temporaries the encoder
/// needs (never committed). Throws like write_mesh.
std::map<const Image*, std::string> encode_png(const std::string& beside, const std::vector<const Image*>& images);

/// Format by extension (case-insensitive): .obj (+ .mtl and textures, renamed
/// into place together), .ply (binary little-endian), .off, .glb (glTF 2.0,
/// UVs stored as (u, 1 - v), one primitive per material). The fields of each:
/// docs/decisions/404-mesh-readers.md. A texture without kCornerUV is refused.
/// Properties read: kVertexColor, kCornerUV, kFaceMaterial, kVertexNormal (else computed,
/// area-weighted), the named scalar. Throws InvalidInputError (unknown
/// extension, no faces, non-finite position, missing scalar property) or
/// IOError (cannot write; output exists and !overwrite). A failed write
/// leaves no file behind. Returns the paths of the files written (`path`
/// first, then an OBJ's .mtl and texture images), for the run's report.
std::vector<std::string> write_mesh(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt = {});

/// An OBJ and a GLB of one textured asset side by side: the maps both carry
/// (obj_opt's texture, normal and metallic-roughness maps, when given and not
/// already in obj_opt.encoded_png) encoded once, then the two files written in
/// parallel; glb_opt's texture pointers must be the same images. Returns the
/// OBJ's files, then the GLB. Throws like write_mesh.
std::vector<std::string> write_obj_and_glb(const std::string& obj, const std::string& glb, const Mesh& mesh,
                                           const WriteMeshOptions& obj_opt, const WriteMeshOptions& glb_opt);

}  // namespace surftex
