// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "geometry/newell.h"

using namespace surftex;

namespace {
using P = std::array<double, 3>;
std::array<double, 3> normal_of(const std::vector<P>& poly) {
  return newell_normal(poly.size(), [&](std::size_t k) -> const P& { return poly[k]; });
}
}  // namespace

TEST(Newell, NonConvexPlanarPolygonGivesTwiceItsAreaAlongTheRightHandNormal) {
  // An L-shape of area 3 in the plane z = 2, counter-clockwise seen from +z,
  // then tilted: rotated by 30 degrees about the x axis.
  std::vector<P> l = {{0, 0, 2}, {2, 0, 2}, {2, 1, 2}, {1, 1, 2}, {1, 2, 2}, {0, 2, 2}};
  auto n = normal_of(l);
  EXPECT_DOUBLE_EQ(n[0], 0.0);
  EXPECT_DOUBLE_EQ(n[1], 0.0);
  EXPECT_DOUBLE_EQ(n[2], 6.0);
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  std::vector<P> tilted;
  for (const P& p : l) tilted.push_back({p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]});
  n = normal_of(tilted);
  EXPECT_NEAR(n[0], 0.0, 1e-12);
  EXPECT_NEAR(n[1], -6.0 * s, 1e-12);
  EXPECT_NEAR(n[2], 6.0 * c, 1e-12);
  // Reversed corner order: opposite normal.
  std::vector<P> rev(tilted.rbegin(), tilted.rend());
  const auto r = normal_of(rev);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(r[k], -n[k], 1e-12);
}

TEST(Newell, NonPlanarQuadGetsTheSumOfItsTwoTriangleNormals) {
  // A skew quad: the Newell vector equals the sum of the cross products of
  // its diagonal split (either split), here checked against the first one.
  std::vector<P> q = {{0, 0, 0}, {1, 0, 0.3}, {1, 1, 0}, {0, 1, 0.3}};
  auto cross = [](const P& a, const P& b) {
    return P{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  auto sub = [](const P& a, const P& b) { return P{a[0] - b[0], a[1] - b[1], a[2] - b[2]}; };
  const P t1 = cross(sub(q[1], q[0]), sub(q[2], q[0]));
  const P t2 = cross(sub(q[2], q[0]), sub(q[3], q[0]));
  const auto n = normal_of(q);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(n[k], t1[k] + t2[k], 1e-12);
  EXPECT_GT(n[2], 0.0);
}
