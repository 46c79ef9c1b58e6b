// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex info` and `surftex convert`, run as a user would.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "geometry/read_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {
using surftex::test::q;
}  // namespace

TEST(CmdInfo, PrintsCountsAndWritesReport) {
  auto d = test::temp_dir("cli");
  auto r = test::run_surftex("info " + q(test::shared_data("meshes/elephant.off")) + " --report " +
                             q(d + "/r.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("genus:           3"), std::string::npos) << r.out;
  std::ifstream f(d + "/r.json");
  auto j = nlohmann::json::parse(f);
  EXPECT_EQ(j["faces"], 5558);
  EXPECT_EQ(j["points"], 2775);
  EXPECT_EQ(j["components"], 1);
  EXPECT_EQ(j["boundary_loops"], 0);
  EXPECT_EQ(j["genus"], 3);
  EXPECT_EQ(j["command"], "info");
}

TEST(CmdInfo, OpenMeshHasBoundaryLoopsAndNoGenus) {
  auto d = test::temp_dir("cli");
  auto r = test::run_surftex("info " + q(test::shared_data("meshes/airplane_with_holes.obj")) + " --report " +
                             q(d + "/r.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream f(d + "/r.json");
  auto j = nlohmann::json::parse(f);
  EXPECT_EQ(j["boundary_loops"], 27);
  EXPECT_TRUE(j["genus"].is_null());
}

TEST(CmdInfo, BrokenFileIsErrorExit2) {
  auto r = test::run_surftex("info " + q(test::shared_data("broken/out_of_memory_header.off")));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("353535235358"), std::string::npos) << r.err;
}

TEST(CmdConvert, ConvertsAndRefusesToOverwrite) {
  auto d = test::temp_dir("cli");
  const std::string in = test::shared_data("meshes/spot_quads.obj");
  auto r = test::run_surftex("convert " + q(in) + " -o " + q(d + "/s.ply"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto soup = read_polygon_soup(d + "/s.ply");
  EXPECT_EQ(soup.polygons.size(), 372u);  // 4 tris + 160 quads x2 + 16 pentagons x3
  r = test::run_surftex("convert " + q(in) + " -o " + q(d + "/s.ply"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  r = test::run_surftex("convert " + q(in) + " -o " + q(d + "/s.ply") + " --force --no-triangulate");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(read_polygon_soup(d + "/s.ply").polygons.size(), 180u);
  // Output equal to the input is refused even with --force.
  fs::copy_file(d + "/s.ply", d + "/t.ply");
  r = test::run_surftex("convert " + q(d + "/t.ply") + " -o " + q(d + "/t.ply") + " --force");
  EXPECT_EQ(r.exit_code, 2);
  r = test::run_surftex("convert " + q(in) + " -o " + q(d + "/s.glb") + " --texture " +
                        q(test::shared_data("textures/leather_64.png")));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(fs::file_size(d + "/s.glb"), 8000u);
}
