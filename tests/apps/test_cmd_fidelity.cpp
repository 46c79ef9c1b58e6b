// SPDX-License-Identifier: AGPL-3.0-or-later
// Issue 18 at the CLI: `subdiv` chooses its scale and depth from the inputs
// and says so; every image-texture method's report carries the surface
// fidelity (texture/surface_fidelity.h).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/write_mesh.h"
#include "test_support.h"
#include "texture/material_space/material_tile.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {
nlohmann::json report(const std::string& dir) {
  std::ifstream f(dir + "/report.json");
  return nlohmann::json::parse(f);
}
}  // namespace

// Defaults: the scale in exemplar widths across the object, the depth chosen
// for one texel per vertex within --max-vertices, both printed and reported,
// and the fidelity block in the report.
TEST(CmdSubdivFidelity, DefaultsAreChosenPrintedAndReportedWithTheFidelity) {
  const std::string dir = test::temp_dir("subdiv_defaults");
  Mesh m;
  make_icosphere(m, 1, 50.0);  // 100 units across
  write_mesh(dir + "/ball.obj", m);
  const std::string ex = test::shared_data("textures/leather_64.png");
  auto r = test::run_surftex("subdiv '" + dir + "/ball.obj' '" + ex + "' -o '" + dir +
                             "/out' --max-vertices 4000 --atlas-size 128 --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // 4000 vertices would reduce leather_64 to 12 px at 3 widths across, which
  // keeps too little of its detail: fewer repeats, said so (decision 209).
  EXPECT_NE(r.err.find("scale from repeats: 2.1 exemplar widths across"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("instead of the default 3"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("uniform levels (chosen"), std::string::npos) << r.err;
  const auto j = report(dir + "/out");
  EXPECT_EQ(j["scale"]["from"], "repeats");
  EXPECT_NEAR(j["scale"]["repeats_requested"].get<double>(), 3.0, 1e-9);
  EXPECT_LT(j["scale"]["repeats"].get<double>(), 3.0);
  EXPECT_GE(j["scale"]["relative_detail"].get<double>(), 1.0 / 3.0);
  // asked for: kept
  auto given = test::run_surftex("subdiv '" + dir + "/ball.obj' '" + ex + "' -o '" + dir +
                                 "/given' --texel-size 3x --max-vertices 4000 --atlas-size 128 --threads 2");
  ASSERT_EQ(given.exit_code, 0) << given.err;
  EXPECT_NE(given.err.find("scale from repeats: 3 exemplar widths across"), std::string::npos) << given.err;
  EXPECT_EQ(given.err.find("instead of the default"), std::string::npos) << given.err;
  EXPECT_NEAR(report(dir + "/given")["scale"]["repeats"].get<double>(), 3.0, 1e-9);
  EXPECT_TRUE(j["scale"]["levels_chosen"].get<bool>());
  EXPECT_LE(j["scale"]["predicted_vertices"].get<double>(), 4000);
  EXPECT_GT(j["fidelity"]["bds"].get<double>(), 0.0) << j["fidelity"].dump();
  EXPECT_GT(j["fidelity"]["bds_2d"].get<double>(), 0.0);
  EXPECT_GT(j["fidelity"]["ratio"].get<double>(), 0.0);
  EXPECT_GE(j["fidelity"]["long_run_fraction"].get<double>(), 0.0);
  EXPECT_GT(j["export"]["atlas"]["seam"]["pairs_across"].get<double>(), 0.0);
  EXPECT_TRUE(j["wrap"].contains("periodic"));
}

TEST(CmdSubdivFidelity, TexelSizeForms) {
  const std::string dir = test::temp_dir("subdiv_texel");
  Mesh m;
  make_icosphere(m, 1, 0.005);  // 0.01 units across
  write_mesh(dir + "/ball.obj", m);
  const std::string ex = test::shared_data("textures/leather_64.png");
  const std::string base = "subdiv '" + dir + "/ball.obj' '" + ex + "' ";
  auto per_edge = test::run_surftex(base + "-o '" + dir + "/e' --texel-size 1.5/edge --max-vertices 3000 "
                                           "--atlas-size 64 -q");
  ASSERT_EQ(per_edge.exit_code, 0) << per_edge.err;
  const auto j = report(dir + "/e");
  EXPECT_EQ(j["scale"]["from"], "texels_per_edge");
  EXPECT_NEAR(j["scale"]["texels_per_edge"].get<double>(), 1.5, 1e-9);
  for (const char* bad : {"3", "x", "-2x", "0/edge", "2/edges", "nanx"}) {
    auto b = test::run_surftex(base + "-o '" + dir + "/b' --texel-size '" + bad + "' -q");
    EXPECT_EQ(b.exit_code, 2) << bad;
    EXPECT_NE(b.err.find("error: --texel-size"), std::string::npos) << bad << ": " << b.err;
    EXPECT_FALSE(fs::exists(dir + "/b/report.json"));
  }
  auto both = test::run_surftex(base + "-o '" + dir + "/c' --texel-size 2x --rscale 100 -q");
  EXPECT_EQ(both.exit_code, 2) << both.err;
  auto wrap = test::run_surftex(base + "-o '" + dir + "/d' --wrap sometimes -q");
  EXPECT_EQ(wrap.exit_code, 2) << wrap.err;
  // --atlas-size: 0 (from the vertices) or 64..8192, said in one sentence.
  for (const char* bad : {"10", "9000", "-1", "1.5"}) {
    auto b = test::run_surftex(base + "-o '" + dir + "/f' --atlas-size " + bad + " -q");
    EXPECT_EQ(b.exit_code, 2) << bad;
    EXPECT_NE(b.err.find("error: --atlas-size: must be 0 (from the vertices) or 64..8192"), std::string::npos)
        << bad << ": " << b.err;
    EXPECT_FALSE(fs::exists(dir + "/f"));
  }
}

// patches and material-map reports carry the same fidelity block, with the
// seam ratio across their patch / parameterization boundaries.
TEST(CmdPatchesMaterialMapFidelity, ReportsCarryTheFidelity) {
  const std::string dir = test::temp_dir("fidelity_reports");
  Mesh m;
  make_icosphere(m, 2);
  write_mesh(dir + "/sphere.obj", m);
  const std::string ex = test::shared_data("textures/leather_64.png");
  auto p = test::run_surftex("patches '" + dir + "/sphere.obj' '" + ex + "' -o '" + dir +
                             "/p' --patch-res 48 --max-patch-faces 60 --rotations 8 -q");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const auto jp = report(dir + "/p");
  EXPECT_GT(jp["fidelity"]["bds"].get<double>(), 0.0) << jp["fidelity"].dump();
  EXPECT_GT(jp["fidelity"]["ratio"].get<double>(), 0.0);
  EXPECT_GT(jp["fidelity"]["seam"]["pairs_across"].get<double>(), 0.0);
  EXPECT_GT(jp["fidelity"]["seam"]["seam_edges"].get<double>(), 0.0);
  // A one-layer material tile of the same texture, made in process.
  MaterialTileOptions to;
  to.size = 32;
  to.layers = 1;
  const MaterialTileResult tile = make_material_tile({MaterialKey{read_image(ex), Image(), "leather"}}, to);
  MaterialTileInfo info;
  info.sources = {"leather"};
  info.masks = {""};
  info.layers_per_pair = 1;
  write_material_tile(dir + "/tile", tile, info, true);
  auto mm = test::run_surftex("material-map '" + dir + "/sphere.obj' --tile '" + dir + "/tile' -o '" + dir +
                              "/m' --render-size 64 -q");
  ASSERT_EQ(mm.exit_code, 0) << mm.err;
  const auto jm = report(dir + "/m");
  EXPECT_GT(jm["fidelity"]["bds"].get<double>(), 0.0) << jm["fidelity"].dump();
  EXPECT_GT(jm["fidelity"]["texel_size"].get<double>(), 0.0);
  EXPECT_TRUE(jm["fidelity"].contains("seam"));
}
