// SPDX-License-Identifier: AGPL-3.0-or-later
// Every subcommand's --report has the one schema of apps/surftex/report.h
// (README "Reports"): surftex_version, command, command_line, seed, threads,
// inputs (path, bytes, SHA-256 as sha256sum computes it), seconds.total and
// numeric per-stage seconds, outputs (files that exist). One test per
// subcommand (the demo's is in test_cmd_demo.cpp).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/write_mesh.h"
#include "apps/report_schema.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

using surftex::test::q;

// Runs `args` with --report DIR/COMMAND_report.json and checks the report's schema.
nlohmann::json run_and_check(const std::string& dir, const std::string& command, const std::string& args,
                             const std::vector<std::string>& inputs, const std::vector<std::string>& outputs) {
  const std::string report = dir + "/" + command + "_report.json";
  const test::RunResult r = test::run_surftex(command + " " + args + " --report " + q(report) + " -q");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return {};
  std::ifstream f(report);
  const nlohmann::json j = nlohmann::json::parse(f);
  test::expect_report_schema(j, command, inputs, outputs);
  // The command line as given.
  const auto& cl = j["command_line"];
  EXPECT_EQ(cl[1], command);
  EXPECT_EQ(cl[cl.size() - 1], "-q");
  EXPECT_EQ(cl[cl.size() - 2], report);
  return j;
}

}  // namespace

TEST(ReportSchema, Convert) {
  const std::string d = test::temp_dir("schema-convert");
  const std::string in = test::shared_data("meshes/eight_genus2.off");
  const auto j = run_and_check(d, "convert", q(in) + " -o " + q(d + "/e.ply"), {in}, {d + "/e.ply"});
  EXPECT_TRUE(j["seconds"].contains("read"));
}

TEST(ReportSchema, Info) {
  const std::string d = test::temp_dir("schema-info");
  const std::string in = test::shared_data("meshes/elephant.off");
  run_and_check(d, "info", q(in), {in}, {});
}

TEST(ReportSchema, Render) {
  const std::string d = test::temp_dir("schema-render");
  const std::string in = test::shared_data("swatches/rock_1.obj"), tex = test::shared_data("textures/rock_512.png");
  const auto j = run_and_check(d, "render", q(in) + " --texture " + q(tex) + " -o " + q(d + "/r.png") + " --size 64",
                               {in, tex}, {d + "/r.png"});
  EXPECT_TRUE(j["seconds"].contains("render"));
}

TEST(ReportSchema, Repair) {
  const std::string d = test::temp_dir("schema-repair");
  const std::string in = test::shared_data("broken/degtri_sliding.off");
  run_and_check(d, "repair", q(in) + " -o " + q(d + "/r.off"), {in}, {d + "/r.off"});
}

TEST(ReportSchema, Synth) {
  const std::string d = test::temp_dir("schema-synth");
  const std::string ex = test::shared_data("textures/leather_64.png");
  const auto j = run_and_check(d, "synth", q(ex) + " -o " + q(d + "/s.png") + " --size 24x24 --window 5", {ex},
                               {d + "/s.png"});
  EXPECT_TRUE(j["seconds"].contains("synthesis"));
}

TEST(ReportSchema, Tile) {
  const std::string d = test::temp_dir("schema-tile");
  const std::string ex = test::shared_data("textures/coffee_beans_64.png");
  run_and_check(d, "tile", q(ex) + " -o " + q(d + "/t.png") + " --size 32 --preview " + q(d + "/p.png"), {ex},
                {d + "/t.png", d + "/p.png"});
}

TEST(ReportSchema, MaterialTileAndMaterialMap) {
  const std::string d = test::temp_dir("schema-material");
  const std::string a = test::shared_data("textures/brick_small_96.png"), b = test::shared_data("textures/burlap_96.png");
  const auto t = run_and_check(d, "material-tile", q(a) + " " + q(b) + " -o " + q(d + "/tile") + " --layers 2 --size 32",
                               {a, b}, {d + "/tile/tile.json"});
  EXPECT_GE(t["outputs"].size(), 4u);
  Mesh m;
  make_torus(m, 3.0, 1.0, 24, 10);
  write_mesh(d + "/torus.ply", m);
  std::ofstream(d + "/c.json") << R"({"strokes": [{"polyline": [[4, 0, 1], [0, 4, 1], [-4, 0, 1]]}],
    "material": [{"point": [4, 0, 0], "value": 1}, {"point": [-4, 0, 0], "value": 0}]})";
  const std::string md = d + "/map";
  fs::create_directory(md);
  const auto j = run_and_check(md, "material-map",
                               q(d + "/torus.ply") + " --tile " + q(d + "/tile") + " --constraints " + q(d + "/c.json") +
                                   " --render-size 48 -o " + q(d + "/out"),
                               {d + "/torus.ply", d + "/c.json", d + "/tile/tile.json"},
                               {d + "/out/mesh.glb", d + "/out/render_fixed.png", d + "/out/state.json"});
  EXPECT_TRUE(j["seconds"].contains("pgp"));
  // The report.json the command writes into its folder has the same schema.
  std::ifstream f(d + "/out/report.json");
  test::expect_report_schema(nlohmann::json::parse(f), "material-map", {d + "/torus.ply"}, {d + "/out/mesh.glb"});
}

TEST(ReportSchema, Patches) {
  const std::string d = test::temp_dir("schema-patches");
  Mesh m;
  make_icosphere(m, 1);
  write_mesh(d + "/s.obj", m);
  const std::string ex = test::shared_data("textures/leather_64.png");
  const auto j = run_and_check(d, "patches",
                               q(d + "/s.obj") + " " + q(ex) + " -o " + q(d + "/out") +
                                   " --patch-res 16 --max-patch-faces 40 --window 5 --rotations 8",
                               {d + "/s.obj", ex}, {d + "/out/mesh.glb", d + "/out/mesh.obj", d + "/out/render.png"});
  EXPECT_TRUE(j["seconds"].contains("synthesis"));
  std::ifstream f(d + "/out/report.json");
  test::expect_report_schema(nlohmann::json::parse(f), "patches", {ex}, {d + "/out/mesh.png"});
}

TEST(ReportSchema, Subdiv) {
  const std::string d = test::temp_dir("schema-subdiv");
  Mesh m;
  make_cube(m, 1.0);
  write_mesh(d + "/c.off", m);
  const std::string ex = test::shared_data("textures/leather_64.png");
  const auto j = run_and_check(d, "subdiv", q(d + "/c.off") + " " + q(ex) + " -o " + q(d + "/out") +
                                                " --levels 1 --atlas-size 64",
                               {d + "/c.off", ex},
                               {d + "/out/surface.ply", d + "/out/surface.glb", d + "/out/surface_atlas.obj",
                                d + "/out/surface_atlas.mtl", d + "/out/surface_atlas.png", d + "/out/render.png"});
  EXPECT_TRUE(j["seconds"].contains("synthesis"));
}

TEST(ReportSchema, QuiltElementsSwatch) {
  const std::string d = test::temp_dir("schema-quilt");
  run_and_check(d, "swatch", "scatter -o " + q(d + "/s.obj"), {}, {d + "/s.obj"});
  const auto j = run_and_check(d, "quilt", "--plane 1.5x1.5 " + q(d + "/s.obj") + " -o " + q(d + "/p.ply") + " --no-render",
                               {d + "/s.obj"}, {d + "/p.ply"});
  EXPECT_TRUE(j["seconds"].contains("quilt"));
  run_and_check(d, "elements", q(d + "/p.ply") + " -o " + q(d + "/e.ply"), {d + "/p.ply"}, {d + "/e.ply"});
}

TEST(ReportSchema, VersionIsTheBuildVersion) {
  // The version printed by --version is the report's surftex_version.
  const test::RunResult v = test::run_surftex("--version");
  ASSERT_EQ(v.exit_code, 0);
  const std::string d = test::temp_dir("schema-version");
  const std::string in = test::shared_data("meshes/eight_genus2.off");
  const auto j = run_and_check(d, "info", q(in), {in}, {});
  EXPECT_EQ("surftex " + j["surftex_version"].get<std::string>() + "\n", v.out);
  EXPECT_NE(j["surftex_version"].get<std::string>().find("0.1.0"), std::string::npos);
}
