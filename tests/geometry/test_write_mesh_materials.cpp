// SPDX-License-Identifier: AGPL-3.0-or-later
// write_mesh with several materials (WriteMeshOptions::materials): one glTF
// material and primitive per material, OBJ usemtl groups and one texture file
// per textured material; they read back as written.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "geometry/errors.h"
#include "geometry/face_material.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

Image flat(float r, float g, float b) {
  Image img(4, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) img.at(x, y, 0) = r, img.at(x, y, 1) = g, img.at(x, y, 2) = b;
  return img;
}

// A colour, a normal and a 16-bit height map of 32 x 16 with distinct patterns.
struct Maps {
  Image color{32, 16, 3}, normal{32, 16, 3}, height{32, 16, 1};
};
Maps patterned_maps() {
  Maps m;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 32; ++x) {
      for (int c = 0; c < 3; ++c) m.color.at(x, y, c) = static_cast<float>((x * 7 + y * 3 + c * 11) % 32) / 31.f;
      m.normal.at(x, y, 0) = 0.5f, m.normal.at(x, y, 1) = static_cast<float>(y) / 15.f, m.normal.at(x, y, 2) = 1.f;
      m.height.at(x, y, 0) = static_cast<float>(x) / 31.f;
    }
  return m;
}

// A torus with UVs whose faces use three materials by their index mod 3:
// red texture, blue texture, and a plain green colour.
Mesh three_material_torus(std::vector<MeshMaterial>& mats) {
  Mesh m;
  make_torus(m, 1.0, 0.4, 12, 6);
  assign_torus_uvs(m, 1.0, 1.0, 1.0);
  auto fm = get_or_add(m, kFaceMaterial, -1);
  for (FaceIndex f : m.faces()) fm[f] = static_cast<int>(f.idx() % 3);
  mats.resize(3);
  mats[0].name = "red paint";
  mats[0].texture = flat(1, 0, 0);
  mats[1].name = "blue";
  mats[1].texture = flat(0, 0, 1);
  mats[2].name = "green";
  mats[2].base_color = {0.f, 1.f, 0.f};
  return m;
}

}  // namespace

TEST(WriteMeshMaterials, GlbHasOneMaterialAndPrimitivePerMaterial) {
  std::vector<MeshMaterial> mats;
  const Mesh m = three_material_torus(mats);
  const std::string d = test::temp_dir("wmm");
  WriteMeshOptions wo;
  wo.materials = &mats;
  EXPECT_EQ(write_mesh(d + "/t.glb", m, wo), std::vector<std::string>{d + "/t.glb"});
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, d + "/t.glb")) << err;
  ASSERT_EQ(model.materials.size(), 3u);
  EXPECT_EQ(model.materials[0].name, "red_paint");
  EXPECT_EQ(model.materials[2].pbrMetallicRoughness.baseColorTexture.index, -1);
  EXPECT_DOUBLE_EQ(model.materials[2].pbrMetallicRoughness.baseColorFactor[1], 1.0);
  EXPECT_DOUBLE_EQ(model.materials[2].pbrMetallicRoughness.baseColorFactor[0], 0.0);
  EXPECT_EQ(model.images.size(), 2u);
  ASSERT_EQ(model.meshes[0].primitives.size(), 3u);
  std::size_t tris = 0;
  for (const auto& p : model.meshes[0].primitives) tris += model.accessors[p.indices].count / 3;
  EXPECT_EQ(tris, m.number_of_faces());
  // Read back: the faces keep their materials, the textures their colours.
  Mesh back;
  MeshFileContents in = read_mesh_file(d + "/t.glb", back);
  ASSERT_EQ(in.materials.size(), 3u);
  load_material_textures(in.materials);
  EXPECT_FLOAT_EQ(in.materials[1].texture.at(1, 1, 2), 1.f);
  auto fm = find(back, kFaceMaterial).first;
  std::vector<int> count(3, 0);
  for (FaceIndex f : back.faces()) ++count[static_cast<std::size_t>(fm[f])];
  EXPECT_EQ(count, std::vector<int>(3, static_cast<int>(m.number_of_faces() / 3)));
}

TEST(WriteMeshMaterials, ObjWritesUsemtlGroupsAndATextureEach) {
  std::vector<MeshMaterial> mats;
  const Mesh m = three_material_torus(mats);
  const std::string d = test::temp_dir("wmm");
  WriteMeshOptions wo;
  wo.materials = &mats;
  const auto files = write_mesh(d + "/t.obj", m, wo);
  EXPECT_EQ(files, (std::vector<std::string>{d + "/t.obj", d + "/t.mtl", d + "/t_0.png", d + "/t_1.png"}));
  const std::string mtl = test::file_bytes(d + "/t.mtl");
  EXPECT_NE(mtl.find("newmtl red_paint\n"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("map_Kd t_1.png"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("newmtl green\nKa 1 1 1\nKd 0 1 0\n"), std::string::npos) << mtl;
  Mesh back;
  MeshFileContents in = read_mesh_file(d + "/t.obj", back);
  ASSERT_EQ(in.materials.size(), 3u);
  EXPECT_EQ(fs::path(in.materials[0].texture_file).filename(), "t_0.png");
  EXPECT_FLOAT_EQ(in.materials[2].base_color[1], 1.f);
  auto fm = find(back, kFaceMaterial).first;
  std::vector<int> count(3, 0);
  for (FaceIndex f : back.faces()) ++count[static_cast<std::size_t>(fm[f])];
  EXPECT_EQ(count, std::vector<int>(3, static_cast<int>(m.number_of_faces() / 3)));
}

TEST(WriteMeshMaterials, TextureWithoutUvsIsRefused) {
  // A GLB whose texture has no TEXCOORD_0 is invalid glTF
  // (MESH_PRIMITIVE_TOO_FEW_TEXCOORDS): refused, nothing written.
  Mesh m;
  make_icosphere(m, 1);
  const Image tex = flat(1, 1, 0);
  const std::string d = test::temp_dir("wmm");
  WriteMeshOptions wo;
  wo.texture = &tex;
  EXPECT_THROW(write_mesh(d + "/s.glb", m, wo), InvalidInputError);
  EXPECT_FALSE(fs::exists(d + "/s.glb"));
}

// Maps encoded ahead (an OBJ and a GLB of one asset sharing them) give the
// files encoding them in each writer gives; an image with no bytes ahead is
// still encoded (the 16-bit height map here).
TEST(WriteMeshMaterials, MapsEncodedAheadGiveTheSameFiles) {
  Mesh m;
  make_torus(m, 1.0, 0.4, 12, 6);
  assign_torus_uvs(m, 1.0, 1.0, 1.0);
  const Maps maps = patterned_maps();
  const Image &color = maps.color, &normal = maps.normal, &height = maps.height;
  WriteMeshOptions o;
  o.texture = &color;
  o.normal_texture = &normal;
  o.height_texture = &height;
  const std::string dir = test::temp_dir("encoded_ahead");
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  for (const char* ext : {".obj", ".glb"}) write_mesh(dir + "/a/m" + ext, m, o);
  const std::map<const Image*, std::string> ahead = encode_png(dir + "/b/m.glb", {&color, &normal});
  ASSERT_EQ(ahead.size(), 2u);
  EXPECT_EQ(ahead.at(&color).substr(1, 3), "PNG");
  o.encoded_png = &ahead;
  for (const char* ext : {".obj", ".glb"}) write_mesh(dir + "/b/m" + ext, m, o);
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir + "/a")) {
    const std::string name = e.path().filename().string();
    EXPECT_EQ(test::file_bytes(e.path().string()), test::file_bytes(dir + "/b/" + name)) << name;
    ++files;
  }
  EXPECT_GE(files, 5u);  // obj, mtl, colour, normal, height, glb
  for (const auto& e : fs::directory_iterator(dir + "/b"))
    EXPECT_TRUE(fs::exists(dir + "/a/" + e.path().filename().string())) << e.path();  // no temporary left
  // The bytes ahead are what the OBJ's texture file holds.
  std::size_t matched = 0;
  for (const auto& e : fs::directory_iterator(dir + "/b"))
    matched += test::file_bytes(e.path().string()) == ahead.at(&color);
  EXPECT_EQ(matched, 1u);
  // The writers take the bytes given: other bytes for the colour map land in
  // the OBJ's texture file and the GLB.
  fs::create_directories(dir + "/c");
  const std::map<const Image*, std::string> swapped{{&color, ahead.at(&normal)}};
  o.encoded_png = &swapped;
  for (const char* ext : {".obj", ".glb"}) write_mesh(dir + "/c/m" + ext, m, o);
  std::size_t taken = 0;
  for (const auto& e : fs::directory_iterator(dir + "/c"))
    taken += test::file_bytes(e.path().string()) == ahead.at(&normal);
  EXPECT_EQ(taken, 2u);  // the colour file and the normal file
  EXPECT_NE(test::file_bytes(dir + "/c/m.glb"), test::file_bytes(dir + "/a/m.glb"));
}

// write_obj_and_glb: the two files of one asset written side by side, as
// write_mesh writes each alone (the GLB without the 16-bit height map it does
// not carry), every file listed, the OBJ's first, no temporary left behind.
TEST(WriteMeshMaterials, ObjAndGlbSideBySideAreTheFilesEachWriterGives) {
  Mesh m;
  make_torus(m, 1.0, 0.4, 12, 6);
  assign_torus_uvs(m, 1.0, 1.0, 1.0);
  const Maps maps = patterned_maps();
  WriteMeshOptions o;
  o.texture = &maps.color;
  o.normal_texture = &maps.normal;
  o.height_texture = &maps.height;
  WriteMeshOptions g = o;
  g.height_texture = nullptr;
  const std::string dir = test::temp_dir("obj_and_glb");
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  write_mesh(dir + "/a/m.obj", m, o);
  write_mesh(dir + "/a/m.glb", m, g);
  const std::vector<std::string> files = write_obj_and_glb(dir + "/b/m.obj", dir + "/b/m.glb", m, o, g);
  ASSERT_GE(files.size(), 6u);  // obj, mtl, colour, normal, height, glb
  EXPECT_EQ(files.front(), dir + "/b/m.obj");
  EXPECT_EQ(files.back(), dir + "/b/m.glb");
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir + "/b")) {
    const std::string name = e.path().filename().string();
    EXPECT_EQ(test::file_bytes(e.path().string()), test::file_bytes(dir + "/a/" + name)) << name;
    EXPECT_NE(std::find(files.begin(), files.end(), e.path().string()), files.end()) << name;
    ++n;
  }
  EXPECT_EQ(n, files.size());
  // The GLB embeds the very bytes of the OBJ's colour map (encoded once).
  const std::string glb = test::file_bytes(dir + "/b/m.glb"), png = test::file_bytes(dir + "/b/m.png");
  ASSERT_FALSE(png.empty());
  EXPECT_NE(glb.find(png), std::string::npos);
}
