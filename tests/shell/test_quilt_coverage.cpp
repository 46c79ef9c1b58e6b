// SPDX-License-Identifier: AGPL-3.0-or-later
// The bare area of a quilt as written (shell/quilting/quilt_coverage.h).
#include <gtest/gtest.h>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "shell/quilting/quilt_coverage.h"

namespace surftex {
namespace {

// A quilt over the left half of a unit square, floating 0.05 above it:
// its feet (closest points on the base) cover that half only.
TEST(QuiltCoverage, OutputCoversWhereItsElementsStand) {
  Mesh base, quilt;
  make_grid(base, 20, 20);
  make_grid(quilt, 10, 20, 0.5, 1.0);
  for (VertexIndex v : quilt.vertices()) quilt.point(v) = quilt.point(v) + Vector3(0, 0, 0.05);
  const BareArea b = output_bare_area(base, quilt, 0.05, {1, 0, 0});
  EXPECT_NEAR(b.overall, 0.5, 0.06);
  EXPECT_LT(b.by_height[0], 0.01);  // bands along x: the left quarter covered
  EXPECT_GT(b.by_height[3], 0.99);  // the right quarter bare
  // The same quilt over the whole square covers it.
  Mesh whole;
  make_grid(whole, 20, 20);
  EXPECT_LT(output_bare_area(base, whole, 0.05, {0, 1, 0}).overall, 1e-12);
}

// What the embedding removed is bare: an empty output leaves the whole base bare.
TEST(QuiltCoverage, AnEmptyOutputIsAllBare) {
  Mesh base, none;
  make_icosphere(base, 2);
  const BareArea b = output_bare_area(base, none, 0.1, {0, 1, 0});
  EXPECT_DOUBLE_EQ(b.overall, 1.0);
  for (double x : b.by_height) EXPECT_DOUBLE_EQ(x, 1.0);
  EXPECT_THROW(output_bare_area(base, none, 0.0, {0, 1, 0}), InvalidInputError);
}

}  // namespace
}  // namespace surftex
