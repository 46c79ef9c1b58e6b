// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "test_support.h"
#include "texture/material_space/constrained_tile_synthesis.h"
#include "texture/material_space/material_tile.h"
#include "texture/procedural_texture.h"
#include "texture/wrap_seam_ratio.h"

using namespace surftex;

namespace {
using surftex::test::sanitized;

// Chi-square distance between 16-bin luminance histograms.
double chi_square(const Image& a, const Image& b) {
  auto hist = [](const Image& im) {
    std::vector<double> h(16, 0);
    Image l = luminance(im);
    for (float v : l.data) h[std::clamp(int(v * 16), 0, 15)] += 1.0 / l.data.size();
    return h;
  };
  auto ha = hist(a), hb = hist(b);
  double c = 0;
  for (int i = 0; i < 16; ++i)
    if (ha[i] + hb[i] > 0) c += (ha[i] - hb[i]) * (ha[i] - hb[i]) / (ha[i] + hb[i]);
  return 0.5 * c;
}

using surftex::test::cv;

MaterialTileOptions small_options() {
  MaterialTileOptions o;
  o.size = sanitized() ? 32 : 64;
  o.layers = 4;
  o.keys_are_tileable = true;
  o.seed = 5;
  return o;
}

std::vector<MaterialKey> cells_to_stripes(int size) {
  return {{make_noise(size, 4, 7), {}, "noise"}, {make_stripes(size, size / 4.0, 30), {}, "stripes"}};
}
}  // namespace

TEST(MaterialTile, EveryLayerTilesAndTheEndsAreTheKeys) {
  MaterialTileOptions o = small_options();
  MaterialTileResult r = make_material_tile(cells_to_stripes(o.size), o);
  ASSERT_EQ(r.layers.size(), 5u);
  for (std::size_t m = 0; m < r.layers.size(); ++m) {
    EXPECT_LE(wrap_seam_ratio(r.layers[m]), 1.3) << "layer " << m;
    EXPECT_EQ(r.layers[m].width, o.size);
  }
  // Keys are tileable procedural textures: layer 0 / M are exactly the keys, masks F_0 / F_M.
  EXPECT_EQ(r.layers.front().data, r.key_tiles[0].data);
  EXPECT_EQ(r.layers.back().data, r.key_tiles[1].data);
  EXPECT_EQ(r.masks.front().data, r.key_masks[0].data);
  EXPECT_EQ(r.masks.back().data, r.key_masks[1].data);
  std::vector<long long> changes(r.sign_changes.begin() + 1, r.sign_changes.end());
  EXPECT_LE(cv(changes), 0.35);
  // The intermediate layers follow their masks.
  for (double a : r.mask_agreement) EXPECT_GE(a, 0.85);
  // Guard: the seam check fails on a cut (non-tiling) image.
  Image cut(o.size * 2 / 3, o.size, 3);
  for (int y = 0; y < cut.height; ++y)
    for (int x = 0; x < cut.width; ++x)
      for (int c = 0; c < 3; ++c) cut.at(x, y, c) = r.layers[2].at(x, y, c);
  EXPECT_GT(wrap_seam_ratio(cut), 1.3);
}

TEST(MaterialTile, SynthesisedKeyTilesTileAndKeepTheHistogram) {
  // Real, non-tiling inputs: the key tiles are synthesised toroidally.
  MaterialTileOptions o = small_options();
  // Always 64 px, also under the sanitizers: at 32 px the mud key's wrap
  // ratio is 1.64 although its wrap column holds no graph-cut seam (a crack
  // of the exemplar runs along it; patch side 24 = 3/4 of the 32-px
  // resample, overlap 8). The wrap-line sample of 64 pairs is too small at
  // that size; see texture/wrap_seam_ratio.h and
  // TileableTile.At32PxTheWrapLinesCarryNoMoreSeamThanOtherLines.
  o.size = 64;
  o.keys_are_tileable = false;
  std::vector<MaterialKey> keys = {
      {read_image(test::shared_data("textures/brick_small_96.png")), {}, "brick"},
      {read_image(test::shared_data("textures/cracked_mud_100.png")), {}, "mud"}};
  MaterialTileResult r = make_material_tile(keys, o);
  for (std::size_t m = 0; m < r.layers.size(); ++m) EXPECT_LE(wrap_seam_ratio(r.layers[m]), 1.3) << m;
  Image in0 = square_resample(keys[0].texture, o.size), in1 = square_resample(keys[1].texture, o.size);
  EXPECT_LE(chi_square(r.layers.front(), in0), 0.1);
  EXPECT_LE(chi_square(r.layers.back(), in1), 0.1);
  EXPECT_GT(chi_square(in0, in1), 0.1);  // guard: the bound separates different textures
  EXPECT_EQ(r.masks.front().data, r.key_masks[0].data);
  EXPECT_EQ(r.masks.back().data, r.key_masks[1].data);
}

TEST(MaterialTile, ConstrainedSynthesisKeepsTheHistogramAndUsesMostPixels) {
  const int s = sanitized() ? 32 : 64;
  Image ex = make_cells(s, 4, 11);
  Image mask = compute_feature_mask(ex).mask;
  Image other = compute_feature_mask(make_cells(s, 4, 12)).mask;
  ConstrainedSynthesisOptions o;
  ConstrainedSynthesisResult r = synthesize_constrained_tiles(ex, mask, {mask, other}, o);
  EXPECT_EQ(r.layers[0].data, ex.data);  // identity layer
  EXPECT_GE(r.mask_agreement[1], 0.9);
  EXPECT_LE(chi_square(r.layers[1], ex), 0.06);
  EXPECT_LE(r.unused_fraction[1], 0.5);
  o.reuse_penalty = 0;
  ConstrainedSynthesisResult r0 = synthesize_constrained_tiles(ex, mask, {mask, other}, o);
  EXPECT_LE(r.unused_fraction[1], r0.unused_fraction[1]);  // the penalty spreads the usage
}

// Regression: the synthesis had its own pyramid (floor(w/2) per level) and
// refused sides not divisible by 2^(levels-1); it now uses gaussian_pyramid,
// whose levels round odd sides up, so a 63x45 tile runs at 3 levels.
TEST(MaterialTile, ConstrainedSynthesisOnAnOddSizedExemplarUsesCeilLevels) {
  Image cells = make_cells(64, 4, 11);
  Image ex(63, 45, cells.channels);
  for (int y = 0; y < ex.height; ++y)
    for (int x = 0; x < ex.width; ++x)
      for (int c = 0; c < ex.channels; ++c) ex.at(x, y, c) = cells.at(x, y, c);
  Image mask = compute_feature_mask(ex).mask;
  Image other(63, 45, 1, 0.f);
  for (int y = 0; y < 45; ++y)
    for (int x = 0; x < 63; ++x) other.at(x, y) = mask.at(62 - x, 44 - y);  // mirrored mask
  ConstrainedSynthesisOptions o;
  o.levels = 3;
  ConstrainedSynthesisResult r = synthesize_constrained_tiles(ex, mask, {mask, other}, o);
  ASSERT_EQ(r.levels, 3);
  const int want[3][2] = {{16, 12}, {32, 23}, {63, 45}};  // coarsest first
  for (int k = 0; k < 2; ++k)
    for (int l = 0; l < 3; ++l) {
      const IndirectionMap& m = r.maps[k][l];
      EXPECT_EQ(m.width, want[l][0]) << k << " " << l;
      EXPECT_EQ(m.height, want[l][1]) << k << " " << l;
      ASSERT_EQ(m.coords.size(), 2u * m.width * m.height);
      for (int j = 0; j < m.height; ++j)
        for (int i = 0; i < m.width; ++i) {
          ASSERT_TRUE(m.x(i, j) >= 0 && m.x(i, j) < want[l][0]) << k << " " << l;
          ASSERT_TRUE(m.y(i, j) >= 0 && m.y(i, j) < want[l][1]) << k << " " << l;
        }
    }
  EXPECT_EQ(r.layers[0].data, ex.data);  // identity layer
  ASSERT_EQ(r.layers[1].width, 63);
  EXPECT_GE(r.mask_agreement[1], 0.85);
  // Automatic levels on an odd size: 63x45 already has its longer side above
  // 32, and halving once more (32x23) keeps the shorter side >= 8: 2 levels.
  o.levels = 0;
  EXPECT_EQ(synthesize_constrained_tiles(ex, mask, {mask}, o).levels, 2);
  o.levels = 5;  // 63x45 -> ... -> 4x3: coarsest side below 4
  EXPECT_THROW(synthesize_constrained_tiles(ex, mask, {mask}, o), InvalidInputError);
}

TEST(MaterialTile, ChainsThreeKeys) {
  MaterialTileOptions o = small_options();
  o.layers = 2;
  auto keys = cells_to_stripes(o.size);
  keys.push_back({make_checker(o.size, 4), {}, "checker"});
  MaterialTileResult r = make_material_tile(keys, o);
  ASSERT_EQ(r.layers.size(), 5u);
  EXPECT_EQ(r.layers[2].data, r.key_tiles[1].data);
  EXPECT_EQ(r.layers[4].data, r.key_tiles[2].data);
  EXPECT_DOUBLE_EQ(r.material[3], 1.5);
}

TEST(MaterialTile, SameMaskModeGivesDifferentTilesWithOneMask) {
  MaterialTileOptions o = small_options();
  o.layers = 3;
  MaterialTileResult r = make_material_tile({{make_noise(o.size, 4, 9), {}, "noise"}}, o);
  ASSERT_EQ(r.layers.size(), 4u);
  for (std::size_t m = 1; m < r.layers.size(); ++m) {
    EXPECT_NE(r.layers[m].data, r.layers[0].data);
    EXPECT_GE(r.mask_agreement[m], 0.85);
    EXPECT_LE(wrap_seam_ratio(r.layers[m]), 1.3);
    EXPECT_EQ(r.masks[m].data, r.masks[0].data);
  }
}

TEST(MaterialTile, SameSeedSameBytesWhateverTheThreads) {
  // Parallel stages: the keys, the key pairs (three keys: two pairs), the two
  // syntheses of a pair, the exemplar levels and the finer levels' layers.
  MaterialTileOptions o = small_options();
  o.layers = 2;
  auto keys = cells_to_stripes(o.size);
  keys.push_back({make_checker(o.size, 4), {}, "checker"});
  MaterialTileResult a;
  {
    tbb::global_control two(tbb::global_control::max_allowed_parallelism, 2);
    a = make_material_tile(keys, o);
  }
  MaterialTileResult b;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    b = make_material_tile(keys, o);
  }
  ASSERT_EQ(a.layers.size(), 5u);
  ASSERT_EQ(a.layers.size(), b.layers.size());
  for (std::size_t m = 0; m < a.layers.size(); ++m) EXPECT_EQ(a.layers[m].data, b.layers[m].data) << "layer " << m;
  EXPECT_EQ(a.sign_changes, b.sign_changes);
  EXPECT_EQ(a.mask_agreement, b.mask_agreement);
  keys.pop_back();
  o.seed = 6;
  MaterialTileResult c = make_material_tile(keys, o);
  EXPECT_NE(a.layers[1].data, c.layers[1].data);
}

TEST(MaterialTile, WritesTheFolderFormat) {
  MaterialTileOptions o = small_options();
  o.layers = 2;
  MaterialTileResult r = make_material_tile(cells_to_stripes(o.size), o);
  std::string dir = test::temp_dir("mattile") + "/tile";
  MaterialTileInfo info{{"noise", "stripes"}, {"", ""}, 5, 2};
  write_material_tile(dir, r, info);
  std::vector<Image> stack = read_image_layers(dir + "/layers.tif");
  ASSERT_EQ(stack.size(), 3u);
  Image l1 = read_image(dir + "/layer_001.png");
  EXPECT_EQ(l1.width, o.size);
  for (std::size_t i = 0; i < l1.data.size(); ++i) ASSERT_NEAR(l1.data[i], r.layers[1].data[i], 0.5 / 255 + 1e-6);
  std::ifstream f(dir + "/tile.json");
  nlohmann::json j = nlohmann::json::parse(f);
  EXPECT_EQ(j["layers"], 3);
  EXPECT_EQ(j["size"], o.size);
  EXPECT_EQ(j["layer_list"][2]["mask"], "mask_002.png");
  EXPECT_EQ(j["layer_list"][1]["sign_changes"], r.sign_changes[1]);
  EXPECT_THROW(write_material_tile(dir, r, info, false), IOError);
  EXPECT_NO_THROW(write_material_tile(dir, r, info, true));
}

TEST(MaterialTile, InvalidInputsThrow) {
  EXPECT_THROW(make_material_tile({}), InvalidInputError);
  MaterialTileOptions o = small_options();
  MaterialKey bad{make_cells(64, 4, 1), Image(10, 10, 1), "bad"};
  EXPECT_THROW(make_material_tile({bad}, o), InvalidInputError);
  o.layers = 0;
  EXPECT_THROW(make_material_tile(cells_to_stripes(64), o), InvalidInputError);
}

namespace {
// Maps of a key that are known functions of its colour: height = 1 - red,
// roughness = green, normal = a tilt whose x is the red (in the image's frame).
void add_maps(MaterialKey& k) {
  const Image& c = k.texture;
  k.height = Image(c.width, c.height, 1);
  k.roughness = Image(c.width, c.height, 1);
  k.normal = Image(c.width, c.height, 3);
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) {
      const float r = c.at(x, y, 0), g = c.at(x, y, std::min(1, c.channels - 1));
      k.height.at(x, y) = 1.f - r;
      k.roughness.at(x, y) = g;
      const double nx = 0.6 * r, nz = std::sqrt(1 - nx * nx);
      k.normal.at(x, y, 0) = static_cast<float>(0.5 + 0.5 * nx);
      k.normal.at(x, y, 1) = 0.5f;
      k.normal.at(x, y, 2) = static_cast<float>(0.5 + 0.5 * nz);
    }
}

// Every map layer is the same function of its colour layer (float precision;
// normals are renormalised after the resample and the blend, so only layers
// that are not blends (`unblended`) have their tilt checked, within the
// renormalisation's change).
void expect_maps_follow_colour(const MaterialTileResult& r, const std::vector<std::size_t>& unblended) {
  ASSERT_EQ(r.height_layers.size(), r.layers.size());
  ASSERT_EQ(r.roughness_layers.size(), r.layers.size());
  ASSERT_EQ(r.normal_layers.size(), r.layers.size());
  for (std::size_t m = 0; m < r.layers.size(); ++m) {
    const Image& c = r.layers[m];
    ASSERT_EQ(r.height_layers[m].width, c.width);
    ASSERT_EQ(r.height_layers[m].channels, 1);
    ASSERT_EQ(r.normal_layers[m].channels, 3);
    for (int y = 0; y < c.height; ++y)
      for (int x = 0; x < c.width; ++x) {
        ASSERT_NEAR(r.height_layers[m].at(x, y), 1.f - c.at(x, y, 0), 1e-5) << "layer " << m << " " << x << "," << y;
        ASSERT_NEAR(r.roughness_layers[m].at(x, y), c.at(x, y, 1), 1e-5) << "layer " << m;
        const double nx = 2.0 * r.normal_layers[m].at(x, y, 0) - 1, ny = 2.0 * r.normal_layers[m].at(x, y, 1) - 1,
                     nz = 2.0 * r.normal_layers[m].at(x, y, 2) - 1;
        ASSERT_NEAR(nx * nx + ny * ny + nz * nz, 1.0, 1e-5) << "layer " << m;
        ASSERT_NEAR(ny, 0.0, 1e-6);
        ASSERT_GE(nx, -1e-6);
        if (std::find(unblended.begin(), unblended.end(), m) != unblended.end()) {
          ASSERT_NEAR(nx, 0.6 * c.at(x, y, 0), 0.02) << "layer " << m;  // the resample renormalised
        }
      }
  }
}
}  // namespace

// Issue 16 item 2: the key maps go through the colour's coordinates at every
// stage (square resample, tileable graph-cut sources, the toroidal synthesis
// of a painted-mask key, the layers' indirection maps, the blend), and the
// colour layers do not change when maps are given.
TEST(MaterialTile, KeyMapsFollowTheColourThroughEveryStage) {
  MaterialTileOptions o = small_options();
  o.size = 32;
  o.layers = 2;
  o.keys_are_tileable = false;
  // Two keys of other sizes than the tile (resample), synthesised tileable (graph cut); blend.
  std::vector<MaterialKey> keys = {{make_noise(40, 4, 7), {}, "noise"}, {make_cells(48, 4, 3), {}, "cells"}};
  const MaterialTileResult plain = make_material_tile(keys, o);
  EXPECT_TRUE(plain.height_layers.empty());
  for (auto& k : keys) add_maps(k);
  const MaterialTileResult r = make_material_tile(keys, o);
  ASSERT_EQ(r.layers.size(), plain.layers.size());
  for (std::size_t m = 0; m < r.layers.size(); ++m) EXPECT_EQ(r.layers[m].data, plain.layers[m].data) << m;
  expect_maps_follow_colour(r, {0, r.layers.size() - 1});
  // One key with a painted mask (toroidal synthesis carrying it), same-mask mode.
  MaterialKey painted{make_noise(32, 4, 11), Image(32, 32, 1, 0.f), "painted"};
  for (int y = 8; y < 20; ++y)
    for (int x = 4; x < 24; ++x) painted.mask.at(x, y) = 1.f;
  add_maps(painted);
  expect_maps_follow_colour(make_material_tile({painted}, o), {0, 1, 2});
  // Refusals: a map of another size, a kind given for one key only.
  std::vector<MaterialKey> bad = keys;
  bad[1].height = Image(47, 48, 1);
  EXPECT_THROW(make_material_tile(bad, o), InvalidInputError);
  bad = keys;
  bad[0].roughness = Image();
  EXPECT_THROW(make_material_tile(bad, o), InvalidInputError);
}
