// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex synth`: output and report written for both methods,
// existing outputs protected.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "geometry/image_io.h"
#include "test_support.h"

using namespace surftex;

TEST(CmdSynth, WritesImageAndReport) {
  const std::string dir = test::temp_dir("synth");
  Image ex(16, 16, 3);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) ex.at(x, y, c) = static_cast<float>(((x / 4 + y / 4 + c) % 3) / 2.0);
  write_image(dir + "/ex.png", ex);
  auto r = test::run_surftex("synth '" + dir + "/ex.png' -o '" + dir + "/out.png' --size 24x20 --window 5 "
                             "--angle 30 --rotations 16 --seed 3 -q --report '" + dir + "/rep.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image out = read_image(dir + "/out.png");
  EXPECT_EQ(out.width, 24);
  EXPECT_EQ(out.height, 20);
  std::ifstream f(dir + "/rep.json");
  const auto j = nlohmann::json::parse(f);
  EXPECT_EQ(j["command"], "synth");
  EXPECT_GT(j["texels_per_second"].get<double>(), 0.0);
  EXPECT_GE(j["bidirectional_similarity"]["coherence"].get<double>(), 0.0);
  EXPECT_GE(j["histogram_chi_square"].get<double>(), 0.0);
  // Existing output without --force: refused, file unchanged.
  r = test::run_surftex("synth '" + dir + "/ex.png' -o '" + dir + "/out.png' --size 8x8 --window 5 -q");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(read_image(dir + "/out.png").width, 24);
  // Graph-cut synthesis: every output pixel is an exemplar colour.
  r = test::run_surftex("synth '" + dir + "/ex.png' -o '" + dir + "/g.png' --method graphcut --size 40x40 -q "
                        "--report '" + dir + "/g.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image g = read_image(dir + "/g.png");
  const Image ex8 = read_image(dir + "/ex.png");  // as quantised on disk
  EXPECT_EQ(g.width, 40);
  for (int y = 0; y < g.height; ++y)
    for (int x = 0; x < g.width; ++x) {
      bool found = false;
      for (int v = 0; v < 16 && !found; ++v)
        for (int u = 0; u < 16 && !found; ++u)
          found = g.at(x, y, 0) == ex8.at(u, v, 0) && g.at(x, y, 1) == ex8.at(u, v, 1) && g.at(x, y, 2) == ex8.at(u, v, 2);
      ASSERT_TRUE(found) << "pixel " << x << "," << y << " is not an exemplar colour";
    }
  // Graph-cut is not oriented: an angle is refused, nothing written.
  r = test::run_surftex("synth '" + dir + "/ex.png' -o '" + dir + "/ga.png' --method graphcut --angle 30 -q");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--angle"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/ga.png"));
  // Bad size names the option.
  r = test::run_surftex("synth '" + dir + "/ex.png' -o '" + dir + "/b.png' --size 0x4 -q");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
}
