// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "apps/asset_checks.h"
#include "geometry/image_io.h"
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

namespace {

namespace fs = std::filesystem;

using surftex::test::q;

// Maps of key `png` that are known functions of its colour, written beside it
// in `dir`: height = 1 - red (16-bit), roughness = green, normal tilted along
// +x by the red. Returns "--exemplar-height H --exemplar-roughness R --exemplar-normal N".
std::string write_key_maps(const std::string& png, const std::string& dir, const std::string& tag) {
  const Image c = read_image(png);
  Image h(c.width, c.height, 1), r(c.width, c.height, 1), n(c.width, c.height, 3);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      h.at(x, y) = 1.f - c.at(x, y, 0);
      r.at(x, y) = c.at(x, y, 1);
      const double nx = 0.6 * c.at(x, y, 0);
      n.at(x, y, 0) = static_cast<float>(0.5 + 0.5 * nx);
      n.at(x, y, 1) = 0.5f;
      n.at(x, y, 2) = static_cast<float>(0.5 + 0.5 * std::sqrt(1 - nx * nx));
    }
  WriteImageOptions sixteen;
  sixteen.sixteen_bit = true;
  write_image(dir + "/" + tag + "_h.png", h, sixteen);
  write_image(dir + "/" + tag + "_r.png", r);
  write_image(dir + "/" + tag + "_n.png", n);
  return " --exemplar-height " + q(dir + "/" + tag + "_h.png") + " --exemplar-roughness " +
         q(dir + "/" + tag + "_r.png") + " --exemplar-normal " + q(dir + "/" + tag + "_n.png");
}

// Fraction of the texels of every layer whose height is 1 - red of the colour
// layer within 8-bit rounding (the colour layer is 8-bit, the height 16-bit).
double height_follows_colour(const std::string& tile, int layers) {
  std::size_t ok = 0, all = 0;
  for (int l = 0; l < layers; ++l) {
    char c[64], h[64];
    std::snprintf(c, sizeof c, "/layer_%03d.png", l);
    std::snprintf(h, sizeof h, "/height_%03d.png", l);
    const Image col = read_image(tile + c), hei = read_image(tile + h);
    EXPECT_EQ(hei.channels, 1);
    EXPECT_EQ(test::png_bit_depth(tile + h), 16);
    if (hei.width != col.width || hei.height != col.height) return 0;
    for (int y = 0; y < col.height; ++y)
      for (int x = 0; x < col.width; ++x, ++all) ok += std::abs(hei.at(x, y) - (1.f - col.at(x, y, 0))) < 1.0 / 255;
  }
  return all ? double(ok) / all : 0;
}

}  // namespace

// Issue 16 item 2: exemplar maps given per key go through the same
// coordinates as the colour (resample, tileable cut, synthesis, blend): the
// height layers are 1 - red of the colour layers, for one key (same-mask
// mode) and for two keys (blend), and the colour layers are byte for byte
// those of a run without maps.
TEST(CmdMaterialTile, ExemplarMapsFollowTheColourLayers) {
  const std::string dir = test::temp_dir("cmd-mattile-maps");
  const std::string a = test::shared_data("textures/brick_small_96.png");
  const std::string b = test::shared_data("textures/cracked_mud_100.png");
  const std::string ma = write_key_maps(a, dir, "a"), mb = write_key_maps(b, dir, "b");
  const std::string opts = " --layers 2 --size 32 -q";
  // Two keys: the option of each kind once per key, in key order.
  auto r = test::run_surftex("material-tile " + q(a) + " " + q(b) + " -o " + q(dir + "/two") + opts + ma + mb);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(height_follows_colour(dir + "/two", 3), 0.999);
  r = test::run_surftex("material-tile " + q(a) + " " + q(b) + " -o " + q(dir + "/two_plain") + opts);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"layer_000.png", "layer_001.png", "layer_002.png", "mask_001.png"})
    EXPECT_EQ(test::file_bytes(dir + "/two/" + f), test::file_bytes(dir + "/two_plain/" + f)) << f;
  EXPECT_FALSE(fs::exists(dir + "/two_plain/height_000.png"));
  const nlohmann::json j = nlohmann::json::parse(std::ifstream(dir + "/two/tile.json"));
  EXPECT_EQ(j["maps"], nlohmann::json({"normal", "height", "roughness"}));
  EXPECT_EQ(j["layer_list"][1]["height"], "height_001.png");
  EXPECT_EQ(j["layer_list"][2]["normal"], "normal_002.png");
  EXPECT_EQ(j["layer_list"][0]["roughness"], "roughness_000.png");
  // Normal layers are unit tangent-space normals.
  const Image n = read_image(dir + "/two/normal_001.png");
  ASSERT_EQ(n.channels, 3);
  for (int i = 0; i < n.width * n.height; i += 7) {
    const double x = 2.0 * n.data[3 * i] - 1, y = 2.0 * n.data[3 * i + 1] - 1, z = 2.0 * n.data[3 * i + 2] - 1;
    EXPECT_NEAR(x * x + y * y + z * z, 1.0, 0.03);
  }
  // One key: same-mask mode.
  r = test::run_surftex("material-tile " + q(a) + " -o " + q(dir + "/one") + opts + ma);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(height_follows_colour(dir + "/one", 3), 0.999);
}

// A map of another size than its key, or an option given for some keys only,
// is refused before anything is written.
TEST(CmdMaterialTile, RefusesExemplarMapsOfAnotherSizeOrCount) {
  const std::string dir = test::temp_dir("cmd-mattile-maps-bad");
  const std::string a = test::shared_data("textures/brick_small_96.png");
  const std::string b = test::shared_data("textures/cracked_mud_100.png");
  write_image(dir + "/small.png", Image(40, 30, 1, 0.5f));
  const std::string base = "material-tile " + q(a) + " " + q(b) + " -o " + q(dir + "/out") + " --size 32 --layers 2 -q ";
  for (const char* opt : {"--exemplar-normal", "--exemplar-height", "--exemplar-roughness"}) {
    auto r = test::run_surftex(base + opt + " " + q(dir + "/small.png") + " " + opt + " " + q(dir + "/small.png"));
    EXPECT_EQ(r.exit_code, 2) << opt;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(opt), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("40 x 30"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("96 x 96"), std::string::npos) << r.err;
    r = test::run_surftex(base + opt + " " + q(dir + "/small.png"));  // one map for two keys
    EXPECT_EQ(r.exit_code, 2) << opt;
    EXPECT_NE(r.err.find(std::string(opt) + " given 1 times for 2 textures"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir + "/out"));
}
