// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex demo`: one run, checked for what a user opens (issue 16 items 5-8):
// every GLB it writes passes the Khronos glTF-Validator with no error and no
// warning; its tori lie flat in a Y-up viewer; torus_tiled.obj's texture is
// the tile (not a render of the torus); its report has the shared schema and
// lists every file it wrote.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "apps/report_schema.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

std::string map_kd(const std::string& mtl) {
  std::ifstream f(mtl);
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("map_Kd ", 0) == 0) return line.substr(7);
  return {};
}

std::array<double, 3> extent(const std::string& glb) {
  Mesh m;
  read_mesh(glb, m);
  std::array<double, 3> lo{1e30, 1e30, 1e30}, hi{-1e30, -1e30, -1e30};
  for (VertexIndex v : m.vertices())
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], m.point(v)[c]);
      hi[c] = std::max(hi[c], m.point(v)[c]);
    }
  return {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
}

// The steps' entries use the report schema's names (issue 16 item 7): files
// under "outputs" (names under the demo folder, each existing), times under
// "seconds" as an object of numbers; no "files", "seconds_total" or "timings".
void expect_step_keys_follow_the_schema(const nlohmann::json& j, const std::string& dir, const std::string& at = "steps") {
  if (j.is_array()) {
    for (const auto& v : j) expect_step_keys_follow_the_schema(v, dir, at + "[]");
    return;
  }
  if (!j.is_object()) return;
  for (const auto& [k, v] : j.items()) {
    const std::string where = at + "." + k;
    EXPECT_TRUE(k != "files" && k != "seconds_total" && k != "timings") << where;
    if (k == "seconds") {
      EXPECT_TRUE(v.is_object()) << where;
      for (const auto& [stage, s] : v.items()) EXPECT_TRUE(s.is_number()) << where << "." << stage;
    } else if (k == "outputs") {
      ASSERT_TRUE(v.is_array()) << where;
      for (const auto& f : v) EXPECT_TRUE(fs::is_regular_file(fs::path(dir) / f.get<std::string>())) << where << ": " << f;
    } else {
      expect_step_keys_follow_the_schema(v, dir, where);
    }
  }
}

}  // namespace

TEST(CmdDemo, WritesValidUprightAssetsAndOneReport) {
  const std::string out = test::temp_dir("demo") + "/out";
  const test::RunResult r = test::run_surftex("demo -o '" + out + "' --threads 2 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;

  std::vector<std::string> glbs;
  for (const auto& e : fs::recursive_directory_iterator(out))
    if (e.path().extension() == ".glb") glbs.push_back(e.path().string());
  std::sort(glbs.begin(), glbs.end());
  ASSERT_GE(glbs.size(), 5u);
  int errors = 0, warnings = 0, infos = 0, hints = 0;
  for (const auto& v : test::validate_glbs(glbs)) {
    EXPECT_EQ(v.errors, 0) << v.file << "\n" << v.messages;
    EXPECT_EQ(v.warnings, 0) << v.file << "\n" << v.messages;
    errors += v.errors, warnings += v.warnings, infos += v.infos, hints += v.hints;
  }
  std::printf("glTF-Validator over the demo's %zu GLBs: %d errors, %d warnings, %d infos, %d hints\n", glbs.size(),
              errors, warnings, infos, hints);

  // Item 6: +Y up; the demo's tori lie flat (their axis along y).
  for (const char* f : {"torus_tiled.glb", "patches/mesh.glb", "material_map.glb"}) {
    const auto e = extent(out + "/" + f);
    EXPECT_LT(e[1], 0.6 * std::min(e[0], e[2])) << f << ": extent " << e[0] << " " << e[1] << " " << e[2];
  }

  // Item 8: the OBJ's map_Kd is the tile itself, pixel for pixel.
  const std::string tex = map_kd(out + "/torus_tiled.mtl");
  ASSERT_FALSE(tex.empty());
  const Image mapped = read_image(out + "/" + tex), tile = read_image(out + "/tile_noise.png");
  ASSERT_EQ(mapped.width, tile.width);
  ASSERT_EQ(mapped.height, tile.height);
  for (std::size_t i = 0; i < tile.data.size(); ++i) ASSERT_NEAR(mapped.data[i], tile.data[i], 1e-6) << i;
  EXPECT_TRUE(fs::exists(out + "/torus_tiled_render.png"));

  // Item 7: the report's schema; every GLB and the torus files among its outputs.
  std::ifstream rf(out + "/report.json");
  const nlohmann::json j = nlohmann::json::parse(rf);
  std::vector<std::string> expected = glbs;
  for (const char* f : {"torus_tiled.obj", "torus_tiled.mtl", "torus_tiled.png", "torus_tiled_render.png"})
    expected.push_back(out + "/" + f);
  test::expect_report_schema(j, "demo", {}, expected);
  EXPECT_TRUE(j["seconds"].contains("textured_torus"));
  expect_step_keys_follow_the_schema(j["steps"], out);

  // Issue 17: the chain mail sphere at the CLI's default scale is covered
  // and no two faces cross. The bare share is the output's bare area
  // (session 34: a quarter face per uncovered sample point, fragments left
  // out; it was whole faces with two such points, 2.6% here): seeds 1-4
  // 6.9 / 6.0 / 6.4 / 5.5%, with no refill rounds 7.6 / 6.1 / 6.9 / 5.8%
  // (decision 102). The bound catches a quilt that lost its elements.
  const nlohmann::json& sphere = j["steps"]["quilt"]["sphere"];
  EXPECT_LE(sphere["bare_fraction"].get<double>(), 0.09);
  EXPECT_EQ(sphere["self_intersections"].get<long long>(), 0);
}
