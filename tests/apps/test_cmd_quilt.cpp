// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex quilt`: planar and surface mesh quilting from the command line
// (outputs, report figures, refusals that write nothing).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {
using surftex::test::read_json;
// The merge statistics both branches write through one function: the same
// keys, and the refusal reasons add up to the refusals.
void expect_stitch_stats(const nlohmann::json& j) {
  for (const char* k : {"stitched", "stitch_refused", "coincident", "stitched_trimmed", "related",
                        "stitch_refused_loops", "stitch_refused_border", "stitch_refused_geometry",
                        "stitch_refused_infeasible", "inputs_added", "inputs_dropped", "inputs_kept_cut"})
    EXPECT_TRUE(j.contains(k) && j[k].is_number_unsigned()) << k;
  ASSERT_TRUE(j.contains("stitch_refused_reasons") && j["stitch_refused_reasons"].is_object());
  std::size_t sum = 0;
  for (const auto& [why, n] : j["stitch_refused_reasons"].items()) sum += n.get<std::size_t>();
  EXPECT_EQ(sum, j["stitch_refused"].get<std::size_t>());
}
}  // namespace

TEST(CmdQuilt, PlaneWithGeneratedSwatchWritesMeshRenderAndReport) {
  const std::string dir = test::temp_dir("quilt-plane");
  const std::string args = "quilt --plane 1.6x1.6 scatter -o '" + dir + "/p.ply' --seed 3 --report '" + dir +
                           "/r.json' --quiet";
  test::RunResult r = test::run_surftex(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir + "/p.ply"));
  ASSERT_TRUE(fs::exists(dir + "/p_render.png"));
  const nlohmann::json j = read_json(dir + "/r.json");
  EXPECT_GT(j["elements"].get<int>(), 5);
  expect_stitch_stats(j);
  EXPECT_GT(j["element_length_mean"].get<double>(), 0.0);
  EXPECT_GE(j["element_length_max"].get<double>(), j["element_length_mean"].get<double>());
  Mesh m;
  read_mesh(dir + "/p.ply", m);
  EXPECT_EQ(m.number_of_faces(), j["faces"].get<std::size_t>());
  // Same seed, same bytes.
  test::RunResult again = test::run_surftex("quilt --plane 1.6x1.6 scatter -o '" + dir + "/p2.ply' --seed 3 --quiet --no-render");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  std::ifstream a(dir + "/p.ply", std::ios::binary), b(dir + "/p2.ply", std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(a)), {}), sb((std::istreambuf_iterator<char>(b)), {});
  EXPECT_EQ(sa, sb);
  // Existing output: refused without --force.
  EXPECT_EQ(test::run_surftex(args).exit_code, 2);
}

TEST(CmdQuilt, SphereWritesSiblingsAndReportsStretchAndSelfIntersections) {
  const std::string dir = test::temp_dir("quilt-sphere");
  Mesh base;
  make_icosphere(base, 1);
  write_mesh(dir + "/sphere.off", base);
  const std::string args = "quilt '" + dir + "/sphere.off' scatter -o '" + dir + "/q.obj' --scale 0.5 --field none " +
                           "--shell-height 1 --stretch-iterations 5 --report '" + dir + "/r.json' --quiet";
  test::RunResult r = test::run_surftex(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"/q.obj", "/q.ply", "/q.glb", "/q_render.png"}) EXPECT_TRUE(fs::exists(dir + f)) << f;
  const nlohmann::json j = read_json(dir + "/r.json");
  EXPECT_GT(j["elements"].get<int>(), 5);
  EXPECT_GT(j["faces"].get<std::size_t>(), 100u);
  EXPECT_GE(j["stretch_before"].get<double>(), 1.0 - 1e-9);
  EXPECT_LE(j["stretch_after"].get<double>(), j["stretch_before"].get<double>());
  EXPECT_TRUE(j["self_intersections"].is_number_unsigned());
  // Every vertex with w in [0, 1] is mapped through a tet and lies in the shell.
  EXPECT_EQ(j["outside_uv"].get<std::size_t>(), 0u);
  EXPECT_EQ(j["outside_shell"].get<std::size_t>(), 0u);
  EXPECT_TRUE(j["locations_clamped"].is_number_unsigned());
  expect_stitch_stats(j);
  EXPECT_GE(j["seconds"]["quilt"].get<double>(), 0.0);
  EXPECT_GE(j["seconds"]["embed"].get<double>(), 0.0);
  Mesh m;
  read_mesh(dir + "/q.ply", m);
  EXPECT_EQ(m.number_of_faces(), j["faces"].get<std::size_t>());
}

// --thread-pieces reaches the scatter fill: a weave on a flat lens, whose
// rim cuts the threads, gets thread pieces in what stays bare by default and
// none with 0.
TEST(CmdQuilt, ThreadPiecesFillBareSpotsOfAWeaveAndZeroTurnsThemOff) {
  const std::string dir = test::temp_dir("quilt-thread-pieces");
  Mesh base;
  make_icosphere(base, 3);
  for (VertexIndex v : base.vertices()) {
    const Point3 p = base.point(v);
    base.point(v) = Point3(p.x(), p.y(), 0.08 * p.z());
  }
  write_mesh(dir + "/lens.off", base);
  auto run = [&](const std::string& extra, const std::string& tag) {
    const test::RunResult r = test::run_surftex("quilt '" + dir + "/lens.off' weave -o '" + dir + "/" + tag +
                                                ".obj' --scale 0.6 --no-render --stretch-iterations 0 --no-check "
                                                "--quiet --report '" + dir + "/" + tag + ".json'" + extra);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return read_json(dir + "/" + tag + ".json");
  };
  const nlohmann::json off = run(" --thread-pieces 0", "off");
  const nlohmann::json on = run("", "on");
  EXPECT_EQ(off["scatter_placed"].get<std::size_t>(), 0u);
  EXPECT_GT(on["scatter_placed"].get<std::size_t>(), 0u);
  EXPECT_LT(on["bare_fraction"].get<double>(), off["bare_fraction"].get<double>());
}

// Rings wider than a horn, smaller copies off: its tips stay bare, and the
// summary says why and what to do (a smaller --scale); with the default
// --fill-smaller smaller rings go there; at the default scale the horn is
// covered and nothing is said. A bad --fill-smaller writes nothing.
TEST(CmdQuilt, ThinPartsLeftBareAreNamedWithTheScaleToLower) {
  const std::string dir = test::temp_dir("quilt-thin-parts");
  Mesh horn, ring;
  make_ellipsoid(horn, 0.25, 0.25, 1.5, 2);
  make_torus(ring, 0.35, 0.12, 16, 6);
  write_mesh(dir + "/horn.off", horn);
  write_mesh(dir + "/ring.off", ring);
  auto run = [&](const std::string& scale, const std::string& tag) {
    const test::RunResult r = test::run_surftex("quilt '" + dir + "/horn.off' '" + dir + "/ring.off' -o '" + dir + "/" +
                                                tag + ".obj' --up 0 0 1 --scale " + scale +
                                                " --stretch-iterations 2 --no-check --no-render --report '" + dir +
                                                "/" + tag + ".json'");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return std::make_pair(r.err, read_json(dir + "/" + tag + ".json"));
  };
  auto worst_band = [](const nlohmann::json& j) {
    double worst = 0;
    for (const auto& b : j["bare_by_height"]) worst = std::max(worst, b.get<double>());
    return worst;
  };
  const auto [wide_err, wide] = run("0.3 --fill-smaller none", "wide");
  EXPECT_GT(worst_band(wide), 0.04);
  EXPECT_EQ(wide["fill_placed_smaller"].get<std::size_t>(), 0u);
  for (const char* w : {"parts thinner than", "quarter of the mesh's height", "--scale 0.3", "smaller --scale"})
    EXPECT_NE(wide_err.find(w), std::string::npos) << w << " in " << wide_err;
  const auto [smaller_err, smaller] = run("0.3", "smaller");
  EXPECT_GT(smaller["fill_placed_smaller"].get<std::size_t>(), 0u);
  EXPECT_LT(worst_band(smaller), worst_band(wide));
  for (const char* bad : {"1.2", "0.5,x", "0", "0.5,,0.3"}) {
    const test::RunResult r = test::run_surftex("quilt '" + dir + "/horn.off' '" + dir + "/ring.off' -o '" + dir +
                                                "/bad.obj' --fill-smaller " + bad + " --quiet");
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.err.find("error: quilt: --fill-smaller"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir + "/bad.obj")) << bad;
  }
  const auto [fine_err, fine] = run("0", "fine");
  for (const auto& b : fine["bare_by_height"]) EXPECT_LE(b.get<double>(), 0.04);
  EXPECT_EQ(fine_err.find("parts thinner than"), std::string::npos) << fine_err;
}

TEST(CmdQuilt, BadInputExitsTwoAndWritesNothing) {
  const std::string dir = test::temp_dir("quilt-bad");
  // Unknown swatch file.
  test::RunResult r = test::run_surftex("quilt --plane 2x2 '" + dir + "/nope.obj' -o '" + dir + "/o.ply' --quiet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  // Bad plane size.
  r = test::run_surftex("quilt --plane 2by2 chainmail -o '" + dir + "/o.ply' --quiet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--plane"), std::string::npos) << r.err;
  // A base mesh that is not a mesh file.
  {
    std::ofstream bad(dir + "/bad.off");
    bad << "OFF\n3 1 0\n0 0 0\n1 0 0\n";
  }
  r = test::run_surftex("quilt '" + dir + "/bad.off' chainmail -o '" + dir + "/o.ply' --quiet");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  // Bad field.
  r = test::run_surftex("quilt '" + dir + "/bad.off' chainmail -o '" + dir + "/o.ply' --field sideways --quiet");
  EXPECT_NE(r.exit_code, 0);
  for (const char* f : {"/o.ply", "/o.glb", "/o_render.png"}) EXPECT_FALSE(fs::exists(dir + f)) << f;
}

// Issue 17 item 3 / issue 16 item 6: the swatch's thin axis is detected (a
// ring modelled thin along y, like shared/data/swatches/torus_ring.obj) and
// reported, up defaults to +Y, and a swatch too small for the grid is refused
// naming its axes, --cell and --swatch-up.
TEST(CmdQuilt, SwatchThinAxisIsDetectedUpIsYAndTheCellErrorNamesAxes) {
  const std::string dir = test::temp_dir("quilt-axis");
  Mesh ring;
  make_torus(ring, 1.0, 0.25, 16, 6);  // in xy, thin along z
  for (VertexIndex v : ring.vertices()) {
    const Point3 p = ring.point(v);
    ring.point(v) = Point3(p.y(), p.z(), p.x());  // thin along y
  }
  write_mesh(dir + "/ring_y.obj", ring);
  Mesh base;
  make_icosphere(base, 1);
  write_mesh(dir + "/sphere.off", base);
  test::RunResult r = test::run_surftex("quilt '" + dir + "/sphere.off' '" + dir + "/ring_y.obj' -o '" + dir +
                                        "/q.ply' --scale 0.4 --stretch-iterations 2 --no-check --no-render --report '" + dir +
                                        "/r.json' --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = read_json(dir + "/r.json");
  EXPECT_EQ(j["swatch_up"].get<std::string>(), "y");
  EXPECT_EQ(j["up"], nlohmann::json::parse("[0.0, 1.0, 0.0]"));
  for (const char* k : {"edge_stretch_max", "crossings_resolved", "crossing_hits", "bare_fraction", "faces_refilled"})
    EXPECT_TRUE(j.contains(k)) << k;
  // Taken as z-thin, the ring's xy extent is 2.5 x 0.5: 10 x 2 cells, refused with the axes named.
  r = test::run_surftex("quilt '" + dir + "/sphere.off' '" + dir + "/ring_y.obj' -o '" + dir +
                        "/z.ply' --swatch-up z --no-render --quiet");
  EXPECT_EQ(r.exit_code, 2);
  for (const char* w : {"along its x and y axes", "thin axis z", "--cell", "--swatch-up"})
    EXPECT_NE(r.err.find(w), std::string::npos) << w << " in " << r.err;
  EXPECT_FALSE(fs::exists(dir + "/z.ply"));
  // The generated tori swatch.
  r = test::run_surftex("swatch tori -o '" + dir + "/t.obj' --size 2 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  Mesh t;
  read_mesh(dir + "/t.obj", t);
  EXPECT_GT(t.number_of_faces(), 4u * 100u);
}
