// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_support.h"

using namespace surftex;

TEST(CmdTile, WritesTilePreviewAndReportAndRefusesOverwrite) {
  const std::string dir = test::temp_dir("tile");
  const std::string ex = test::shared_data("textures/leather_64.png");
  const std::string args = "tile '" + ex + "' -o '" + dir + "/t.png' --size 40 --preview '" + dir +
                           "/p.png' --report '" + dir + "/r.json' --quiet";
  test::RunResult r = test::run_surftex(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir + "/t.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/p.png"));
  std::ifstream in(dir + "/r.json");
  nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["command"], "tile");
  EXPECT_LE(j["wrap_seam_ratio"].get<double>(), 1.3);
  EXPECT_GE(j["seconds"].get<double>(), 0.0);
  // Existing output without --force: error, exit 2.
  test::RunResult again = test::run_surftex(args);
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("already exists"), std::string::npos);
  // Overlap not smaller than the patch: error naming the option, no file left.
  test::RunResult bad = test::run_surftex("tile '" + ex + "' -o '" + dir +
                                          "/u.png' --size 40 --patch 8 --overlap 8 --quiet");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("overlap"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir + "/u.png"));
}
