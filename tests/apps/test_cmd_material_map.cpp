// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex material-map`: outputs, and the local update through the CLI path.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "geometry/effect_area.h"
#include "texture/material_space/material_constraints.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "geometry/write_mesh.h"
#include "apps/asset_checks.h"
#include "geometry/image_io.h"
#include "test_support.h"
#include "texture/material_space/material_tile.h"

using namespace surftex;

namespace {

// Appends one layer (colour, an empty mask) to a tile result.
void add_layer(MaterialTileResult& r, const Image& img, int material) {
  r.layers.push_back(img);
  r.masks.push_back(Image(img.width, img.height, 1, 0.f));
  r.material.push_back(material);
  r.sign_changes.push_back(0);
  r.mask_agreement.push_back(1);
}

// Writes a two-layer tile of sources "a" and "b" into path.
void write_two_layer_tile(const std::string& path, const MaterialTileResult& r) {
  MaterialTileInfo info;
  info.sources = {"a", "b"};
  info.masks = {"", ""};
  info.layers_per_pair = 1;
  write_material_tile(path, r, info, true);
}

std::string make_inputs(const std::string& dir) {
  Mesh m;
  make_torus(m, 3.0, 1.0, 48, 20);
  write_mesh(dir + "/torus.ply", m);
  MaterialTileResult r;
  for (int l = 0; l < 2; ++l) {
    Image img(16, 16, 3);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        img.at(x, y, 0) = ((x / 4 + y / 4) % 2) ? 1.f : 0.f;
        img.at(x, y, 1) = static_cast<float>(l);
        img.at(x, y, 2) = 0.5f;
      }
    add_layer(r, img, l);
  }
  write_two_layer_tile(dir + "/tile", r);
  std::ofstream(dir + "/c1.json") << R"({"strokes": [{"polyline": [[4, 0, 1], [0, 4, 1], [-4, 0, 1]]}],
    "material": [{"point": [4, 0, 0], "value": 1}, {"point": [-4, 0, 0], "value": 0}]})";
  std::ofstream(dir + "/c2.json") << R"({"effect_radius": 1.5,
    "strokes": [{"faces": [10], "direction": [0, 0, 1]}],
    "scale": [{"point": [0, -4, 0], "value": 0.4}], "material": [{"point": [0, -4, 0], "value": 0.2}]})";
  return dir;
}

std::vector<double> arr(const nlohmann::json& j, const char* k) { return j.at(k).get<std::vector<double>>(); }

}  // namespace

TEST(CmdMaterialMap, WritesEverythingAndUpdatesOnlyTheEffectArea) {
  const std::string dir = make_inputs(test::temp_dir("cmd-matmap"));
  const std::string base = "material-map '" + dir + "/torus.ply' --tile '" + dir + "/tile' --render-size 96 --atlas-size 128 -q ";
  test::RunResult r = test::run_surftex(base + "--constraints '" + dir + "/c1.json' -o '" + dir + "/out1'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"mesh.obj", "mesh.mtl", "mesh.png", "mesh_normal.png", "mesh_height.png", "mesh.glb",
                        "mesh.ply", "render_plain.png", "render_fixed.png", "render_normalmap.png", "report.json",
                        "state.json"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/out1/" + f)) << f;
  nlohmann::json rep = nlohmann::json::parse(std::ifstream(dir + "/out1/report.json"));
  EXPECT_EQ(rep["faces"], 48 * 20 * 2);
  EXPECT_EQ(rep["field_source"], "strokes");
  EXPECT_GE(rep["singular_fraction"].get<double>(), 0.0);
  EXPECT_LT(rep["singular_fraction"].get<double>(), 1.0);
  EXPECT_TRUE(rep["seconds"].contains("pgp"));
  // Refuses to overwrite without --force.
  EXPECT_EQ(test::run_surftex(base + "--constraints '" + dir + "/c1.json' -o '" + dir + "/out1'").exit_code, 2);

  r = test::run_surftex(base + "--update '" + dir + "/c2.json' --state '" + dir + "/out1/state.json' -o '" + dir + "/out2'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json s1 = nlohmann::json::parse(std::ifstream(dir + "/out1/state.json"));
  const nlohmann::json s2 = nlohmann::json::parse(std::ifstream(dir + "/out2/state.json"));
  Mesh m;
  read_mesh(dir + "/torus.ply", m);
  const MaterialConstraints c2 = read_material_constraints(dir + "/c2.json", m);
  EffectAreaOptions eo;
  eo.radius = c2.effect_radius;
  const EffectArea area = compute_effect_area(m, c2.seed_vertices, eo);
  ASSERT_GT(area.free_vertices, 10u);
  ASSERT_LT(area.free_vertices, m.number_of_vertices() / 2);
  const auto zs1 = arr(s1, "z_s"), zs2 = arr(s2, "z_s"), zt1 = arr(s1, "z_t"), zt2 = arr(s2, "z_t");
  const auto sc1 = arr(s1, "scale"), sc2 = arr(s2, "scale"), m1 = arr(s1, "material"), m2 = arr(s2, "material");
  const auto d1 = arr(s1, "direction"), d2 = arr(s2, "direction");
  std::size_t changed_inside = 0;
  for (std::size_t v = 0; v < m.num_vertices(); ++v) {
    if (area.vertex_free[v]) {
      changed_inside += zs1[2 * v] != zs2[2 * v] || sc1[v] != sc2[v];
      continue;
    }
    ASSERT_EQ(zs1[2 * v], zs2[2 * v]) << v;
    ASSERT_EQ(zs1[2 * v + 1], zs2[2 * v + 1]) << v;
    ASSERT_EQ(zt1[2 * v], zt2[2 * v]) << v;
    ASSERT_EQ(zt1[2 * v + 1], zt2[2 * v + 1]) << v;
    ASSERT_EQ(sc1[v], sc2[v]) << v;
    ASSERT_EQ(m1[v], m2[v]) << v;
  }
  for (std::size_t f = 0; f < m.num_faces(); ++f)
    if (!area.face_free[f]) {
      for (int k = 0; k < 3; ++k) ASSERT_EQ(d1[3 * f + k], d2[3 * f + k]) << f;
    }
  EXPECT_GT(changed_inside, area.free_vertices / 2);
  nlohmann::json rep2 = nlohmann::json::parse(std::ifstream(dir + "/out2/report.json"));
  EXPECT_EQ(rep2["mode"], "update");
  EXPECT_EQ(rep2["effect_area"]["vertices"], area.free_vertices);

  // Errors: --update without --state, a bad constraints file.
  EXPECT_EQ(test::run_surftex(base + "--update '" + dir + "/c2.json' -o '" + dir + "/out3'").exit_code, 2);
  std::ofstream(dir + "/bad.json") << "{\n \"strokes\": 3}";
  r = test::run_surftex(base + "--constraints '" + dir + "/bad.json' -o '" + dir + "/out4'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bad.json: line 2: field strokes: must be an array"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/out4/report.json"));
}

// The curl correction (pgp_curl_correction.h) is off by default, can be turned
// on, is stored in the state and an update keeps the state's setting.
TEST(CmdMaterialMap, CurlCorrectionIsOptInAndTheStateKeepsIt) {
  const std::string dir = make_inputs(test::temp_dir("cmd-matmap-curl"));
  const std::string base =
      "material-map '" + dir + "/torus.ply' --tile '" + dir + "/tile' --render-size 64 --atlas-size 128 -q ";
  ASSERT_EQ(test::run_surftex(base + "--constraints '" + dir + "/c1.json' -o '" + dir + "/off'").exit_code, 0);
  test::RunResult r = test::run_surftex(base + "--constraints '" + dir +
                                        "/c1.json' --curl-correction -o '" + dir + "/on'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json on = nlohmann::json::parse(std::ifstream(dir + "/on/report.json"));
  const nlohmann::json off = nlohmann::json::parse(std::ifstream(dir + "/off/report.json"));
  EXPECT_EQ(on["curl_correction"], true);
  EXPECT_EQ(off["curl_correction"], false);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir + "/on/state.json"))["curl_correction"], true);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir + "/off/state.json"))["curl_correction"], false);
  // The two runs solve different targets.
  EXPECT_NE(nlohmann::json::parse(std::ifstream(dir + "/on/state.json"))["z_s"],
            nlohmann::json::parse(std::ifstream(dir + "/off/state.json"))["z_s"]);
  r = test::run_surftex(base + "--update '" + dir + "/c2.json' --state '" + dir +
                        "/on/state.json' -o '" + dir + "/update'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir + "/update/report.json"))["curl_correction"], true);
}

// --no-swap (the paper's simplified PGP, PgpOptions::swap_coordinates false)
// is off by default, is stored in the state, and an update keeps the state's
// form even without the flag (its z are in that form's frames).
TEST(CmdMaterialMap, NoSwapIsOptInAndTheStateKeepsIt) {
  const std::string dir = make_inputs(test::temp_dir("cmd-matmap-noswap"));
  const std::string base =
      "material-map '" + dir + "/torus.ply' --tile '" + dir + "/tile' --render-size 64 --atlas-size 128 -q ";
  ASSERT_EQ(test::run_surftex(base + "--constraints '" + dir + "/c1.json' -o '" + dir + "/swap'").exit_code, 0);
  test::RunResult r =
      test::run_surftex(base + "--constraints '" + dir + "/c1.json' --no-swap -o '" + dir + "/noswap'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto json = [&](const std::string& f) { return nlohmann::json::parse(std::ifstream(dir + f)); };
  EXPECT_EQ(json("/swap/report.json")["swap_coordinates"], true);
  EXPECT_EQ(json("/noswap/report.json")["swap_coordinates"], false);
  EXPECT_EQ(json("/swap/state.json")["swap_coordinates"], true);
  EXPECT_EQ(json("/noswap/state.json")["swap_coordinates"], false);
  r = test::run_surftex(base + "--update '" + dir + "/c2.json' --state '" + dir + "/noswap/state.json' -o '" + dir +
                        "/update'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json("/update/report.json")["swap_coordinates"], false);
  EXPECT_EQ(json("/update/state.json")["swap_coordinates"], false);
  r = test::run_surftex("material-map --help");
  EXPECT_NE(r.out.find("--no-swap"), std::string::npos) << r.out;
}

namespace {
double psnr(const Image& a, const Image& b) {
  EXPECT_EQ(a.data.size(), b.data.size());
  double se = 0;
  for (std::size_t i = 0; i < std::min(a.data.size(), b.data.size()); ++i)
    se += (a.data[i] - b.data[i]) * (a.data[i] - b.data[i]);
  return 10 * std::log10(1.0 / std::max(se / static_cast<double>(a.data.size()), 1e-20));
}
}  // namespace

// Issue 16 item 1: the mapping baked into a standard asset. surftex's render of
// the written mesh with its own texture (the OBJ's uv and mesh.png, through
// `surftex render`) matches the singularity-fixed render at >= 30 dB; the GLB
// carries the atlas as base colour and its normal map; no file twice.
TEST(CmdMaterialMap, BakedAssetRendersLikeTheFixedRender) {
  const std::string dir = make_inputs(test::temp_dir("cmd-matmap-bake"));
  const std::string out = dir + "/out";
  test::RunResult r = test::run_surftex("material-map '" + dir + "/torus.ply' --tile '" + dir +
                                        "/tile' --render-size 256 --atlas-size 1024 -q --constraints '" + dir +
                                        "/c1.json' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_surftex("render '" + out + "/mesh.obj' --texture '" + out + "/mesh.png' --clamp --size 256 -q -o '" +
                        dir + "/obj_render.png'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double db = psnr(read_image(out + "/render_fixed.png"), read_image(dir + "/obj_render.png"));
  EXPECT_GE(db, 30.0);
  // The plain (unfixed) render is further away: the bake holds the fix.
  EXPECT_LT(psnr(read_image(out + "/render_plain.png"), read_image(dir + "/obj_render.png")), db);
  // The GLB as a glTF viewer shows it (its embedded base-colour texture, its
  // own sampler), with no texture given on the command line.
  r = test::run_surftex("render '" + out + "/mesh.glb' --size 256 -q -o '" + dir + "/glb_render.png'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double glb_db = psnr(read_image(out + "/render_fixed.png"), read_image(dir + "/glb_render.png"));
  EXPECT_GE(glb_db, 30.0);
  EXPECT_LT(psnr(read_image(out + "/render_plain.png"), read_image(dir + "/glb_render.png")), glb_db);
  const nlohmann::json g = test::glb_json(out + "/mesh.glb");
  ASSERT_TRUE(g.contains("materials"));
  EXPECT_TRUE(g["materials"][0]["pbrMetallicRoughness"].contains("baseColorTexture"));
  EXPECT_TRUE(g["materials"][0].contains("normalTexture"));
  EXPECT_TRUE(g["meshes"][0]["primitives"][0]["attributes"].contains("TEXCOORD_0"));
  EXPECT_TRUE(g["meshes"][0]["primitives"][0]["attributes"].contains("_material"));
  EXPECT_TRUE(test::duplicate_files(out).empty()) << test::duplicate_files(out).front();
  EXPECT_EQ(test::png_bit_depth(out + "/mesh_height.png"), 16);
  const Image height = read_image(out + "/mesh_height.png");
  EXPECT_GT(test::normal_follows_height(read_image(out + "/mesh_normal.png"), height,
                                        test::chart_interior(out + "/mesh.obj", height.width, height.height)),
            0.9);
  const nlohmann::json rep = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(rep["atlas"]["size"], 1024);
  EXPECT_EQ(rep["atlas"]["gutter"], 16);
  EXPECT_EQ(rep["atlas"]["gutter_violations"], 0);
}

namespace {

// A tile like make_inputs' with map layers that are functions of its colour:
// height = 1 - red, roughness = 0.25 + 0.5 red; and flat normal layers.
void write_tile_with_maps(const std::string& dir) {
  MaterialTileResult r;
  for (int l = 0; l < 2; ++l) {
    Image img(16, 16, 3), h(16, 16, 1), rough(16, 16, 1);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        img.at(x, y, 0) = static_cast<float>(((x + 3 * y + 5 * l) % 16) / 15.0);
        img.at(x, y, 1) = static_cast<float>(l);
        img.at(x, y, 2) = 0.5f;
        h.at(x, y) = 1.f - img.at(x, y, 0);
        rough.at(x, y) = 0.25f + 0.5f * img.at(x, y, 0);
      }
    add_layer(r, img, l);
    r.height_layers.push_back(h);
    r.roughness_layers.push_back(rough);
    Image flat(16, 16, 3, 0.5f);
    for (int i = 0; i < 16 * 16; ++i) flat.data[3 * i + 2] = 1.f;
    r.normal_layers.push_back(flat);
  }
  write_two_layer_tile(dir + "/tile_maps", r);
}

}  // namespace

// Issue 16 item 2: a tile's map layers are baked through the same (s,t,m)
// lookups as the colour (material blend, section 3's three lookups):
// mesh_height.png is 1 - red of mesh.png, the roughness lands in the GLB's
// metallicRoughnessTexture (G) and the MTL's map_Pr, flat tile normals give a
// flat tangent-space map, and the report names the sources.
TEST(CmdMaterialMap, TileMapsAreBakedThroughTheColourLookups) {
  const std::string dir = make_inputs(test::temp_dir("cmd-matmap-maps"));
  write_tile_with_maps(dir);
  const std::string out = dir + "/out";
  test::RunResult r = test::run_surftex("material-map '" + dir + "/torus.ply' --tile '" + dir +
                                        "/tile_maps' --render-size 64 --atlas-size 128 -q --constraints '" + dir +
                                        "/c1.json' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image colour = read_image(out + "/mesh.png"), height = read_image(out + "/mesh_height.png");
  ASSERT_EQ(colour.width, height.width);
  const std::vector<char> inside = test::chart_interior(out + "/mesh.obj", colour.width, colour.height);
  std::size_t texels = 0, same = 0;
  for (int y = 0; y < colour.height; ++y)
    for (int x = 0; x < colour.width; ++x) {
      if (!inside[static_cast<std::size_t>(y) * colour.width + x]) continue;
      ++texels;
      same += std::abs(height.at(x, y, 0) - (1.f - colour.at(x, y, 0))) < 1.0 / 255;
    }
  ASSERT_GT(texels, 1000u);
  EXPECT_GT(same, texels * 999 / 1000) << "height is not baked through the colour's lookups";
  const Image normal = read_image(out + "/mesh_normal.png");
  std::size_t flat = 0;
  for (int y = 0; y < normal.height; ++y)
    for (int x = 0; x < normal.width; ++x)
      flat += inside[static_cast<std::size_t>(y) * normal.width + x] && std::abs(normal.at(x, y, 0) - 0.5f) < 0.01f &&
              std::abs(normal.at(x, y, 1) - 0.5f) < 0.01f && normal.at(x, y, 2) > 0.99f;
  EXPECT_GT(flat, texels * 999 / 1000);
  // The roughness, read back from the GLB as a viewer would.
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, out + "/mesh.glb")) << err;
  ASSERT_FALSE(model.materials.empty());
  const int t = model.materials[0].pbrMetallicRoughness.metallicRoughnessTexture.index;
  ASSERT_GE(t, 0);
  const auto& img = model.images[static_cast<std::size_t>(model.textures[static_cast<std::size_t>(t)].source)];
  ASSERT_EQ(img.width, colour.width);
  ASSERT_GE(img.component, 3);
  std::size_t rough_ok = 0;
  for (int y = 0; y < colour.height; ++y)
    for (int x = 0; x < colour.width; ++x) {
      if (!inside[static_cast<std::size_t>(y) * colour.width + x]) continue;
      const std::size_t i = static_cast<std::size_t>(y) * img.width + x;
      const double g = img.image[i * img.component + 1] / 255.0, b = img.image[i * img.component + 2] / 255.0;
      rough_ok += std::abs(g - (0.25 + 0.5 * colour.at(x, y, 0))) < 1.5 / 255 && b == 0;
    }
  EXPECT_GT(rough_ok, texels * 999 / 1000);
  EXPECT_NE(test::file_bytes(out + "/mesh.mtl").find("map_Pr"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out + "/mesh_roughness.png"));
  EXPECT_TRUE(test::duplicate_files(out).empty()) << test::duplicate_files(out).front();
  const nlohmann::json rep = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(rep["atlas"]["height_source"], "exemplar_height");
  EXPECT_EQ(rep["atlas"]["normal_source"], "exemplar_normal");
  EXPECT_EQ(rep["atlas"]["roughness"], true);
  EXPECT_EQ(rep["tile"]["maps"], nlohmann::json({"normal", "height", "roughness"}));
  // Without maps: the luminance, no roughness.
  r = test::run_surftex("material-map '" + dir + "/torus.ply' --tile '" + dir +
                        "/tile' --render-size 64 --atlas-size 128 -q -o '" + dir + "/plain'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json plain = nlohmann::json::parse(std::ifstream(dir + "/plain/report.json"));
  EXPECT_EQ(plain["atlas"]["height_source"], "luminance");
  EXPECT_EQ(plain["atlas"]["normal_source"], "height");
  EXPECT_EQ(plain["atlas"]["roughness"], false);
  EXPECT_FALSE(std::filesystem::exists(dir + "/plain/mesh_roughness.png"));
}
