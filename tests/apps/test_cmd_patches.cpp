// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex patches`: outputs and report written, existing outputs protected,
// bad options and inputs refused with exit code 2.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {
// A small periodic stochastic exemplar (test_apps links the geometry module only).
Image noise_exemplar(int n) {
  Image img(n, n, 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      unsigned h = static_cast<unsigned>(x * 73856093u) ^ static_cast<unsigned>(y * 19349663u);
      h = (h ^ (h >> 13)) * 0x5bd1e995u;
      const float v = static_cast<float>((h >> 8) & 255u) / 255.f;
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = 0.3f + 0.4f * v * (c + 1) / 3.f;
    }
  return img;
}
}  // namespace

TEST(CmdPatches, WritesAtlasMeshRenderReport) {
  const std::string dir = test::temp_dir("patches");
  Mesh m;
  make_icosphere(m, 2);
  write_mesh(dir + "/sphere.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  const std::string out = dir + "/out";
  const std::string cmd = "patches '" + dir + "/sphere.obj' '" + dir + "/ex.png' -o '" + out +
                          "' --patch-res 24 --max-patch-faces 40 --window 7 --rotations 16 "
                          "--resynth 0,2 --field up -q";
  auto r = test::run_surftex(cmd);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"atlas.png", "mesh.obj", "mesh.mtl", "mesh.png", "mesh.glb", "render.png",
                        "report.json"})
    EXPECT_TRUE(fs::exists(fs::path(out) / f)) << f;
  std::ifstream rf(out + "/report.json");
  const auto j = nlohmann::json::parse(rf);
  EXPECT_GT(j["patches"].get<int>(), 4);
  EXPECT_GT(j["texels_synthesized"].get<double>(), 0);
  EXPECT_GT(j["seam"]["pairs_across"].get<double>(), 0);
  EXPECT_EQ(j["resynthesized"].size(), 2u);
  const Image render = read_image(out + "/render.png");
  EXPECT_EQ(render.width, 768);
  // Existing outputs are kept unless --force.
  auto again = test::run_surftex(cmd);
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("exists"), std::string::npos) << again.err;
  auto forced = test::run_surftex(cmd + " --force");
  EXPECT_EQ(forced.exit_code, 0) << forced.err;
}

TEST(CmdPatches, RefusesBadInput) {
  const std::string dir = test::temp_dir("patches_bad");
  Mesh m;
  make_icosphere(m, 1);
  write_mesh(dir + "/s.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  auto missing = test::run_surftex("patches '" + dir + "/nope.obj' '" + dir + "/ex.png' -o '" + dir + "/o' -q");
  EXPECT_EQ(missing.exit_code, 2);
  auto field = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                                 "/o' --field sideways -q");
  EXPECT_NE(field.exit_code, 0);
  auto multi = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                                 "/o' --multi illumination -q");
  EXPECT_EQ(multi.exit_code, 2);
  EXPECT_NE(multi.err.find("exemplar2"), std::string::npos) << multi.err;
  auto ids = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                               "/o' --resynth 1,x -q");
  EXPECT_EQ(ids.exit_code, 2);
  auto range = test::run_surftex("patches '" + dir + "/s.obj' '" + dir + "/ex.png' -o '" + dir +
                                 "/o' --resynth 99999 --patch-res 16 -q");
  EXPECT_EQ(range.exit_code, 2);
  EXPECT_FALSE(fs::exists(dir + "/o/atlas.png"));
}
