// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex render` as a user runs it: real meshes from the shared data, the
// image it writes, and refusals of bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "geometry/image_io.h"
#include "test_support.h"

using namespace surftex;
using test::run_surftex;

namespace {
using surftex::test::q;
}  // namespace

TEST(CmdRender, RendersARealMeshFramedOnTheBackground) {
  std::string dir = test::temp_dir("render");
  std::string out = dir + "/bunny.png", rep = dir + "/r.json";
  auto r = run_surftex("render " + q(test::shared_data("meshes/bunny_6k.obj")) + " -o " + q(out) +
                       " --size 96 --view 30,20 --background 0,0,1 --report " + q(rep) + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Image img = read_image(out);
  ASSERT_EQ(img.width, 96);
  ASSERT_EQ(img.height, 96);
  // Background on every border pixel (the camera frames the whole mesh), surface in the middle.
  for (int i = 0; i < 96; ++i)
    for (auto [x, y] : {std::pair{i, 0}, std::pair{i, 95}, std::pair{0, i}, std::pair{95, i}}) {
      ASSERT_FLOAT_EQ(img.at(x, y, 2), 1.f) << x << "," << y;
      ASSERT_FLOAT_EQ(img.at(x, y, 0), 0.f) << x << "," << y;
    }
  int surface = 0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x) surface += img.at(x, y, 0) > 0.1f;
  EXPECT_GT(surface, 96 * 96 / 6);
  std::ifstream f(rep);
  nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["command"], "render");
  EXPECT_EQ(j["faces"], 6598);
  EXPECT_EQ(j["colors"], "constant");
  EXPECT_GT(j["coverage"].get<double>(), 0.15);
}

TEST(CmdRender, MapsATextureThroughTheMeshUVs) {
  std::string dir = test::temp_dir("render");
  std::string out = dir + "/spot.png";
  auto r = run_surftex("render " + q(test::shared_data("meshes/spot_quads.obj")) + " -o " + q(out) +
                       " --texture " + q(test::shared_data("textures/red_checked_384.png")) +
                       " --size 64 --ortho --no-shade --supersample 1 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Image img = read_image(out);
  Image tex = read_image(test::shared_data("textures/red_checked_384.png"));
  // Unshaded texture lookups: every surface pixel is a blend of texels, so each channel
  // stays within the texture's range, the pattern shows (channels vary), and the
  // average colour is the texture's (spot's UV atlas covers the image fairly evenly).
  double tmin[3] = {1, 1, 1}, tmax[3] = {0, 0, 0}, tmean[3] = {0, 0, 0};
  for (int y = 0; y < tex.height; ++y)
    for (int x = 0; x < tex.width; ++x)
      for (int c = 0; c < 3; ++c) {
        tmin[c] = std::min(tmin[c], double(tex.at(x, y, c)));
        tmax[c] = std::max(tmax[c], double(tex.at(x, y, c)));
        tmean[c] += tex.at(x, y, c) / (double(tex.width) * tex.height);
      }
  int surface = 0;
  double smin[3] = {1, 1, 1}, smax[3] = {0, 0, 0}, smean[3] = {0, 0, 0};
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      bool bg = img.at(x, y, 0) == 1.f && img.at(x, y, 1) == 1.f && img.at(x, y, 2) == 1.f;
      if (bg) continue;
      ++surface;
      for (int c = 0; c < 3; ++c) {
        double v = img.at(x, y, c);
        EXPECT_GE(v, tmin[c] - 1.0 / 255);
        EXPECT_LE(v, tmax[c] + 1.0 / 255);
        smin[c] = std::min(smin[c], v);
        smax[c] = std::max(smax[c], v);
        smean[c] += v;
      }
    }
  ASSERT_GT(surface, 300);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(smean[c] / surface, tmean[c], 0.06) << "channel " << c;
  EXPECT_GT(smax[2] - smin[2], 0.5);
}

TEST(CmdRender, RefusesBadInputWithAnError) {
  std::string dir = test::temp_dir("render");
  const std::string mesh = q(test::shared_data("meshes/bunny_6k.obj"));
  const std::string out = q(dir + "/o.png");
  struct Case {
    std::string args, needle;
  };
  for (const Case& c : std::vector<Case>{
           {"--size 8", "--size"},
           {"--size 9000", "--size"},
           {"--supersample 5", "--supersample"},
           {"--view 0,120", "elevation"},
           {"--view 0,nan", "--view"},
           {"--background 2,0,0", "--background"},
           {"--colors rainbow", "--colors"},
           {"--colors vertex", "vertex colours"},
           {"--texture " + q(test::shared_data("textures/wood_512.png")), "texture coordinates"},
       }) {
    auto r = run_surftex("render " + mesh + " -o " + out + " " + c.args + " --quiet");
    EXPECT_EQ(r.exit_code, 2) << c.args;
    EXPECT_NE(r.err.find("error:"), std::string::npos) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir + "/o.png")) << c.args;
  }
  // Missing input, output over the input, existing output without --force.
  auto r = run_surftex("render " + q(dir + "/none.off") + " -o " + out + " --quiet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
  r = run_surftex("render " + mesh + " -o " + mesh + " --quiet");
  EXPECT_EQ(r.exit_code, 2);
  r = run_surftex("render " + mesh + " -o " + out + " --size 16 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_surftex("render " + mesh + " -o " + out + " --size 16 --quiet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  r = run_surftex("render " + mesh + " -o " + out + " --size 16 --force --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}
