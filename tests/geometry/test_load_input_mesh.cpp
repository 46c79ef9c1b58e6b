// SPDX-License-Identifier: AGPL-3.0-or-later
// load_input_mesh: a method's input is repaired before use, refused when it
// cannot be, and valid polygons survive when asked for.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "geometry/errors.h"
#include "geometry/load_input_mesh.h"
#include "geometry/mesh.h"
#include "test_support.h"

using namespace surftex;

namespace {

std::size_t zero_area_faces(const Mesh& m) {
  std::size_t n = 0;
  for (FaceIndex f : m.faces()) {
    auto h = m.halfedge(f);
    if (CGAL::collinear(m.point(m.source(h)), m.point(m.target(h)),
                        m.point(m.target(m.next(h)))))
      ++n;
  }
  return n;
}

std::string write_text(const std::string& name, const std::string& text) {
  const std::string p = test::temp_dir("load_input") + "/" + name;
  std::ofstream(p) << text;
  return p;
}

// A 3x1 strip of quads in the plane z = 0.
const char* kQuadStrip =
    "OFF\n8 3 0\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n0 1 0\n1 1 0\n2 1 0\n3 1 0\n"
    "4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n";

}  // namespace

TEST(LoadInputMesh, MeshWithOnlyZeroAreaFacesIsRefusedNamingTheFile) {
  Mesh m;
  const std::string path = test::shared_data("broken/all_degen.off");
  try {
    load_input_mesh(path, m);
    FAIL() << "all_degen.off was accepted";
  } catch (const TopologyError& e) {
    EXPECT_NE(std::string(e.what()).find("all_degen.off"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cannot use mesh"), std::string::npos) << e.what();
  }
}

TEST(LoadInputMesh, ZeroAreaTrianglesAreRemovedAndSaid) {
  for (const char* name : {"broken/deg_on_border.off", "broken/degtri_sliding.off"}) {
    Mesh m;
    const LoadInputReport r = load_input_mesh(test::shared_data(name), m);
    EXPECT_TRUE(r.repair_ran) << name;
    EXPECT_GT(r.repair_changes, 0u) << name;
    EXPECT_NE(r.summary.find("zero-area faces removed"), std::string::npos) << name << ": " << r.summary;
    EXPECT_GT(m.number_of_faces(), 0u) << name;
    EXPECT_EQ(zero_area_faces(m), 0u) << name;
    EXPECT_TRUE(m.is_valid(false)) << name;
  }
}

TEST(LoadInputMesh, CleanMeshNeedsNoRepairAndSaysNothing) {
  Mesh m;
  const LoadInputReport r = load_input_mesh(write_text("strip.off", kQuadStrip), m);
  EXPECT_EQ(r.repair_changes, 0u);
  EXPECT_TRUE(r.summary.empty()) << r.summary;
  EXPECT_EQ(m.number_of_faces(), 6u);  // triangulated without keep_polygons
  for (FaceIndex f : m.faces()) EXPECT_EQ(m.degree(f), 3u);
}

TEST(LoadInputMesh, ValidPolygonsAreKeptWhenAskedFor) {
  Mesh m;
  LoadInputOptions o;
  o.keep_polygons = true;
  const LoadInputReport r = load_input_mesh(write_text("strip.off", kQuadStrip), m, o);
  EXPECT_FALSE(r.repair_ran);
  EXPECT_EQ(m.number_of_faces(), 3u);
  for (FaceIndex f : m.faces()) EXPECT_EQ(m.degree(f), 4u);
}

TEST(LoadInputMesh, PolygonMeshWithADegenerateFaceIsTriangulatedAndRepaired) {
  // The strip plus a quad whose four corners lie on one line (zero area),
  // glued to the strip's right border.
  const std::string text =
      "OFF\n10 4 0\n0 0 0\n1 0 0\n2 0 0\n3 0 0\n0 1 0\n1 1 0\n2 1 0\n3 1 0\n3 2 0\n3 3 0\n"
      "4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 8 9 7\n";
  Mesh m;
  LoadInputOptions o;
  o.keep_polygons = true;
  const LoadInputReport r = load_input_mesh(write_text("strip_degenerate.off", text), m, o);
  EXPECT_TRUE(r.repair_ran);
  EXPECT_GT(r.repair_changes, 0u);
  EXPECT_EQ(zero_area_faces(m), 0u);
  EXPECT_EQ(m.number_of_faces(), 6u);
  for (FaceIndex f : m.faces()) EXPECT_EQ(m.degree(f), 3u);
}
