// SPDX-License-Identifier: AGPL-3.0-or-later
// flatten_disc_chart's direct LSCM solve (LscmSolver::kDirect, decision 210)
// against CGAL's LSCM_parameterizer_3 (kCgal), and its per-thread vertex map.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <vector>

#include "geometry/disc_chart.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "test_support.h"

using namespace surftex;

namespace {
using UV2 = std::array<double, 2>;

// Largest uv difference over the chart's vertices, relative to its uv extent.
double relative_difference(const std::vector<UV2>& a, const std::vector<UV2>& b) {
  double diff = 0, lo = HUGE_VAL, hi = -HUGE_VAL;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max({diff, std::abs(a[i][0] - b[i][0]), std::abs(a[i][1] - b[i][1])});
    lo = std::min({lo, a[i][0], a[i][1]}), hi = std::max({hi, a[i][0], a[i][1]});
  }
  return diff / (hi - lo);
}

// Disc charts of up to `max_faces` faces grown from a few seeds spread over `mesh`.
std::vector<std::vector<int>> some_charts(const Mesh& mesh, std::size_t max_faces) {
  DiscGrowthState state(mesh);
  std::vector<std::vector<int>> charts;
  const int nf = static_cast<int>(mesh.number_of_faces());
  for (int seed : {0, nf / 3, 2 * nf / 3})
    charts.push_back(grow_disc_chart(mesh, seed, [](int) { return true; }, max_faces, state));
  return charts;
}
}  // namespace

// The same pinned vertices and energy: the same uvs up to rounding, on
// charts of a real mesh and of a sphere.
TEST(DiscChart, DirectLscmMatchesCgalLscm) {
  Mesh elephant, sphere;
  read_mesh(test::shared_data("meshes/elephant.off"), elephant);
  make_icosphere(sphere, 3);
  double largest = 0;
  for (const Mesh* m : {&elephant, &sphere})
    for (const auto& faces : some_charts(*m, 600)) {
      const DiscChartFlattening direct = flatten_disc_chart(*m, faces, LscmSolver::kDirect);
      const DiscChartFlattening cgal = flatten_disc_chart(*m, faces, LscmSolver::kCgal);
      ASSERT_EQ(direct.status, DiscChartFlattening::Status::kOk) << direct.error;
      ASSERT_EQ(cgal.status, DiscChartFlattening::Status::kOk) << cgal.error;
      ASSERT_EQ(direct.vertices, cgal.vertices);
      const double diff = relative_difference(direct.uv, cgal.uv);
      largest = std::max(largest, diff);
      EXPECT_LT(diff, 1e-8) << faces.size() << " faces";
      EXPECT_NEAR(direct.area_distortion, cgal.area_distortion, 1e-8);
      EXPECT_EQ(direct.flipped_faces, cgal.flipped_faces);
      EXPECT_EQ(direct.border_crossings, cgal.border_crossings);
    }
  std::cout << "[ lscm ] direct vs CGAL: largest uv difference " << largest << " of the chart's extent\n";
}

// The mesh-to-chart vertex map kept per thread is clean after every chart,
// a failed one included, and after a chart of a smaller mesh.
TEST(DiscChart, RepeatedFlatteningsAreIdentical) {
  Mesh big, small;
  make_icosphere(big, 4);
  make_grid(small, 3, 3);
  const std::vector<int> chart = some_charts(big, 300).front();
  const DiscChartFlattening first = flatten_disc_chart(big, chart, LscmSolver::kDirect);
  std::vector<int> all(big.number_of_faces());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  EXPECT_EQ(flatten_disc_chart(big, all).status, DiscChartFlattening::Status::kTopology);  // closed: not a disc
  EXPECT_EQ(flatten_disc_chart(small, {0}).status, DiscChartFlattening::Status::kOk);
  const DiscChartFlattening again = flatten_disc_chart(big, chart, LscmSolver::kDirect);
  EXPECT_EQ(again.vertices, first.vertices);
  EXPECT_EQ(again.uv, first.uv);
}
