// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

using surftex::test::write_file;

// Binary helpers for PLY/STL written in code.
template <class T>
void put(std::string& s, T v, bool big_endian = false) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if (big_endian) std::reverse(b, b + sizeof(T));
  s.append(reinterpret_cast<const char*>(b), sizeof(T));
}

// A tetrahedron: 4 points, 4 outward triangles.
const double kTet[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const int kTetF[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
const unsigned char kTetRGB[4][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {10, 20, 30}};

std::string tet_off() {
  std::ostringstream s;
  s << "OFF\n# a tetrahedron\n4 4 6\n";
  for (auto& p : kTet) s << p[0] << " " << p[1] << " " << p[2] << "\n";
  for (auto& f : kTetF) s << "3 " << f[0] << " " << f[1] << " " << f[2] << "\n";
  return s.str();
}

/// A tetrahedron PLY with uchar colours, an unknown vertex property (a list
/// and a scalar), an unknown element before the faces, and int16 list counts.
std::string tet_ply(const std::string& format) {
  const bool ascii = format == "ascii";
  const bool big = format == "binary_big_endian";
  std::string s = "ply\nformat " + format + " 1.0\ncomment made in a test\n";
  s += "element vertex 4\nproperty double x\nproperty float y\nproperty float z\n";
  s += "property list uchar int junk\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n";
  s += "property float quality\n";
  s += "element material 2\nproperty list uint short values\nproperty int id\n";
  s += "element face 4\nproperty uchar flags\nproperty list short uint vertex_indices\n";
  s += "end_header\n";
  std::ostringstream a;
  for (int i = 0; i < 4; ++i) {
    if (ascii) {
      a << kTet[i][0] << " " << kTet[i][1] << " " << kTet[i][2] << " 2 7 8 " << int(kTetRGB[i][0]) << " "
        << int(kTetRGB[i][1]) << " " << int(kTetRGB[i][2]) << " 0.5\n";
    } else {
      put<double>(s, kTet[i][0], big);
      put<float>(s, static_cast<float>(kTet[i][1]), big);
      put<float>(s, static_cast<float>(kTet[i][2]), big);
      put<std::uint8_t>(s, 2);
      put<std::int32_t>(s, 7, big);
      put<std::int32_t>(s, 8, big);
      for (int k = 0; k < 3; ++k) put<std::uint8_t>(s, kTetRGB[i][k]);
      put<float>(s, 0.5f, big);
    }
  }
  for (int m = 0; m < 2; ++m) {
    if (ascii) {
      a << "3 1 2 3 " << m << "\n";
    } else {
      put<std::uint32_t>(s, 3, big);
      for (int k = 0; k < 3; ++k) put<std::int16_t>(s, static_cast<std::int16_t>(k), big);
      put<std::int32_t>(s, m, big);
    }
  }
  for (auto& f : kTetF) {
    if (ascii) {
      a << "0 3 " << f[0] << " " << f[1] << " " << f[2] << "\n";
    } else {
      put<std::uint8_t>(s, 0);
      put<std::int16_t>(s, 3, big);
      for (int k = 0; k < 3; ++k) put<std::uint32_t>(s, static_cast<std::uint32_t>(f[k]), big);
    }
  }
  return ascii ? s + a.str() : s;
}

std::string tet_stl_binary(const char* header80 = "solid binary file that starts with solid") {
  std::string s(80, '\0');
  std::memcpy(s.data(), header80, std::min<std::size_t>(80, std::strlen(header80)));
  put<std::uint32_t>(s, 4);
  for (auto& f : kTetF) {
    for (int k = 0; k < 3; ++k) put<float>(s, 0.f);
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) put<float>(s, static_cast<float>(kTet[f[c]][k]));
    put<std::uint16_t>(s, 0);
  }
  return s;
}

std::string tet_stl_ascii() {
  std::ostringstream s;
  s << "solid tet\n";
  for (auto& f : kTetF) {
    s << "  facet normal 0 0 0\n    outer loop\n";
    for (int c = 0; c < 3; ++c)
      s << "      vertex " << kTet[f[c]][0] << " " << kTet[f[c]][1] << " " << kTet[f[c]][2] << "\n";
    s << "    endloop\n  endfacet\n";
  }
  s << "endsolid tet\n";
  return s.str();
}

std::string tet_obj() {
  std::ostringstream s;
  s << "# tet\nmtllib none.mtl\no tet\n";
  for (auto& p : kTet) s << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
  s << "usemtl x\n";
  for (auto& f : kTetF) s << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
  return s.str();
}

void expect_tet(const PolygonSoup& s, bool welded_order = true) {
  ASSERT_EQ(s.points.size(), 4u);
  ASSERT_EQ(s.polygons.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.points[i][k], kTet[i][k]) << "point " << i;
    ASSERT_EQ(s.polygons[i].size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.polygons[i][k], static_cast<std::size_t>(kTetF[i][k]));
  }
}

template <class E, class F>
std::string expect_throw(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type: " << e.what();
    return "";
  }
  ADD_FAILURE() << "no exception";
  return "";
}

using surftex::test::sanitized;

}  // namespace

// ------------------------------------------------------------------ formats

TEST(ReadMesh, OffTetrahedronExact) {
  auto d = test::temp_dir("rm");
  expect_tet(read_polygon_soup(write_file(d, "t.off", tet_off())));
}

TEST(ReadMesh, OffHeaderOnCountLineAndCommentsAnywhere) {
  auto d = test::temp_dir("rm");
  auto s = read_polygon_soup(write_file(
      d, "t.off", "OFF 3 1 0 # counts on the keyword line\n\n0 0 0 # v0\n1 0 0\n# comment\n0 1 0\n3 0 1 2 255 0 0\n"));
  EXPECT_EQ(s.points.size(), 3u);
  ASSERT_EQ(s.polygons.size(), 1u);
  EXPECT_EQ(s.points[1][0], 1.0);
}

TEST(ReadMesh, CoffIntegerAndFloatColours) {
  auto d = test::temp_dir("rm");
  auto s = read_polygon_soup(
      write_file(d, "c.off", "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 51 0 255\n0 1 0 0 0 102 255\n3 0 1 2\n"));
  ASSERT_EQ(s.colors.size(), 3u);
  EXPECT_FLOAT_EQ(s.colors[0][0], 1.f);
  EXPECT_FLOAT_EQ(s.colors[1][1], 0.2f);
  EXPECT_FLOAT_EQ(s.colors[2][2], 0.4f);
  auto f = read_polygon_soup(
      write_file(d, "f.off", "COFF\n3 1 0\n0 0 0 0.5 0 0 1\n1 0 0 0 0.25 0 1\n0 1 0 0 0 1.0 1\n3 0 1 2\n"));
  EXPECT_FLOAT_EQ(f.colors[0][0], 0.5f);
  EXPECT_FLOAT_EQ(f.colors[1][1], 0.25f);
  EXPECT_FLOAT_EQ(f.colors[2][2], 1.f);
}

TEST(ReadMesh, NoffSkipsNormalsAndCnoffReadsColourAfterThem) {
  auto d = test::temp_dir("rm");
  auto s = read_polygon_soup(write_file(d, "n.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n2 0 0 0 0 1\n0 3 0 0 0 1\n3 0 1 2\n"));
  EXPECT_EQ(s.points[1][0], 2.0);
  EXPECT_EQ(s.points[2][1], 3.0);
  EXPECT_TRUE(s.colors.empty());
  auto c = read_polygon_soup(
      write_file(d, "cn.off", "CNOFF\n3 1 0\n0 0 0 0 0 1 255 0 0\n2 0 0 0 0 1 0 255 0\n0 3 0 0 0 1 0 0 255\n3 0 1 2\n"));
  ASSERT_EQ(c.colors.size(), 3u);
  EXPECT_FLOAT_EQ(c.colors[1][1], 1.f);
  EXPECT_FLOAT_EQ(c.colors[1][0], 0.f);
}

TEST(ReadMesh, ObjTetrahedronExact) {
  auto d = test::temp_dir("rm");
  expect_tet(read_polygon_soup(write_file(d, "t.obj", tet_obj())));
}

TEST(ReadMesh, ObjQuadsNegativeIndicesAndCornerForms) {
  auto d = test::temp_dir("rm");
  // A unit cube: 8 v, 4 vt, 6 quads written with relative (negative) indices
  // in every corner form.
  std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng cube\ns off\n"
      "f -8/-4 -5/-1 -6/-2 -7/-3\n"                // bottom 0 3 2 1
      "f -4/-4/-1 -3/-3/-1 -2/-2/-1 -1/-1/-1\n"    // top 4 5 6 7
      "f 1//1 2//1 6//1 5//1\n"                    // no UVs on this face
      "f 2/1 3/2 7/3 6/4\n"
      "f 3/1 4/2 8/3 7/4\n"
      "f 4/1 1/2 5/3 8/4\n";
  auto s = read_polygon_soup(write_file(d, "cube.obj", obj));
  ASSERT_EQ(s.points.size(), 8u);
  ASSERT_EQ(s.polygons.size(), 6u);
  EXPECT_EQ(s.polygons[0], (std::vector<std::size_t>{0, 3, 2, 1}));
  EXPECT_EQ(s.polygons[1], (std::vector<std::size_t>{4, 5, 6, 7}));
  ASSERT_EQ(s.polygon_uvs.size(), 6u);
  EXPECT_EQ(s.polygon_uvs[0], (std::vector<std::size_t>{0, 3, 2, 1}));
  EXPECT_TRUE(s.polygon_uvs[2].empty());
  EXPECT_EQ(s.uvs.size(), 4u);

  Mesh m;
  SoupRepairCounts c;
  soup_to_mesh(s, m, {}, &c);
  EXPECT_EQ(m.number_of_faces(), 12u);
  EXPECT_EQ(c.faces_triangulated, 6u);
  EXPECT_EQ(c.uv_corners, 20u);
  EXPECT_EQ(c.uv_corners_dropped, 4u);
  auto uv = find(m, kCornerUV);
  ASSERT_TRUE(uv.second);
  // Every corner at vertex (1,1,1) of the face x = 1 (4th polygon) has uv (1,1).
  int checked = 0;
  for (FaceIndex f : m.faces()) {
    bool on_x1 = true;
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) on_x1 &= m.point(m.target(h)).x() == 1.0;
    if (!on_x1) continue;
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
      const Point3& p = m.point(m.target(h));
      if (p.y() == 1.0 && p.z() == 1.0) {
        EXPECT_EQ(uv.first[h][0], 1.0);
        EXPECT_EQ(uv.first[h][1], 1.0);
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 1);
}

TEST(ReadMesh, FacesWithFewerThanThreeVerticesAreDroppedAndCountedInEveryFormat) {
  auto d = test::temp_dir("rm");
  // A triangle plus a 2-vertex face: the short face is left out and counted,
  // with its location, in OBJ, OFF and PLY alike.
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1// 2//\nf 1 2 3\n";
  const std::string off = "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n";
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n3 0 1 2\n";
  for (const auto& [name, text] : {std::pair<std::string, std::string>{"s.obj", obj}, {"s.off", off}, {"s.ply", ply}}) {
    PolygonSoup soup = read_polygon_soup(write_file(d, name, text));
    EXPECT_EQ(soup.polygons.size(), 1u) << name;
    EXPECT_EQ(soup.short_polygons_dropped, 1u) << name;
    EXPECT_FALSE(soup.first_short_polygon.empty()) << name;
    Mesh m;
    SoupRepairCounts c;
    soup_to_mesh(soup, m, {}, &c);
    EXPECT_EQ(c.short_polygons_dropped, 1u) << name;
    EXPECT_EQ(m.number_of_faces(), 1u) << name;
  }
  EXPECT_NE(read_polygon_soup(write_file(d, "line.obj", obj)).first_short_polygon.find("line 4"), std::string::npos);
  // Out-of-range indices in a short face are still refused.
  expect_throw<InvalidInputError>(
      [&] { read_polygon_soup(write_file(d, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 9\nf 1 2 3\n")); });
  // Only short faces: no face left, and the error says why.
  Mesh m;
  auto msg = expect_throw<InvalidInputError>(
      [&] { read_mesh(write_file(d, "only.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"), m); });
  EXPECT_NE(msg.find("shorter"), std::string::npos) << msg;
}

TEST(SoupToMesh, UntriangulablePolygonIsFanTriangulatedNotRefused) {
  // triangulate_faces refuses a polygon whose normal is null (all corners
  // collinear); a valid square next to it must still come through.
  PolygonSoup s;
  s.source = "collinear.off";
  s.points = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}, {0, 5, 0}, {1, 5, 0}, {1, 6, 0}, {0, 6, 0}};
  s.polygons = {{0, 1, 2, 3, 4}, {5, 6, 7, 8}};
  Mesh m;
  SoupRepairCounts c;
  soup_to_mesh(s, m, {}, &c);
  EXPECT_EQ(c.faces_fan_triangulated, 1u);
  EXPECT_EQ(m.number_of_faces(), 3u + 2u);
  for (FaceIndex f : m.faces()) EXPECT_EQ(m.degree(f), 3u);
  EXPECT_TRUE(m.is_valid(false));
}

TEST(ReadMesh, ObjVertexColours) {
  auto d = test::temp_dir("rm");
  auto s = read_polygon_soup(write_file(d, "c.obj", "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 0.5\nf 1 2 3\n"));
  ASSERT_EQ(s.colors.size(), 3u);
  EXPECT_FLOAT_EQ(s.colors[2][2], 0.5f);
}

TEST(ReadMesh, PlyAsciiAndBothBinaryEndians) {
  auto d = test::temp_dir("rm");
  for (std::string fmt : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(fmt);
    auto s = read_polygon_soup(write_file(d, fmt + ".ply", tet_ply(fmt)));
    expect_tet(s);
    ASSERT_EQ(s.colors.size(), 4u);
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k) EXPECT_FLOAT_EQ(s.colors[i][k], kTetRGB[i][k] / 255.f);
  }
}

TEST(ReadMesh, PlyFloatColoursAndVertexIndexName) {
  auto d = test::temp_dir("rm");
  std::string s =
      "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty float x\r\nproperty float y\r\n"
      "property float z\r\nproperty float red\r\nproperty float green\r\nproperty float blue\r\n"
      "element face 1\r\nproperty list int int vertex_index\r\nend_header\r\n"
      "0 0 0 0.25 0 0\r\n1 0 0 0 1 0\r\n0 1 0 0 0 1\r\n3 2 1 0\r\n";
  auto soup = read_polygon_soup(write_file(d, "f.ply", s));
  ASSERT_EQ(soup.polygons.size(), 1u);
  EXPECT_EQ(soup.polygons[0], (std::vector<std::size_t>{2, 1, 0}));
  EXPECT_FLOAT_EQ(soup.colors[0][0], 0.25f);
}

TEST(ReadMesh, StlBinaryStartingWithSolidAndAsciiAreWelded) {
  auto d = test::temp_dir("rm");
  for (auto [name, bytes] : {std::pair<std::string, std::string>{"b.stl", tet_stl_binary()},
                             {"a.stl", tet_stl_ascii()}}) {
    SCOPED_TRACE(name);
    auto s = read_polygon_soup(write_file(d, name, bytes));
    ASSERT_EQ(s.points.size(), 4u);  // 12 corners welded to 4 points
    ASSERT_EQ(s.polygons.size(), 4u);
    // Welding keeps first-seen order: face 0 = (0,2,1) gives points 0, 2, 1.
    EXPECT_EQ(s.points[1][1], 1.0);
    EXPECT_EQ(s.points[2][0], 1.0);
    Mesh m;
    read_mesh(d + "/" + name, m);
    EXPECT_EQ(m.number_of_vertices(), 4u);
    EXPECT_EQ(m.number_of_faces(), 4u);
    EXPECT_TRUE(CGAL::is_closed(m));
  }
}

TEST(ReadMesh, UnknownExtensionIsSniffed) {
  auto d = test::temp_dir("rm");
  EXPECT_EQ(read_polygon_soup(write_file(d, "a.mesh", tet_off())).polygons.size(), 4u);
  EXPECT_EQ(read_polygon_soup(write_file(d, "b.dat", tet_ply("binary_little_endian"))).polygons.size(), 4u);
  EXPECT_EQ(read_polygon_soup(write_file(d, "c", tet_obj())).polygons.size(), 4u);
  EXPECT_EQ(read_polygon_soup(write_file(d, "d.bin", tet_stl_binary("no solid here"))).polygons.size(), 4u);
  EXPECT_EQ(read_polygon_soup(write_file(d, "e.txt", tet_stl_ascii())).polygons.size(), 4u);
  expect_throw<IOError>([&] { read_polygon_soup(write_file(d, "f.xyz", "hello world\n")); });
}

// ------------------------------------------------------------------ soup -> mesh

TEST(SoupToMesh, RepairCountsAreMeasured) {
  // Tetrahedron + a duplicate of point 1 used by one face, a face repeating a
  // vertex, a duplicate face (reversed), and an isolated point.
  PolygonSoup s;
  s.source = "test-soup";
  for (auto& p : kTet) s.points.push_back({p[0], p[1], p[2]});
  s.points.push_back({1, 0, 0});   // 4: duplicate of 1
  s.points.push_back({5, 5, 5});   // 5: isolated
  s.polygons = {{0, 2, 1}, {0, 4, 3}, {0, 3, 2}, {1, 2, 3}, {0, 0, 3}, {1, 2, 0}};
  Mesh m;
  SoupRepairCounts c;
  soup_to_mesh(s, m, {}, &c);
  EXPECT_EQ(c.input_points, 6u);
  EXPECT_EQ(c.input_polygons, 6u);
  EXPECT_EQ(c.duplicate_points_merged, 1u);
  EXPECT_EQ(c.degenerate_polygons_removed, 1u);
  EXPECT_EQ(c.duplicate_polygons_removed, 1u);
  EXPECT_EQ(c.isolated_points_removed, 1u);
  EXPECT_EQ(c.points_duplicated_to_orient, 0u);
  EXPECT_TRUE(c.oriented);
  EXPECT_EQ(m.number_of_vertices(), 4u);
  EXPECT_EQ(m.number_of_faces(), 4u);
  EXPECT_TRUE(CGAL::is_closed(m));
}

TEST(SoupToMesh, ColoursFollowTheRenumbering) {
  PolygonSoup s;
  s.points = {{9, 9, 9}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}};  // point 0 isolated
  s.colors = {{0.1f, 0.1f, 0.1f}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  s.polygons = {{1, 2, 3}};
  Mesh m;
  soup_to_mesh(s, m);
  ASSERT_EQ(m.number_of_vertices(), 3u);
  auto col = find(m, kVertexColor);
  ASSERT_TRUE(col.second);
  for (VertexIndex v : m.vertices()) {
    const Point3& p = m.point(v);
    Color3f expect = p.x() == 1 ? Color3f{0, 1, 0} : p.y() == 1 ? Color3f{0, 0, 1} : Color3f{1, 0, 0};
    EXPECT_EQ(col.first[v], expect);
  }
}

TEST(SoupToMesh, NothingLeftIsTopologyErrorNamingTheSource) {
  PolygonSoup s;
  s.source = "all-degenerate.off";
  s.points = {{0, 0, 0}, {1, 0, 0}};
  s.polygons = {{0, 1, 1}, {0, 0, 1}};
  Mesh m;
  auto msg = expect_throw<TopologyError>([&] { soup_to_mesh(s, m); });
  EXPECT_NE(msg.find("all-degenerate.off"), std::string::npos) << msg;
}

TEST(SoupToMesh, FacesWithRepeatedVerticesFromAFileAreRemovedAndCounted) {
  auto d = test::temp_dir("rm");
  std::string off = tet_off();
  off.replace(off.find("4 4 6"), 5, "4 6 0");
  off += "3 1 1 2\n4 0 1 1 0\n";
  Mesh m;
  SoupRepairCounts c;
  read_mesh(write_file(d, "rep.off", off), m, {}, &c);
  EXPECT_EQ(c.input_polygons, 6u);
  EXPECT_EQ(c.degenerate_polygons_removed, 2u);
  EXPECT_EQ(m.number_of_faces(), 4u);
}

// ------------------------------------------------------------------ real data

TEST(ReadMeshRealData, EveryMeshLoads) {
  fs::path dir = test::shared_data("meshes");
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    if (sanitized() && e.file_size() > 600000) continue;
    SCOPED_TRACE(e.path().string());
    Mesh m;
    SoupRepairCounts c;
    ASSERT_NO_THROW(read_mesh(e.path().string(), m, {}, &c));
    EXPECT_GT(m.number_of_faces(), 0u);
    EXPECT_TRUE(m.is_valid(false));
    ++n;
  }
  EXPECT_GE(n, 10);
}

TEST(ReadMeshRealData, KnownCounts) {
  Mesh m;
  SoupRepairCounts c;
  read_mesh(test::shared_data("meshes/spot.ply"), m, {}, &c);  // binary little-endian
  EXPECT_EQ(c.input_points, 2930u);
  EXPECT_EQ(c.input_polygons, 5856u);
  EXPECT_EQ(m.number_of_faces(), 5856u);
  read_mesh(test::shared_data("meshes/double_torus_polygons.off"), m, {}, &c);
  EXPECT_EQ(c.input_polygons, 220u);
  EXPECT_EQ(m.number_of_faces(), 466u);  // fan of 202 quads, 12 pentagons, 4 hexagons, 2 heptagons
  read_mesh(test::shared_data("meshes/cow.off"), m, {}, &c);
  EXPECT_EQ(c.input_points, 2904u);
  EXPECT_EQ(c.duplicate_points_merged, 1u);
  read_mesh(test::shared_data("broken/pig_nonmanifold.stl"), m, {}, &c);
  EXPECT_GT(m.number_of_faces(), 0u);
}

TEST(ReadMeshRealData, EveryBrokenFileLoadsOrThrowsSurftexError) {
  fs::path dir = test::shared_data("broken");
  int loaded = 0, refused = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    if (sanitized() && e.file_size() > 600000) continue;
    SCOPED_TRACE(e.path().string());
    Mesh m;
    try {
      read_mesh(e.path().string(), m);
      EXPECT_GT(m.number_of_faces(), 0u);
      ++loaded;
    } catch (const Error& err) {
      EXPECT_NE(std::string(err.what()).find(e.path().filename().string()), std::string::npos) << err.what();
      ++refused;
    }
  }
  EXPECT_GT(loaded, 10);
  EXPECT_GE(refused, 4);  // empty, truncated, out-of-memory header, malformed indices, ...
}

TEST(ReadMeshRealData, BrokenFilesWithKnownDefects) {
  expect_throw<IOError>([] { read_polygon_soup(test::shared_data("broken/empty.off")); });
  auto msg = expect_throw<IOError>([] { read_polygon_soup(test::shared_data("broken/out_of_memory_header.off")); });
  EXPECT_NE(msg.find("353535235358"), std::string::npos) << msg;
  expect_throw<Error>([] { read_polygon_soup(test::shared_data("broken/truncated.off")); });
  msg = expect_throw<InvalidInputError>([] { read_polygon_soup(test::shared_data("broken/malformed_indices.obj")); });
  EXPECT_NE(msg.find("12"), std::string::npos) << msg;
  // "f 1// 2//" is dropped and counted; the file's one real triangle loads.
  PolygonSoup short_face = read_polygon_soup(test::shared_data("broken/not_enough_indices.obj"));
  EXPECT_EQ(short_face.short_polygons_dropped, 1u);
  EXPECT_EQ(short_face.polygons.size(), 1u);
  EXPECT_NE(short_face.first_short_polygon.find("line"), std::string::npos) << short_face.first_short_polygon;
}

// ------------------------------------------------------------------ item 9: hostile input

namespace {
struct Variant {
  std::string name, bytes;
};
std::vector<Variant> valid_variants() {
  return {{"t.off", tet_off()},
          {"t.obj", tet_obj()},
          {"a.ply", tet_ply("ascii")},
          {"l.ply", tet_ply("binary_little_endian")},
          {"b.ply", tet_ply("binary_big_endian")},
          {"b.stl", tet_stl_binary()},
          {"a.stl", tet_stl_ascii()}};
}
}  // namespace

TEST(ReadMeshHostile, EmptyFileIsIOErrorForEveryFormat) {
  auto d = test::temp_dir("rm");
  for (std::string n : {"e.off", "e.obj", "e.ply", "e.stl", "e.xyz"}) {
    auto msg = expect_throw<IOError>([&] { read_polygon_soup(write_file(d, n, "")); });
    EXPECT_NE(msg.find(n), std::string::npos) << msg;
  }
}

TEST(ReadMeshHostile, RandomBytesNeverCrash) {
  auto d = test::temp_dir("rm");
  std::mt19937_64 rng(12345);
  for (int trial = 0; trial < 40; ++trial) {
    std::size_t len = 1 + rng() % 3000;
    std::string bytes(len, '\0');
    for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
    for (std::string ext : {".off", ".obj", ".ply", ".stl", ".bin"}) {
      // Also random bytes behind a valid magic, so the parsers get past it.
      for (std::string prefix : {"", "OFF\n", "ply\nformat binary_little_endian 1.0\nelement vertex 3\n"}) {
        std::string p = write_file(d, "r" + ext, prefix + bytes);
        EXPECT_THROW(read_polygon_soup(p), Error) << ext << " trial " << trial;
      }
    }
  }
}

TEST(ReadMeshHostile, TruncatedFilesThrowOrLoadFewerFaces) {
  auto d = test::temp_dir("rm");
  for (const auto& v : valid_variants()) {
    for (double frac : {0.1, 0.3, 0.5, 0.7, 0.9, 0.97}) {
      std::size_t cut = static_cast<std::size_t>(v.bytes.size() * frac);
      std::string p = write_file(d, v.name, v.bytes.substr(0, cut));
      SCOPED_TRACE(v.name + " cut at " + std::to_string(cut));
      const bool must_throw = v.name != "t.obj";  // OBJ has no counts: a prefix can be a smaller valid file
      try {
        auto s = read_polygon_soup(p);
        EXPECT_FALSE(must_throw) << "truncated file loaded with " << s.polygons.size() << " faces";
        EXPECT_LE(s.polygons.size(), 4u);
      } catch (const Error&) {
      }
    }
  }
}

TEST(ReadMeshHostile, AnImageGivenAsAMeshIsNamedAsSuch) {
  auto d = test::temp_dir("rm");
  // A PNG signature followed by bytes that, read as text, hold OBJ-like lines:
  // the sniffer alone would parse them and complain about a "line".
  std::string png("\x89PNG\r\n\x1a\n", 8);
  png += "\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  auto msg = expect_throw<IOError>([&] { read_polygon_soup(write_file(d, "texture.png", png)); });
  EXPECT_NE(msg.find("is a PNG image, not a mesh"), std::string::npos) << msg;
  std::string jpeg("\xff\xd8\xff\xe0", 4);
  msg = expect_throw<IOError>([&] { read_polygon_soup(write_file(d, "photo", jpeg + "\nf 1 2 3\n")); });
  EXPECT_NE(msg.find("is a JPEG image"), std::string::npos) << msg;
}

TEST(ReadMeshHostile, NanAndInfCoordinatesAreInvalidInput) {
  auto d = test::temp_dir("rm");
  for (std::string bad : {"nan", "inf", "-inf", "1e999", "1e300", "-3.5e38"}) {
    SCOPED_TRACE(bad);
    std::string off = "OFF\n3 1 0\n0 0 0\n1 " + bad + " 0\n0 1 0\n3 0 1 2\n";
    auto msg = expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "n.off", off)); });
    EXPECT_NE(msg.find("line 4"), std::string::npos) << msg;
    std::string obj = "v 0 0 0\nv 1 " + bad + " 0\nv 0 1 0\nf 1 2 3\n";
    msg = expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "n.obj", obj)); });
    EXPECT_NE(msg.find("line 2"), std::string::npos) << msg;
    std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\n1 " + bad + " 0\n0 1 0\n3 0 1 2\n";
    expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "n.ply", ply)); });
    std::string stl = tet_stl_ascii();
    stl.replace(stl.find("vertex 1 0 0"), 12, "vertex 1 " + bad + " 0");
    expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "n.stl", stl)); });
  }
  // The largest float is still a coordinate.
  EXPECT_EQ(read_polygon_soup(write_file(d, "f.off", "OFF\n3 1 0\n0 0 0\n3.4e38 0 0\n0 -3.4e38 0\n3 0 1 2\n"))
                .points.size(),
            3u);
  // Binary: a NaN float in a binary PLY and a binary STL.
  std::string ply = tet_ply("binary_little_endian");
  std::size_t body = ply.find("end_header\n") + 11;
  double nan = std::nan("");
  std::memcpy(ply.data() + body, &nan, 8);
  auto msg = expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "nb.ply", ply)); });
  EXPECT_NE(msg.find("vertex 0"), std::string::npos) << msg;
  std::string stl = tet_stl_binary();
  float inf = INFINITY;
  std::memcpy(stl.data() + 84 + 50 * 2 + 12 + 4, &inf, 4);
  msg = expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "nb.stl", stl)); });
  EXPECT_NE(msg.find("triangle 2"), std::string::npos) << msg;
}

TEST(ReadMeshHostile, OutOfRangeAndNegativeIndicesAreInvalidInput) {
  auto d = test::temp_dir("rm");
  for (std::string idx : {"3", "-1", "99999999999"}) {
    SCOPED_TRACE(idx);
    auto msg = expect_throw<InvalidInputError>(
        [&] { read_polygon_soup(write_file(d, "i.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 " + idx + "\n")); });
    EXPECT_NE(msg.find("line 6"), std::string::npos) << msg;
    std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 " + idx + "\n";
    expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "i.ply", ply)); });
  }
  for (std::string idx : {"4", "-4", "0"}) {
    SCOPED_TRACE(idx);
    auto msg = expect_throw<InvalidInputError>(
        [&] { read_polygon_soup(write_file(d, "i.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 " + idx + "\n")); });
    EXPECT_NE(msg.find("line 4"), std::string::npos) << msg;
  }
  // Binary PLY with a negative int index and one past the end.
  for (std::int32_t bad : {-1, 4}) {
    std::string ply = tet_ply("binary_little_endian");
    std::string tail(ply.end() - 12, ply.end());  // last face's 3 uint indices
    std::memcpy(ply.data() + ply.size() - 4, &bad, 4);
    expect_throw<InvalidInputError>([&] { read_polygon_soup(write_file(d, "i.ply", ply)); });
  }
}

TEST(ReadMeshHostile, HugeHeaderCountsFailFastWithoutAllocating) {
  auto d = test::temp_dir("rm");
  auto msg = expect_throw<IOError>(
      [&] { read_polygon_soup(write_file(d, "h.off", "OFF\n3 1000000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")); });
  EXPECT_NE(msg.find("1000000000000"), std::string::npos) << msg;
  expect_throw<IOError>([&] { read_polygon_soup(write_file(d, "h2.off", "OFF\n18446744073709551615 4 0\n")); });
  for (std::string fmt : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    std::string ply = tet_ply(fmt);
    ply.replace(ply.find("element face 4"), 14, "element face 1000000000000");
    msg = expect_throw<IOError>([&] { read_polygon_soup(write_file(d, "h.ply", ply)); });
    EXPECT_NE(msg.find("1000000000000"), std::string::npos) << msg;
  }
  // A face list length beyond the file: binary PLY, count type uint.
  std::string ply = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
  for (int i = 0; i < 9; ++i) put<float>(ply, static_cast<float>(i % 2));
  put<std::uint32_t>(ply, 4000000000u);
  put<std::int32_t>(ply, 0);
  expect_throw<IOError>([&] { read_polygon_soup(write_file(d, "l.ply", ply)); });
  // Binary STL claiming 2^32-1 triangles.
  std::string stl = tet_stl_binary();
  std::uint32_t huge = 0xffffffffu;
  std::memcpy(stl.data() + 80, &huge, 4);
  msg = expect_throw<IOError>([&] { read_polygon_soup(write_file(d, "h.stl", stl)); });
  EXPECT_NE(msg.find("4294967295"), std::string::npos) << msg;
}

TEST(ReadMeshHostile, MissingFileAndFolderAreIOErrors) {
  auto d = test::temp_dir("rm");
  expect_throw<IOError>([&] { read_polygon_soup(d + "/absent.off"); });
  expect_throw<IOError>([&] { read_polygon_soup(d); });
}
