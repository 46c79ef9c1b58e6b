// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <filesystem>

#include "test_support.h"

using namespace surftex;

TEST(CmdMaterialTile, WritesTheTileAndRefusesToOverwrite) {
  std::string a = test::shared_data("textures/brick_small_96.png");
  std::string b = test::shared_data("textures/cracked_mud_100.png");
  std::string out = test::temp_dir("cmd-mattile") + "/tile";
  std::string args = "material-tile '" + a + "' '" + b + "' -o '" + out + "' --layers 2 --size 32 -q";
  test::RunResult r = test::run_surftex(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"layer_000.png", "layer_002.png", "mask_001.png", "layers.tif", "tile.json"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  EXPECT_EQ(test::run_surftex(args).exit_code, 2);
  EXPECT_EQ(test::run_surftex(args + " --force").exit_code, 0);
  test::RunResult bad = test::run_surftex(args + " --force --mask '" + a + "'");  // 1 mask for 2 textures
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--mask"), std::string::npos);
}
