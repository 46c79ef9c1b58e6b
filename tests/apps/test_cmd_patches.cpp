// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex patches`: outputs and report written, existing outputs protected,
// bad options and inputs refused with exit code 2.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/write_mesh.h"
#include "apps/asset_checks.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {
// A small periodic stochastic exemplar (test_apps links the geometry module only).
Image noise_exemplar(int n) {
  Image img(n, n, 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      unsigned h = static_cast<unsigned>(x * 73856093u) ^ static_cast<unsigned>(y * 19349663u);
      h = (h ^ (h >> 13)) * 0x5bd1e995u;
      const float v = static_cast<float>((h >> 8) & 255u) / 255.f;
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = 0.3f + 0.4f * v * (c + 1) / 3.f;
    }
  return img;
}
}  // namespace

TEST(CmdPatches, WritesAtlasMeshRenderReport) {
  const std::string dir = test::temp_dir("patches");
  Mesh m;
  make_icosphere(m, 2);
  write_mesh(dir + "/sphere.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  const std::string out = dir + "/out";
  const std::string cmd = "patches '" + dir + "/sphere.obj' '" + dir + "/ex.png' -o '" + out +
                          "' --patch-res 24 --max-patch-faces 40 --window 7 --rotations 16 "
                          "--resynth 0,2 --field up -q";
  auto r = test::run_surftex(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"mesh.obj", "mesh.mtl", "mesh.png", "mesh_normal.png", "mesh_height.png", "mesh.glb",
                        "render.png", "report.json"})
    EXPECT_TRUE(fs::exists(fs::path(out) / f)) << f;
  // One copy of each image (the atlas is mesh.png, no atlas.png beside it).
  EXPECT_TRUE(test::duplicate_files(out).empty()) << test::duplicate_files(out).front();
  EXPECT_FALSE(fs::exists(fs::path(out) / "atlas.png"));
  std::ifstream rf(out + "/report.json");
  const auto j = nlohmann::json::parse(rf);
  EXPECT_GT(j["patches"].get<int>(), 4);
  EXPECT_GT(j["texels_synthesized"].get<double>(), 0);
  EXPECT_GT(j["seam"]["pairs_across"].get<double>(), 0);
  EXPECT_EQ(j["resynthesized"].size(), 2u);
  const Image render = read_image(out + "/render.png");
  EXPECT_EQ(render.width, 768);
  // Existing outputs are kept unless --force.
  auto again = test::run_surftex(cmd);
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("exists"), std::string::npos) << again.err;
  auto forced = test::run_surftex(cmd + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

TEST(CmdPatches, RefusesBadInput) {
  const std::string dir = test::temp_dir("patches_bad");
  Mesh m;
  make_icosphere(m, 1);
  write_mesh(dir + "/s.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  auto missing = test::run_surftex("patches '" + dir + "/nope.obj' '" + dir + "/ex.png' -o '" + dir + "/o' -q");
  EXPECT_EQ(missing.exit_code, 2);
  auto field = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                                 "/o' --field sideways -q");
  EXPECT_NE(field.exit_code, 0);
  auto multi = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                                 "/o' --multi illumination -q");
  EXPECT_EQ(multi.exit_code, 2);
  EXPECT_NE(multi.err.find("exemplar2"), std::string::npos) << multi.err;
  auto ids = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                               "/o' --resynth 1,x -q");
  EXPECT_EQ(ids.exit_code, 2);
  auto range = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                                 "/o' --resynth 99999 --patch-res 16 -q");
  EXPECT_EQ(range.exit_code, 2);
  EXPECT_FALSE(fs::exists(dir + "/o/mesh.png"));
}

// Issue 16 items 2-3: the PBR set of one synthesis and a mip-safe atlas.
TEST(CmdPatches, WritesPbrMapsAndAPowerOfTwoAtlasWithGutters) {
  const std::string dir = test::temp_dir("patches_pbr");
  Mesh m;
  make_icosphere(m, 2);
  write_mesh(dir + "/sphere.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  const std::string out = dir + "/out";
  auto r = test::run_surftex("patches '" + dir + "/sphere.obj' '" + dir + "/ex.png' -o '" + out +
                             "' --patch-res 24 --max-patch-faces 40 --window 7 --rotations 16 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image atlas = read_image(out + "/mesh.png"), normal = read_image(out + "/mesh_normal.png");
  const Image height = read_image(out + "/mesh_height.png");
  EXPECT_EQ(atlas.width, atlas.height);
  EXPECT_EQ(atlas.width & (atlas.width - 1), 0) << atlas.width;  // power of two
  EXPECT_EQ(test::png_bit_depth(out + "/mesh_height.png"), 16);
  EXPECT_EQ(test::png_bit_depth(out + "/mesh_normal.png"), 8);
  EXPECT_GT(test::normal_follows_height(normal, height, test::chart_interior(out + "/mesh.obj", height.width, height.height)),
            0.9);
  // No black background: the dilation filled every texel.
  std::size_t black = 0;
  for (int y = 0; y < atlas.height; ++y)
    for (int x = 0; x < atlas.width; ++x) black += atlas.at(x, y, 0) + atlas.at(x, y, 1) + atlas.at(x, y, 2) == 0.f;
  EXPECT_EQ(black, 0u);
  const auto j = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(j["atlas"]["gutter"].get<int>(), atlas.width / 64);
  const nlohmann::json g = test::glb_json(out + "/mesh.glb");
  ASSERT_TRUE(g.contains("materials"));
  const auto& mat = g["materials"][0];
  EXPECT_TRUE(mat["pbrMetallicRoughness"].contains("baseColorTexture"));
  EXPECT_TRUE(mat.contains("normalTexture"));
  EXPECT_EQ(g["images"].size(), 2u);
  EXPECT_EQ(g["samplers"][0]["wrapS"], 33071);  // CLAMP_TO_EDGE: an atlas, not a periodic tile
  const std::string mtl = test::file_bytes(out + "/mesh.mtl");
  EXPECT_NE(mtl.find("map_Kd mesh.png"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("norm mesh_normal.png"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("map_Bump mesh_normal.png"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("disp mesh_height.png"), std::string::npos) << mtl;
}

// Issue 16 item 2: exemplar maps follow the very same synthesis. A height map
// that is an affine function of the colour exemplar (1 - red) comes out as
// the same function of the synthesised colour at every atlas texel; a
// constant tilted normal keeps its tilt (turned with the texture); roughness
// goes into the GLB's metallicRoughnessTexture.
TEST(CmdPatches, ExemplarMapsFollowTheColourSynthesis) {
  const std::string dir = test::temp_dir("patches_maps");
  Mesh m;
  make_icosphere(m, 2);
  write_mesh(dir + "/sphere.obj", m);
  const Image ex = noise_exemplar(32);
  write_image(dir + "/ex.png", ex);
  Image h(32, 32, 1), n(32, 32, 3), rough(32, 32, 1, 0.7f);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      h.at(x, y) = 1.f - ex.at(x, y, 0);
      n.at(x, y, 0) = 0.5f + 0.5f * 0.6f, n.at(x, y, 1) = 0.5f, n.at(x, y, 2) = 0.5f + 0.5f * 0.8f;
    }
  write_image(dir + "/h.png", h, {.eight_bit = true, .sixteen_bit = true});
  write_image(dir + "/n.png", n);
  write_image(dir + "/r.png", rough);
  const std::string out = dir + "/out";
  const std::string base = "patches '" + dir + "/sphere.obj' '" + dir + "/ex.png' --patch-res 24 --max-patch-faces 40 "
                           "--window 7 --rotations 16 -q ";
  auto r = test::run_surftex(base + "--exemplar-height '" + dir + "/h.png' --exemplar-normal '" + dir +
                             "/n.png' --exemplar-roughness '" + dir + "/r.png' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image colour = read_image(out + "/mesh.png"), height = read_image(out + "/mesh_height.png");
  const Image normal = read_image(out + "/mesh_normal.png");
  ASSERT_EQ(colour.width, height.width);
  std::size_t same = 0;
  for (int y = 0; y < colour.height; ++y)
    for (int x = 0; x < colour.width; ++x)
      same += std::abs(double(height.at(x, y, 0)) - (1.0 - colour.at(x, y, 0))) < 2.5 / 255;
  EXPECT_GT(same, colour.data.size() / 3 * 999 / 1000) << "height is not the same synthesis as the colour";
  std::size_t tilted = 0, turned = 0, texels = 0;
  for (int y = 0; y < normal.height; ++y)
    for (int x = 0; x < normal.width; ++x) {
      const double nx = 2 * normal.at(x, y, 0) - 1, ny = 2 * normal.at(x, y, 1) - 1, nz = 2 * normal.at(x, y, 2) - 1;
      ++texels;
      tilted += std::abs(nz - 0.8) < 0.05;
      turned += std::abs(ny) > 0.2;  // the field turned the tilt off the exemplar's +x
      (void)nx;
    }
  EXPECT_GT(tilted, texels * 9 / 10);
  EXPECT_GT(turned, texels / 20);
  const nlohmann::json g = test::glb_json(out + "/mesh.glb");
  EXPECT_TRUE(g["materials"][0]["pbrMetallicRoughness"].contains("metallicRoughnessTexture"));
  EXPECT_TRUE(g["materials"][0].contains("normalTexture"));
  EXPECT_TRUE(fs::exists(out + "/mesh_roughness.png"));
  EXPECT_NE(test::file_bytes(out + "/mesh.mtl").find("map_Pr"), std::string::npos);
  EXPECT_TRUE(test::duplicate_files(out).empty()) << test::duplicate_files(out).front();
  const auto j = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(j["atlas"]["normal_source"], "exemplar_normal");
  EXPECT_EQ(j["atlas"]["height_source"], "exemplar_height");
}

TEST(CmdPatches, RefusesExemplarMapsOfAnotherSizeOrMissing) {
  const std::string dir = test::temp_dir("patches_maps_bad");
  Mesh m;
  make_icosphere(m, 1);
  write_mesh(dir + "/s.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  write_image(dir + "/small.png", noise_exemplar(16));
  const std::string base = "patches '" + dir + "/s.obj' '" + dir + "/ex.png' -q -o '" + dir + "/o' ";
  for (const char* opt : {"--exemplar-normal", "--exemplar-height", "--exemplar-roughness"}) {
    auto r = test::run_surftex(base + opt + " '" + dir + "/small.png'");
    EXPECT_EQ(r.exit_code, 2) << opt;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("16 x 16"), std::string::npos) << r.err;
    r = test::run_surftex(base + opt + " '" + dir + "/nope.png'");
    EXPECT_EQ(r.exit_code, 2) << opt;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/o"));
}
