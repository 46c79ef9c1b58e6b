// SPDX-License-Identifier: AGPL-3.0-or-later
// triangulated_copy: fans that keep the copy a valid manifold triangle mesh
// (a fan diagonal that is already an edge is avoided), vertex colours kept.
#include <gtest/gtest.h>

#include <vector>

#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/triangulated_copy.h"

namespace surftex {
namespace {

bool all_triangles(const Mesh& m) {
  for (FaceIndex f : m.faces())
    if (m.degree(f) != 3) return false;
  return true;
}

bool has_edge(const Mesh& m, std::uint32_t a, std::uint32_t b) {
  return m.halfedge(VertexIndex(a), VertexIndex(b)) != Mesh::null_halfedge();
}

// A closed "pillow": quad (0,1,2,3) whose shorter diagonal 0-2 is already an
// edge of the two triangles behind it. The plain fan from 0 would add 0-2 a
// second time (four faces on one edge); the copy must use 1-3 instead.
TEST(TriangulatedCopy, AvoidsAnExistingDiagonal) {
  Mesh m;
  const VertexIndex v0 = m.add_vertex(Point3(0, 0, 0)), v1 = m.add_vertex(Point3(0.5, 1, 0.2)),
                    v2 = m.add_vertex(Point3(1, 0, 0)), v3 = m.add_vertex(Point3(0.5, -1, 0.2));
  ASSERT_NE(m.add_face(v0, v1, v2, v3), Mesh::null_face());
  ASSERT_NE(m.add_face(v1, v0, v2), Mesh::null_face());
  ASSERT_NE(m.add_face(v2, v0, v3), Mesh::null_face());
  ASSERT_TRUE(m.is_valid(false));
  auto col = get_or_add(m, kVertexColor);
  for (VertexIndex v : m.vertices()) col[v] = Color3f{0.1f * v.idx(), 0.5f, 1.f - 0.2f * v.idx()};

  Mesh t;
  const std::vector<std::uint32_t> from = triangulated_copy(m, t);
  EXPECT_TRUE(t.is_valid(false));
  EXPECT_TRUE(all_triangles(t));
  EXPECT_EQ(t.number_of_vertices(), 4u) << "no vertex copies needed";
  EXPECT_EQ(t.number_of_faces(), 4u);
  EXPECT_EQ(t.number_of_edges(), 6u);
  EXPECT_TRUE(CGAL::is_closed(t)) << "a tetrahedron: every edge has two faces";
  EXPECT_TRUE(has_edge(t, 1, 3));
  ASSERT_EQ(from, (std::vector<std::uint32_t>{0, 1, 2, 3}));
  auto tc = find(t, kVertexColor);
  ASSERT_TRUE(tc.second);
  for (VertexIndex v : t.vertices()) EXPECT_EQ(tc.first[v], col[VertexIndex(from[v.idx()])]);
}

// Two quads glued along both edges of the valence-2 vertex 1, both with the
// shorter diagonal 0-2: the second must not reuse the first one's fan
// diagonal (a-c in four triangles), and takes 1-4.
TEST(TriangulatedCopy, AvoidsADiagonalOfAnEarlierFan) {
  Mesh m;
  std::vector<VertexIndex> v;
  for (const auto& p : {Point3(0, 0, 0), Point3(1, 0.2, 0), Point3(2, 0, 0), Point3(1, -3, 0), Point3(1, 3, 0)})
    v.push_back(m.add_vertex(p));
  ASSERT_NE(m.add_face(v[0], v[1], v[2], v[3]), Mesh::null_face());
  ASSERT_NE(m.add_face(v[2], v[1], v[0], v[4]), Mesh::null_face());
  Mesh t;
  const std::vector<std::uint32_t> from = triangulated_copy(m, t);
  EXPECT_TRUE(t.is_valid(false));
  EXPECT_TRUE(all_triangles(t));
  EXPECT_EQ(t.number_of_faces(), 4u);
  EXPECT_EQ(from.size(), 5u);
  EXPECT_TRUE(has_edge(t, 0, 2));
  EXPECT_TRUE(has_edge(t, 1, 4));
}

// A lone quad is split along its shorter diagonal.
TEST(TriangulatedCopy, QuadSplitsAlongTheShorterDiagonal) {
  for (const double stretch : {0.5, 2.0}) {
    Mesh m;
    const VertexIndex v0 = m.add_vertex(Point3(-stretch, 0, 0)), v1 = m.add_vertex(Point3(0, -1, 0)),
                      v2 = m.add_vertex(Point3(stretch, 0, 0)), v3 = m.add_vertex(Point3(0, 1, 0));
    ASSERT_NE(m.add_face(v0, v1, v2, v3), Mesh::null_face());
    Mesh t;
    triangulated_copy(m, t);
    EXPECT_TRUE(t.is_valid(false));
    EXPECT_EQ(t.number_of_faces(), 2u);
    EXPECT_EQ(has_edge(t, 0, 2), stretch < 1) << stretch;
    EXPECT_EQ(has_edge(t, 1, 3), stretch > 1) << stretch;
    EXPECT_FALSE(find(t, kVertexColor).second) << "no colours in, none out";
  }
}

}  // namespace
}  // namespace surftex
