// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/boost/graph/helpers.h>

#include <cmath>

#include "texture/subdivision/adaptive_sqrt2_subdivide.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "texture/subdivision/sqrt2_subdivide.h"
#include "texture/subdivision/turk_orientation_field.h"

using namespace surftex;
namespace PMP = CGAL::Polygon_mesh_processing;

namespace {
// nx x ny quads over [0,nx] x [0,ny].
void make_quad_grid(Mesh& m, int nx, int ny) {
  m.clear();
  std::vector<VertexIndex> v;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) v.push_back(m.add_vertex(Point3(i, j, 0)));
  auto id = [&](int i, int j) { return v[j * (nx + 1) + i]; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) m.add_face(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
}
std::size_t count_degree(const Mesh& m, unsigned d) {
  std::size_t n = 0;
  for (FaceIndex f : m.faces()) n += m.degree(f) == d;
  return n;
}
std::size_t border_edges(const Mesh& m) {
  std::size_t n = 0;
  for (auto e : m.edges()) n += m.is_border(e);
  return n;
}
}  // namespace

// Exact counts for an nx x ny quad grid: V' = V + F = (nx+1)(ny+1) + nx ny
// (about twice V), one face per old edge E = nx(ny+1) + ny(nx+1), of which the
// 2(nx+ny) border edges give triangles and the rest quads.
TEST(Sqrt2Subdivide, QuadGridCountsAreExact) {
  for (auto [nx, ny] : {std::pair{1, 1}, std::pair{4, 3}, std::pair{10, 10}}) {
    Mesh m;
    make_quad_grid(m, nx, ny);
    const auto r = sqrt2_subdivide(m);
    const std::size_t V = (nx + 1) * (ny + 1) + nx * ny;
    const std::size_t E = nx * (ny + 1) + ny * (nx + 1);
    EXPECT_EQ(m.number_of_vertices(), V);
    EXPECT_EQ(m.number_of_faces(), E);
    EXPECT_EQ(count_degree(m, 3), std::size_t(2 * (nx + ny)));
    EXPECT_EQ(count_degree(m, 4), E - 2 * (nx + ny));
    EXPECT_EQ(r.triangles, std::size_t(2 * (nx + ny)));
    EXPECT_EQ(r.face_points, std::size_t(nx * ny));
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    // Every triangle touches the border.
    for (FaceIndex f : m.faces())
      if (m.degree(f) == 3) {
        bool on_border = false;
        for (auto h : m.halfedges_around_face(m.halfedge(f))) on_border |= m.is_border(m.opposite(h));
        EXPECT_TRUE(on_border);
      }
  }
}

TEST(Sqrt2Subdivide, TwoStepsOnGridQuadrupleFacesAndOrdinaryVerticesHaveValenceFour) {
  Mesh m;
  make_quad_grid(m, 8, 8);
  sqrt2_subdivide(m);
  sqrt2_subdivide(m);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  // Away from the border (where the border triangles of the first step leave
  // valence-3 face points) every vertex is ordinary.
  std::size_t interior = 0, four = 0;
  for (VertexIndex v : m.vertices()) {
    const Point3 p = m.point(v);
    if (p.x() < 1.5 || p.x() > 6.5 || p.y() < 1.5 || p.y() > 6.5) continue;
    ++interior;
    four += m.degree(v) == 4;
  }
  EXPECT_GT(interior, 50u);
  EXPECT_EQ(four, interior);  // the grid has no extraordinary vertices
}

TEST(Sqrt2Subdivide, ClosedMeshesStayClosedValidAndAllQuads) {
  Mesh m;
  make_icosphere(m, 1);
  const double area0 = PMP::area(m);
  for (int step = 0; step < 3; ++step) {
    const std::size_t V = m.number_of_vertices(), F = m.number_of_faces(), E = m.number_of_edges();
    sqrt2_subdivide(m);
    EXPECT_EQ(m.number_of_vertices(), V + F);
    EXPECT_EQ(m.number_of_faces(), E);
    EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
    EXPECT_TRUE(CGAL::is_closed(m));
    EXPECT_EQ(count_degree(m, 4), m.number_of_faces());
    EXPECT_EQ(int(m.number_of_vertices()) - int(m.number_of_edges()) + int(m.number_of_faces()), 2);
  }
  // Approximating: the smoothed surface shrinks a little inside the sphere, not much.
  Mesh tri = m;
  PMP::triangulate_faces(tri);
  const double a = PMP::area(tri);
  EXPECT_LT(a, area0 * 1.05);
  EXPECT_GT(a, area0 * 0.8);
  EXPECT_GT(PMP::volume(tri), 0);  // orientation kept outward
}

TEST(Sqrt2Subdivide, OldVerticesKeepIndicesAndColoursAverageOntoFacePoints) {
  Mesh m;
  make_quad_grid(m, 2, 1);
  auto col = get_or_add(m, kVertexColor);
  for (VertexIndex v : m.vertices()) col[v] = {float(v.idx()) / 10.f, 0.5f, 1.f};
  Sqrt2SubdivideOptions o;
  o.smooth = false;
  sqrt2_subdivide(m, o);
  auto c = find(m, kVertexColor);
  ASSERT_TRUE(c.second);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_FLOAT_EQ(c.first[VertexIndex(i)][0], float(i) / 10.f);
  // Face 0 = vertices 0,1,4,3 -> mean 0.2; face 1 = 1,2,5,4 -> 0.3.
  EXPECT_NEAR(c.first[VertexIndex(6)][0], 0.2f, 1e-6);
  EXPECT_NEAR(c.first[VertexIndex(7)][0], 0.3f, 1e-6);
  EXPECT_DOUBLE_EQ(m.point(VertexIndex(6)).x(), 0.5);
}

TEST(Sqrt2Subdivide, PolygonMeshWithNgonsAndBadInput) {
  Mesh m;
  // a pentagon fan: one pentagon and a triangle glued
  std::vector<VertexIndex> v;
  for (int i = 0; i < 5; ++i) v.push_back(m.add_vertex(Point3(std::cos(i * 1.2566), std::sin(i * 1.2566), 0)));
  const VertexIndex c = m.add_vertex(Point3(2, 0, 0));
  m.add_face(v);
  m.add_face(v[1], v[0], c);
  sqrt2_subdivide(m);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  EXPECT_EQ(m.number_of_vertices(), 8u);
  EXPECT_EQ(m.number_of_faces(), 7u);  // 7 edges: 1 quad + 6 border triangles
  EXPECT_EQ(count_degree(m, 4), 1u);

  Mesh empty;
  EXPECT_THROW(sqrt2_subdivide(empty), InvalidInputError);
  Sqrt2SubdivideOptions bad;
  bad.vertex_weight = 1.5;
  EXPECT_THROW(sqrt2_subdivide(m, bad), InvalidInputError);
  EXPECT_THROW(sqrt2_subdivide_selected(m, std::vector<char>(3, 1)), InvalidInputError);
}

TEST(AdaptiveSqrt2Subdivide, KeepsClosedValidAndReducesAreaDeviation) {
  // A sphere with very uneven faces: refine one hemisphere twice first.
  Mesh m;
  make_icosphere(m, 1);
  for (int k = 0; k < 2; ++k) {
    std::vector<char> sel(m.number_of_faces(), 0);
    for (FaceIndex f : m.faces()) {
      const Point3 p = m.point(m.target(m.halfedge(f)));
      sel[f.idx()] = p.z() > 0.2;
    }
    sqrt2_subdivide_selected(m, sel);
    ASSERT_TRUE(CGAL::is_valid_polygon_mesh(m));
    ASSERT_TRUE(CGAL::is_closed(m));
  }
  AdaptiveSubdivideOptions o;
  o.factor = 1.5;
  o.steps = 6;
  const auto r = adaptive_sqrt2_subdivide(m, o);
  EXPECT_TRUE(CGAL::is_valid_polygon_mesh(m));
  EXPECT_TRUE(CGAL::is_closed(m));
  EXPECT_EQ(border_edges(m), 0u);
  ASSERT_GE(r.area_std_percent.size(), 2u);
  EXPECT_EQ(r.area_std_percent.size(), std::size_t(r.steps_done + 1));
  EXPECT_LT(r.area_std_percent.back(), 0.7 * r.area_std_percent.front());
  EXPECT_NEAR(r.area_std_percent.back(), face_area_std_percent(m), 1e-9);
  EXPECT_EQ(int(m.number_of_vertices()) - int(m.number_of_edges()) + int(m.number_of_faces()), 2);

  AdaptiveSubdivideOptions bad;
  bad.factor = 0;
  EXPECT_THROW(adaptive_sqrt2_subdivide(m, bad), InvalidInputError);
}

TEST(TurkOrientationField, TangentUnitAndCoarseToFine) {
  Mesh m;
  make_icosphere(m, 2);
  const auto r = turk_orientation_field(m, {{0, {1, 0, 0}}, {5, {0, 1, 1}}});
  EXPECT_EQ(r.unreached, 0u);
  EXPECT_GT(r.fill_passes, 0);
  auto check = [](const Mesh& mm) {
    auto d = find(mm, kVertexDirection);
    ASSERT_TRUE(d.second);
    for (VertexIndex v : mm.vertices()) {
      const Vector3 n = mm.point(v) - CGAL::ORIGIN;  // sphere: normal ~ position
      const Vector3 t = d.first[v];
      EXPECT_NEAR(t.squared_length(), 1.0, 1e-9);
      EXPECT_LT(std::abs(t * n) / std::sqrt(n.squared_length()), 0.1);
    }
  };
  check(m);
  sqrt2_subdivide(m);
  TurkFieldOptions o;
  o.from_existing = true;
  turk_orientation_field(m, {{0, {1, 0, 0}}, {5, {0, 1, 1}}}, o);
  check(m);
  const auto s = turk_sweep_field(m, 0);
  EXPECT_LT(s.min_value, s.max_value);
  EXPECT_THROW(turk_orientation_field(m, {{m.number_of_vertices(), {1, 0, 0}}}), InvalidInputError);
  EXPECT_THROW(turk_orientation_field(m, {{0, {0, 0, 0}}}), InvalidInputError);
  EXPECT_THROW(turk_sweep_field(m, m.number_of_vertices()), InvalidInputError);
}

TEST(TurkSweepField, IncreasesAlongAConstantFieldOnAGrid) {
  Mesh m;
  make_quad_grid(m, 10, 4);
  turk_orientation_field(m, {{0, {1, 0, 0}}});
  turk_sweep_field(m, 0);
  auto s = find(m, kVertexSweep).first;
  // Along every row the sweep increases with x (the field is +x everywhere).
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i < 10; ++i)
      EXPECT_LT(s[VertexIndex(j * 11 + i)], s[VertexIndex(j * 11 + i + 1)]);
  EXPECT_NEAR(s[VertexIndex(10)] - s[VertexIndex(0)], 10.0, 1e-6);
}
