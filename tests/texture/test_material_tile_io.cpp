// SPDX-License-Identifier: AGPL-3.0-or-later
// Reading a material tile folder back (the format of write_material_tile) and
// the trilinear (s,t,m) lookup.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "test_support.h"
#include "texture/material_tile.h"
#include "texture/material_tile_io.h"

namespace surftex {
namespace {

namespace fs = std::filesystem;

// Layer l: texel (x,y) = (x/8 + l, y/8, 0.25 l) (8-bit friendly values).
MaterialTileResult tiny_tile(int layers) {
  MaterialTileResult r;
  for (int l = 0; l < layers; ++l) {
    Image img(8, 8, 3), mask(8, 8, 1, 0.f);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        img.at(x, y, 0) = x / 8.f;
        img.at(x, y, 1) = y / 8.f;
        img.at(x, y, 2) = 0.25f * l;
      }
    r.layers.push_back(img);
    r.masks.push_back(mask);
    r.material.push_back(l / double(layers - 1));
    r.sign_changes.push_back(0);
    r.mask_agreement.push_back(1.0);
  }
  return r;
}

std::string write_tiny(const std::string& tag, int layers = 3) {
  const std::string dir = test::temp_dir(tag) + "/tile";
  MaterialTileInfo info;
  info.sources = {"a", "b"};
  info.masks = {"", ""};
  info.layers_per_pair = layers - 1;
  write_material_tile(dir, tiny_tile(layers), info, true);
  return dir;
}

TEST(MaterialTileIO, ReadsWhatWriteMaterialTileWrote) {
  const std::string dir = write_tiny("tileio-rt");
  const MaterialTile t = read_material_tile(dir);
  ASSERT_EQ(t.layers.size(), 3u);
  EXPECT_EQ(t.size, 8);
  EXPECT_EQ(t.layers_per_pair, 2);
  EXPECT_DOUBLE_EQ(t.material[2], 1.0);
  const MaterialTileResult ref = tiny_tile(3);
  for (int l = 0; l < 3; ++l)
    for (std::size_t i = 0; i < ref.layers[l].data.size(); ++i)
      ASSERT_NEAR(t.layers[l].data[i], ref.layers[l].data[i], 1.0 / 255) << "layer " << l << " value " << i;
}

TEST(MaterialTileIO, TrilinearLookupWrapsAndInterpolates) {
  const MaterialTile t = read_material_tile(write_tiny("tileio-sample"));
  // Texel centre (x=3, y=5) of layer 0 at s = 3.5/8, t = 5.5/8, m = 0.
  Vec3f c = sample_material_tile(t, 3.5 / 8, 5.5 / 8, 0.0);
  EXPECT_NEAR(c[0], 3 / 8.f, 1e-2);
  EXPECT_NEAR(c[1], 5 / 8.f, 1e-2);
  EXPECT_NEAR(c[2], 0.f, 1e-2);
  // Periodic in s and t.
  const Vec3f w = sample_material_tile(t, 3.5 / 8 + 2, 5.5 / 8 - 3, 0.0);
  for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(w[k], c[k]);
  // Bilinear between texels 3 and 4.
  c = sample_material_tile(t, 3.75 / 8, 5.5 / 8, 0.0);
  EXPECT_NEAR(c[0], 3.25f / 8, 1e-2);
  // Across the wrap: between texel 7 (7/8) and texel 0 (0): half way.
  c = sample_material_tile(t, 0.0, 5.5 / 8, 0.0);
  EXPECT_NEAR(c[0], 3.5f / 8, 1e-2);
  // m: 3 layers at m = 0, 0.5, 1; blue = 0, 0.25, 0.5. m = 0.75 -> 0.375; clamped outside.
  EXPECT_NEAR(sample_material_tile(t, 0.3, 0.3, 0.75)[2], 0.375f, 1e-2);
  EXPECT_NEAR(sample_material_tile(t, 0.3, 0.3, 0.25)[2], 0.125f, 1e-2);
  EXPECT_NEAR(sample_material_tile(t, 0.3, 0.3, 7.0)[2], 0.5f, 1e-2);
  EXPECT_NEAR(sample_material_tile(t, 0.3, 0.3, -1.0)[2], 0.0f, 1e-2);
}

TEST(MaterialTileIO, PreciseErrors) {
  {
    const std::string dir = write_tiny("tileio-missing");
    fs::remove(dir + "/layer_001.png");
    try {
      read_material_tile(dir);
      FAIL() << "no throw";
    } catch (const IOError& e) {
      EXPECT_NE(std::string(e.what()).find("layer_001.png"), std::string::npos) << e.what();
    }
  }
  {
    const std::string dir = write_tiny("tileio-size");
    write_image(dir + "/layer_002.png", Image(4, 8, 3, 0.5f));
    try {
      read_material_tile(dir);
      FAIL() << "no throw";
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find("layer_002.png' is 4x8x3"), std::string::npos) << e.what();
    }
  }
  {
    const std::string dir = write_tiny("tileio-json");
    std::ofstream(dir + "/tile.json") << "{\"format\": \"surftex material tile\", \"size\": 8,";
    try {
      read_material_tile(dir);
      FAIL() << "no throw";
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find("malformed JSON"), std::string::npos) << e.what();
    }
  }
  {
    const std::string dir = write_tiny("tileio-field");
    std::ofstream(dir + "/tile.json") << R"({"format": "surftex material tile", "size": 8, "channels": 3,
      "layers": 1, "layers_per_pair": 1, "layer_list": [{"file": "layer_000.png"}]})";
    try {
      read_material_tile(dir);
      FAIL() << "no throw";
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find("tile.json: line 2: field layer_list[0].m: missing"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(read_material_tile(test::temp_dir("tileio-none")), IOError);
}

}  // namespace
}  // namespace surftex
