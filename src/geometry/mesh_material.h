// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Surface materials as mesh files carry them: an OBJ's .mtl (newmtl, Kd,
// map_Kd) and glTF 2.0 materials (name, pbrMetallicRoughness.baseColorFactor
// and baseColorTexture). Faces refer to them through kFaceMaterial
// (face_material.h). surftex keeps the base colour only: what its renderer and
// the OBJ format can show.

#include <array>
#include <string>
#include <vector>

#include "geometry/image.h"

namespace surftex {

struct MeshMaterial {
  std::string name;
  /// Base colour factor, linear RGB in [0,1]: OBJ Kd, glTF baseColorFactor.
  /// With a texture, a glTF viewer multiplies the two; an OBJ read with a
  /// map_Kd gets (1,1,1) here, as Blender's importer ignores Kd then.
  std::array<float, 3> base_color{1.f, 1.f, 1.f};
  /// The base-colour texture: the file it is in (OBJ map_Kd resolved against
  /// the .mtl's folder, a glTF image URI resolved against the .gltf) and/or
  /// its encoded bytes as read with the mesh file (GLB buffer view, data: URI,
  /// an external glTF image; decoded first when present). Neither = no texture.
  std::string texture_file;
  std::string texture_bytes;
  /// Where the texture was named, for messages (e.g. "map_Kd in 'a.mtl'").
  std::string texture_origin;
  /// The decoded texture (load_material_textures), empty until then.
  Image texture;
  /// How coordinates outside [0,1] read the texture, per axis: a glTF
  /// sampler's wrapS / wrapT (REPEAT when it has no sampler, glTF 2.0
  /// section 5.26); OBJ map_Kd repeats.
  enum class Wrap { Repeat, ClampToEdge, MirroredRepeat };
  Wrap wrap_s = Wrap::Repeat, wrap_t = Wrap::Repeat;

  bool has_texture() const { return !texture_file.empty() || !texture_bytes.empty(); }
};

/// Decodes the texture of every material that has one into `texture`
/// (OpenImageIO: PNG, JPEG, ...). Throws IOError naming the material, the
/// file or origin and the reason (missing file, undecodable bytes).
void load_material_textures(std::vector<MeshMaterial>& materials);

}  // namespace surftex
