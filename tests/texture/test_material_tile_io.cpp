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
#include "texture/material_space/material_tile.h"
#include "texture/material_space/material_tile_io.h"

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

// Map layers (issue 16 item 2): written beside the colour layers, read back
// in float, sampled like the colour; a missing map file, one of the wrong
// size or channel count, or an unknown kind is refused naming tile.json's
// line and field, before any layer is decoded.
TEST(MaterialTileIO, MapLayersRoundTripAndPreciseErrors) {
  auto with_maps = [](const std::string& tag) {
    MaterialTileResult r = tiny_tile(2);
    for (const Image& l : r.layers) {
      Image h(8, 8, 1), rough(8, 8, 1, 0.25f), n(8, 8, 3);
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
          h.at(x, y) = 1.f - l.at(x, y, 0);
          n.at(x, y, 0) = 0.8f, n.at(x, y, 1) = 0.5f, n.at(x, y, 2) = 0.9f;
        }
      r.height_layers.push_back(h);
      r.roughness_layers.push_back(rough);
      r.normal_layers.push_back(n);
    }
    const std::string dir = test::temp_dir(tag) + "/tile";
    MaterialTileInfo info;
    info.sources = {"a", "b"};
    info.masks = {"", ""};
    info.layers_per_pair = 1;
    write_material_tile(dir, r, info, true);
    return dir;
  };
  {
    const MaterialTile t = read_material_tile(with_maps("tileio-maps"));
    ASSERT_EQ(t.height_layers.size(), 2u);
    ASSERT_EQ(t.normal_layers.size(), 2u);
    ASSERT_EQ(t.roughness_layers.size(), 2u);
    EXPECT_EQ(t.normal_layers[1].channels, 3);
    for (std::size_t i = 0; i < t.layers[1].data.size() / 3; ++i)
      ASSERT_NEAR(t.height_layers[1].data[i], 1.f - t.layers[1].data[3 * i], 1.0 / 255);
    EXPECT_NEAR(sample_material_layers(t.roughness_layers, 0.3, 0.7, 0.5)[0], 0.25f, 1.0 / 255);
    EXPECT_NEAR(sample_material_layers(t.height_layers, 3.5 / 8, 0.5, 0.0)[0], 1.f - 3 / 8.f, 1e-3);
  }
  auto expect_refused = [](const std::string& dir, const std::string& what) {
    try {
      read_material_tile(dir);
      FAIL() << "no throw, expected " << what;
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  {
    const std::string dir = with_maps("tileio-maps-missing");
    fs::remove(dir + "/height_001.png");
    expect_refused(dir, "field layer_list[1].height: map file '" + dir + "/height_001.png' missing");
  }
  {
    const std::string dir = with_maps("tileio-maps-size");
    write_image(dir + "/normal_000.png", Image(8, 4, 3, 0.5f));
    expect_refused(dir, "field layer_list[0].normal: map file '" + dir + "/normal_000.png' is 8x4x3, the tile needs 8x8x3");
    write_image(dir + "/normal_000.png", Image(8, 8, 1, 0.5f));
    expect_refused(dir, "is 8x8x1, the tile needs 8x8x3");
  }
  {
    const std::string dir = with_maps("tileio-maps-kind");
    std::ofstream(dir + "/tile.json") << R"({"format": "surftex material tile", "size": 8, "channels": 3,
      "layers": 1, "layers_per_pair": 1, "maps": ["height", "gloss"],
      "layer_list": [{"m": 0, "file": "layer_000.png", "height": "height_000.png"}]})";
    expect_refused(dir, "tile.json: line 2: field maps[1]: must be \"normal\", \"height\" or \"roughness\"");
    std::ofstream(dir + "/tile.json") << R"({"format": "surftex material tile", "size": 8, "channels": 3,
      "layers": 1, "layers_per_pair": 1, "maps": ["roughness"],
      "layer_list": [{"m": 0, "file": "layer_000.png",
                      "roughness": "../roughness_000.png"}]})";
    expect_refused(dir, "tile.json: line 4: field layer_list[0].roughness: must be a file name inside the tile folder");
    std::ofstream(dir + "/tile.json") << R"({"format": "surftex material tile", "size": 8, "channels": 3,
      "layers": 1, "layers_per_pair": 1, "maps": ["roughness"],
      "layer_list": [{"m": 0, "file": "layer_000.png"}]})";
    expect_refused(dir, "tile.json: line 3: field layer_list[0].roughness: missing");
  }
}

}  // namespace
}  // namespace surftex
