// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex subdiv`'s finished asset (issue 16 items 2-3): the GLB carries the
// baked atlas (base colour, normal map from the height) beside the vertex
// colours; the atlas has mip gutters and no black background; no file twice.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "apps/asset_checks.h"
#include "geometry/image_io.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

TEST(CmdSubdivOutputs, GlbCarriesTheAtlasAndItsNormalMap) {
  const std::string dir = test::temp_dir("subdiv_outputs");
  const std::string out = dir + "/out";
  auto r = test::run_surftex("subdiv '" + test::shared_data("meshes/fish_blub.obj") + "' '" +
                             test::shared_data("textures/leather_64.png") + "' -o '" + out +
                             "' --levels 1 --atlas-size 256 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json g = test::glb_json(out + "/surface.glb");
  ASSERT_TRUE(g.contains("materials"));
  EXPECT_TRUE(g["materials"][0]["pbrMetallicRoughness"].contains("baseColorTexture"));
  EXPECT_TRUE(g["materials"][0].contains("normalTexture"));
  const auto& attr = g["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_TRUE(attr.contains("TEXCOORD_0"));
  EXPECT_TRUE(attr.contains("_COLOR"));     // the vertex colours, kept
  EXPECT_FALSE(attr.contains("COLOR_0"));   // which would multiply the texture holding them
  const Image atlas = read_image(out + "/surface_atlas.png");
  std::size_t black = 0;
  for (int y = 0; y < atlas.height; ++y)
    for (int x = 0; x < atlas.width; ++x) black += atlas.at(x, y, 0) + atlas.at(x, y, 1) + atlas.at(x, y, 2) == 0.f;
  EXPECT_EQ(black, 0u);
  EXPECT_EQ(test::png_bit_depth(out + "/surface_atlas_height.png"), 16);
  const Image height = read_image(out + "/surface_atlas_height.png");
  EXPECT_GT(test::normal_follows_height(read_image(out + "/surface_atlas_normal.png"), height,
                                        test::chart_interior(out + "/surface_atlas.obj", height.width, height.height)),
            0.9);
  EXPECT_TRUE(test::duplicate_files(out).empty()) << test::duplicate_files(out).front();
  const auto j = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(j["export"]["atlas"]["gutter"], 4);  // 256 -> 64 px: 2 halvings
  EXPECT_EQ(j["export"]["atlas"]["gutter_violations"], 0);
}
