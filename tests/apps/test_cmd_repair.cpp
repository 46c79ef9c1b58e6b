// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex repair`: writes a repaired mesh and a report, refuses (exit 2,
// nothing written) what cannot be repaired, and never overwrites silently.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

TEST(CmdRepair, FillsHoleWritesMeshAndReport) {
  const std::string dir = test::temp_dir("repair");
  const std::string in = test::shared_data("broken/cube_open_isolated_vertex.off");
  const std::string args = "repair '" + in + "' -o '" + dir + "/cube.off' --fill-holes --report '" +
                           dir + "/r.json' --quiet";
  test::RunResult r = test::run_surftex(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir + "/cube.off"));
  std::ifstream rin(dir + "/r.json");
  nlohmann::json j = nlohmann::json::parse(rin);
  EXPECT_EQ(j["command"], "repair");
  EXPECT_TRUE(j["valid"].get<bool>());
  EXPECT_EQ(j["found"]["boundary_loops"], 1);
  EXPECT_EQ(j["done"]["holes_filled"], 1);
  EXPECT_EQ(j["load"]["isolated_points_removed"], 1);
  EXPECT_TRUE(j["result"]["closed"].get<bool>());
  EXPECT_EQ(j["result"]["faces"], 12);
  EXPECT_GE(j["seconds"]["repair"].get<double>(), 0.0);
  // The written mesh reads back closed: repairing it again finds no hole.
  test::RunResult again = test::run_surftex("repair '" + dir + "/cube.off' -o '" + dir +
                                            "/cube2.off' --report '" + dir + "/r2.json' --quiet");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  std::ifstream rin2(dir + "/r2.json");
  nlohmann::json j2 = nlohmann::json::parse(rin2);
  EXPECT_EQ(j2["found"]["boundary_loops"], 0);
  EXPECT_EQ(j2["result"]["faces"], 12);
  // Existing output without --force: refused; with --force: replaced.
  test::RunResult exists = test::run_surftex(args);
  EXPECT_EQ(exists.exit_code, 2);
  EXPECT_NE(exists.err.find("already exists"), std::string::npos);
  EXPECT_EQ(test::run_surftex(args + " --force").exit_code, 0);
  // Output equal to the input: refused.
  test::RunResult same = test::run_surftex("repair '" + dir + "/cube.off' -o '" + dir +
                                           "/cube.off' --force --quiet");
  EXPECT_EQ(same.exit_code, 2);
}

TEST(CmdRepair, RefusesUnrepairableMeshAndWritesNothing) {
  const std::string dir = test::temp_dir("repair-refuse");
  test::RunResult r = test::run_surftex("repair '" + test::shared_data("broken/all_degen.off") +
                                        "' -o '" + dir + "/out.ply' --report '" + dir +
                                        "/r.json' --quiet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("nothing left"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out.ply"));
  EXPECT_FALSE(fs::exists(dir + "/r.json"));
  EXPECT_TRUE(fs::is_empty(dir));
  // An unreadable file: the reader's error, exit 2, nothing written.
  test::RunResult bad = test::run_surftex("repair '" + test::shared_data("broken/truncated.off") +
                                          "' -o '" + dir + "/t.ply' --quiet");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_EQ(bad.err.rfind("error: ", 0), 0u) << bad.err;
  EXPECT_TRUE(fs::is_empty(dir));
}
