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
  EXPECT_GE(j["seconds"]["synthesis"].get<double>(), 0.0);  // the shared report schema (report.h)
  // The border is rolled onto the smoothest line: the ratio there is no
  // higher than at the synthesis cut (both reported).
  EXPECT_EQ(j["choose_cut"], true);
  EXPECT_LE(j["wrap_seam_ratio"].get<double>(), j["wrap_seam_ratio_at_synthesis_cut"].get<double>());
  // --synthesis-cut keeps the synthesis cut: no roll, the two ratios agree.
  test::RunResult keep = test::run_surftex("tile '" + ex + "' -o '" + dir + "/k.png' --size 40 --synthesis-cut --report '" +
                                           dir + "/k.json' --quiet");
  ASSERT_EQ(keep.exit_code, 0) << keep.err;
  std::ifstream kin(dir + "/k.json");
  nlohmann::json k = nlohmann::json::parse(kin);
  EXPECT_EQ(k["cut_shift"], nlohmann::json::array({0, 0}));
  EXPECT_EQ(k["wrap_seam_ratio"].get<double>(), k["wrap_seam_ratio_at_synthesis_cut"].get<double>());
  EXPECT_EQ(k["wrap_seam_ratio_at_synthesis_cut"].get<double>(), j["wrap_seam_ratio_at_synthesis_cut"].get<double>());
  // The worst line of the torus does not depend on the roll.
  EXPECT_NEAR(k["worst_line_ratio"].get<double>(), j["worst_line_ratio"].get<double>(), 1e-9);
  EXPECT_EQ(k["synthesis_cut_percentile"], j["synthesis_cut_percentile"]);
  EXPECT_EQ(k["source_matched_worst_line_ratio"], j["source_matched_worst_line_ratio"]);
  EXPECT_GE(k["source_matched_worst_line_ratio"].get<double>(),
            k["source_matched_wrap_ratio_at_synthesis_cut"].get<double>() - 1e-12);
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
