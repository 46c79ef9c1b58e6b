// SPDX-License-Identifier: AGPL-3.0-or-later
// An exemplar with a transparent hole whose stored colour is black, for the
// methods whose outputs have no alpha (subdiv, patches): the hole's black is
// not copied onto the surface (command.h, use_opaque_part).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <string>

#include "apps/asset_checks.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

using namespace surftex;

namespace {

// 64 x 64 RGBA noise (green and blue >= 0.3, red >= 0.2) with a 20 x 20 hole
// in the middle: alpha 0 over black, as photo editors store a cut-out.
Image noise_with_black_hole() {
  Image img(64, 64, 4);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      unsigned h = static_cast<unsigned>(x * 2654435761u) ^ static_cast<unsigned>(y * 40503u);
      h = (h ^ (h >> 15)) * 0x2c1b3c6du;
      const float v = static_cast<float>((h >> 8) & 255u) / 255.f;
      const bool hole = x >= 22 && x < 42 && y >= 22 && y < 42;
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = hole ? 0.f : 0.3f + 0.5f * v * (c + 1) / 3.f - (c == 0 ? 0.1f : 0.f);
      img.at(x, y, 3) = hole ? 0.f : 1.f;
    }
  return img;
}

// Chart-interior texels of an atlas whose green + blue is below 0.3 (the
// noise has at least 0.6: only the hole's black, or a blend with it, is).
std::size_t dark_texels(const std::string& atlas_png, const std::string& atlas_mesh, std::size_t& texels) {
  const Image a = read_image(atlas_png);
  const std::vector<char> in = test::chart_interior(atlas_mesh, a.width, a.height);
  std::size_t dark = 0;
  texels = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      if (!in[static_cast<std::size_t>(y) * a.width + x]) continue;
      ++texels;
      dark += a.at(x, y, 1) + a.at(x, y, 2) < 0.3f;
    }
  return dark;
}

std::string sphere_and_exemplar(const std::string& dir) {
  Mesh m;
  make_icosphere(m, 2);
  write_mesh(dir + "/sphere.obj", m);
  write_image(dir + "/holed.png", noise_with_black_hole());
  return "'" + dir + "/sphere.obj' '" + dir + "/holed.png'";
}

}  // namespace

// Before: the hole (10% of the exemplar) came out as black patches; now the
// exemplar's largest opaque block (64 x 22) is used, said in a note and the report.
TEST(TransparentExemplar, SubdivDoesNotCopyTheHolesColour) {
  const std::string dir = test::temp_dir("transparent_subdiv");
  const std::string out = dir + "/out";
  auto r = test::run_surftex("subdiv " + sphere_and_exemplar(dir) + " --texel-size 2x --atlas-size 256 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("largest opaque block is used, 64x22"), std::string::npos) << r.err;
  std::size_t texels = 0;
  EXPECT_EQ(dark_texels(out + "/surface_atlas.png", out + "/surface_atlas.obj", texels), 0u);
  EXPECT_GT(texels, 5000u);
  const auto j = test::read_json(out + "/report.json");
  EXPECT_EQ(j["exemplar_transparency"]["cropped"], true);
  EXPECT_EQ(j["exemplar_transparency"]["opaque_block"], nlohmann::json({0, 0, 64, 22}));
  EXPECT_NEAR(j["exemplar_transparency"]["transparent_share"].get<double>(), 400.0 / 4096, 1e-9);
}

TEST(TransparentExemplar, PatchesDoNotCopyTheHolesColour) {
  const std::string dir = test::temp_dir("transparent_patches");
  const std::string out = dir + "/out";
  auto r = test::run_surftex("patches " + sphere_and_exemplar(dir) + " --patch-res 48 -q -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::size_t texels = 0;
  EXPECT_EQ(dark_texels(out + "/mesh.png", out + "/mesh.obj", texels), 0u);
  EXPECT_GT(texels, 5000u);
  EXPECT_EQ(test::read_json(out + "/report.json")["exemplar_transparency"]["opaque_block"],
            nlohmann::json({0, 0, 64, 22}));
}

// The second exemplar of multi-texturing goes through the same crop, named in
// its note and reported on its own (before: "the exemplar" and no record).
TEST(TransparentExemplar, PatchesSecondExemplarIsCroppedNamedAndReported) {
  const std::string dir = test::temp_dir("transparent_patches2");
  const std::string out = dir + "/out";
  sphere_and_exemplar(dir);  // writes sphere.obj and holed.png (the second exemplar)
  Image opaque = noise_with_black_hole();
  for (int y = 0; y < opaque.height; ++y)
    for (int x = 0; x < opaque.width; ++x) {
      opaque.at(x, y, 3) = 1.f;
      if (opaque.at(x, y, 1) < 0.3f) opaque.at(x, y, 1) = opaque.at(x, y, 2) = 0.5f;
    }
  write_image(dir + "/opaque.png", opaque);
  auto r = test::run_surftex("patches '" + dir + "/sphere.obj' '" + dir + "/opaque.png' --exemplar2 '" + dir +
                             "/holed.png' --multi height --patch-res 48 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("the second exemplar (--exemplar2) has 9.8% transparent pixels: its largest opaque block is "
                       "used, 64x22"),
            std::string::npos)
      << r.err;
  std::size_t texels = 0;
  EXPECT_EQ(dark_texels(out + "/mesh.png", out + "/mesh.obj", texels), 0u);
  EXPECT_GT(texels, 5000u);
  const auto j = test::read_json(out + "/report.json");
  EXPECT_FALSE(j.contains("exemplar_transparency"));
  EXPECT_EQ(j["exemplar2_transparency"]["opaque_block"], nlohmann::json({0, 0, 64, 22}));
}
