// SPDX-License-Identifier: AGPL-3.0-or-later
// make_swatch on hostile meshes built in code (issue #8 audit): what the file
// readers never let through (non-finite points) and the edge cases of the
// swatch's box (flat, one face, no xy extent).
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "shell/swatch.h"

using namespace surftex;

namespace {
// One triangle with corners a, b, c.
Mesh triangle(const Point3& a, const Point3& b, const Point3& c) {
  Mesh m;
  const VertexIndex va = m.add_vertex(a), vb = m.add_vertex(b), vc = m.add_vertex(c);  // in this order
  m.add_face(va, vb, vc);
  return m;
}
}  // namespace

TEST(SwatchHostile, NonFiniteCoordinateIsRefusedNamingTheVertex) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {nan, inf, -inf}) {
    const Mesh m = triangle(Point3(0, 0, 0), Point3(1, 0, 0), Point3(0, 1, bad));
    try {
      make_swatch(m);
      ADD_FAILURE() << "accepted a swatch with coordinate " << bad;
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find("vertex 2 has a non-finite coordinate"), std::string::npos) << e.what();
    }
  }
}

TEST(SwatchHostile, FlatAndOneFaceSwatchesAreAccepted) {
  const Swatch flat = make_swatch(triangle(Point3(0, 0, 0), Point3(2, 0, 0), Point3(0, 3, 0)));
  EXPECT_EQ(flat.elements.size(), 1u);
  EXPECT_EQ(flat.height(), 0.0);
  EXPECT_EQ(flat.length(), 2.0);
  EXPECT_EQ(flat.width(), 3.0);
  EXPECT_FALSE(flat.elements[0].closed);  // one triangle has three border edges
  EXPECT_EQ(flat.elements[0].faces, 1u);
}

TEST(SwatchHostile, NoFaceOrNoXyExtentIsRefused) {
  Mesh empty;
  empty.add_vertex(Point3(0, 0, 0));
  EXPECT_THROW(make_swatch(empty), InvalidInputError);
  // y extent 0: a triangle standing in the xz plane.
  EXPECT_THROW(make_swatch(triangle(Point3(0, 0, 0), Point3(1, 0, 0), Point3(0, 0, 1))), InvalidInputError);
}
