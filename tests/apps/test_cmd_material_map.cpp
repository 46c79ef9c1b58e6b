// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex material-map`: outputs, and the local update through the CLI path.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "geometry/effect_area.h"
#include "geometry/material_constraints.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "geometry/write_mesh.h"
#include "apps/asset_checks.h"
#include "geometry/image_io.h"
#include "test_support.h"
#include "texture/material_tile.h"

using namespace surftex;

namespace {

std::string make_inputs(const std::string& dir) {
  Mesh m;
  make_torus(m, 3.0, 1.0, 48, 20);
  write_mesh(dir + "/torus.ply", m);
  MaterialTileResult r;
  for (int l = 0; l < 2; ++l) {
    Image img(16, 16, 3), mask(16, 16, 1, 0.f);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        img.at(x, y, 0) = ((x / 4 + y / 4) % 2) ? 1.f : 0.f;
        img.at(x, y, 1) = static_cast<float>(l);
        img.at(x, y, 2) = 0.5f;
      }
    r.layers.push_back(img);
    r.masks.push_back(mask);
    r.material.push_back(l);
    r.sign_changes.push_back(0);
    r.mask_agreement.push_back(1);
  }
  MaterialTileInfo info;
  info.sources = {"a", "b"};
  info.masks = {"", ""};
  info.layers_per_pair = 1;
  write_material_tile(dir + "/tile", r, info, true);
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
