// SPDX-License-Identifier: AGPL-3.0-or-later
// The method subcommands repair their input mesh before use (or refuse it
// with the reason), instead of failing deep inside a method.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

TEST(CmdInputRepair, SubdivRepairsZeroAreaTrianglesBeforeTheAtlas) {
  // Before input repair, the baked atlas's LSCM failed on this mesh's
  // zero-area triangles ("LSCM gave non-finite uv").
  const std::string dir = test::temp_dir("input_repair_subdiv");
  const std::string out = dir + "/out";
  auto r = test::run_surftex("subdiv '" + test::shared_data("broken/degtri_sliding.off") + "' '" +
                             test::shared_data("textures/leather_64.png") + "' -o '" + out +
                             "' --levels 1 --atlas-size 64 --threads 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("note: repaired"), std::string::npos) << r.err;
  std::ifstream rf(out + "/report.json");
  const auto j = nlohmann::json::parse(rf);
  EXPECT_NE(j["input_mesh"]["summary"].get<std::string>().find("zero-area"), std::string::npos);
  EXPECT_TRUE(fs::exists(out + "/surface_atlas.png"));
}

TEST(CmdInputRepair, EveryMethodRefusesAMeshWithNoArea) {
  const std::string dir = test::temp_dir("input_repair_refuse");
  const std::string mesh = test::shared_data("broken/all_degen.off");
  const std::string ex = test::shared_data("textures/leather_64.png");
  for (const std::string& cmd :
       {"patches '" + mesh + "' '" + ex + "' -o '" + dir + "/p' -q",
        "subdiv '" + mesh + "' '" + ex + "' -o '" + dir + "/s' -q",
        "quilt '" + mesh + "' weave -o '" + dir + "/q.obj' -q"}) {
    auto r = test::run_surftex(cmd);
    EXPECT_EQ(r.exit_code, 2) << cmd << "\n" << r.err;
    EXPECT_NE(r.err.find("error: cannot use mesh"), std::string::npos) << cmd << "\n" << r.err;
    EXPECT_NE(r.err.find("all_degen.off"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/p/render.png"));
  EXPECT_FALSE(fs::exists(dir + "/q.obj"));
}

TEST(CmdInputRepair, SubdivAtlasTriangulatesQuadsWhoseShorterDiagonalsCoincide) {
  // Two quads glued along both edges of the valence-2 vertex b: each quad's
  // shorter diagonal is a-c, so splitting both along it would put a-c in
  // four triangles. The atlas triangulation used to fail here ("could not
  // triangulate face"); it must pick the other diagonal for the second quad.
  const std::string dir = test::temp_dir("input_repair_diag");
  {
    std::ofstream f(dir + "/quads.off");
    f << "OFF\n5 2 0\n0 0 0\n1 0.2 0\n2 0 0\n1 -3 0\n1 3 0\n4 0 1 2 3\n4 2 1 0 4\n";
  }
  auto r = test::run_surftex("subdiv '" + dir + "/quads.off' '" +
                             test::shared_data("textures/leather_64.png") + "' -o '" + dir +
                             "/out' --levels 0 --atlas-size 64 --threads 1 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir + "/out/surface_atlas.png"));
}
