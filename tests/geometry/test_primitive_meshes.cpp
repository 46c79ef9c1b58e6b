// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"

using namespace surftex;
namespace PMP = CGAL::Polygon_mesh_processing;

namespace {
int border_edges(const Mesh& m) {
  int n = 0;
  for (auto e : m.edges()) n += m.is_border(e) ? 1 : 0;
  return n;
}
int euler(const Mesh& m) {
  return static_cast<int>(m.number_of_vertices()) - static_cast<int>(m.number_of_edges()) +
         static_cast<int>(m.number_of_faces());
}
}  // namespace

TEST(PrimitiveMeshes, ClosedShapesHaveExpectedCountsAndOutwardOrientation) {
  Mesh m;
  make_tetrahedron(m);
  EXPECT_EQ(m.number_of_faces(), 4u);
  EXPECT_EQ(border_edges(m), 0);
  EXPECT_TRUE(PMP::is_outward_oriented(m));
  EXPECT_GT(PMP::volume(m), 0);

  make_cube(m, 2.0);
  EXPECT_EQ(m.number_of_vertices(), 8u);
  EXPECT_EQ(m.number_of_faces(), 12u);
  EXPECT_NEAR(PMP::volume(m), 8.0, 1e-12);
  EXPECT_TRUE(PMP::is_outward_oriented(m));

  make_icosphere(m, 3, 2.0);
  EXPECT_EQ(m.number_of_vertices(), 10u * 64 + 2);
  EXPECT_EQ(euler(m), 2);
  EXPECT_TRUE(PMP::is_outward_oriented(m));
  EXPECT_NEAR(PMP::volume(m), 4.0 / 3.0 * 3.14159265 * 8, 1.0);

  make_torus(m, 2.0, 0.5, 24, 12);
  EXPECT_EQ(m.number_of_vertices(), 24u * 12);
  EXPECT_EQ(euler(m), 0);  // genus 1
  EXPECT_EQ(border_edges(m), 0);
  EXPECT_GT(PMP::volume(m), 0);
}

TEST(PrimitiveMeshes, OpenShapesHaveExpectedBorders) {
  Mesh m;
  make_grid(m, 4, 3, 2.0, 1.0);
  EXPECT_EQ(m.number_of_vertices(), 20u);
  EXPECT_EQ(m.number_of_faces(), 24u);
  EXPECT_EQ(border_edges(m), 2 * (4 + 3));
  EXPECT_NEAR(PMP::area(m), 2.0, 1e-12);
  make_cylinder(m, 1.0, 2.0, 16, 4);
  EXPECT_EQ(border_edges(m), 32);
  EXPECT_EQ(euler(m), 0);
  make_open_cone(m, 1.0, 1.0, 12, 3);
  EXPECT_EQ(border_edges(m), 12);
  EXPECT_EQ(euler(m), 1);  // a disc
}

TEST(PrimitiveMeshes, InvalidParametersThrow) {
  Mesh m;
  EXPECT_THROW(make_grid(m, 0, 3), InvalidInputError);
  EXPECT_THROW(make_torus(m, 1.0, 2.0, 8, 8), InvalidInputError);
  EXPECT_THROW(make_icosphere(m, 12), InvalidInputError);
}
