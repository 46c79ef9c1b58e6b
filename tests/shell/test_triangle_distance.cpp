// SPDX-License-Identifier: AGPL-3.0-or-later
// TriangleDistance (the closest-point queries of mesh quilting) against a
// brute force over every triangle, on a generated swatch and on random
// triangle soups with degenerate (collinear, point-like) triangles.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "shell/swatch.h"
#include "shell/swatch_generators.h"
#include "shell/triangle_distance.h"

using namespace surftex;

namespace {

// The squared distance from q to segment se and to triangle abc: the minimum
// over the projection on the face's plane (when inside) and the three edges,
// written independently of the library's Voronoi-region code.
double segment_d2(const P3& q, const P3& s, const P3& e) {
  P3 d{e[0] - s[0], e[1] - s[1], e[2] - s[2]};
  const double l = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  double t = l > 0 ? ((q[0] - s[0]) * d[0] + (q[1] - s[1]) * d[1] + (q[2] - s[2]) * d[2]) / l : 0;
  t = std::clamp(t, 0.0, 1.0);
  double r = 0;
  for (int k = 0; k < 3; ++k) r += (q[k] - s[k] - t * d[k]) * (q[k] - s[k] - t * d[k]);
  return r;
}

double triangle_d2(const P3& q, const P3& a, const P3& b, const P3& c) {
  double best = std::min({segment_d2(q, a, b), segment_d2(q, b, c), segment_d2(q, c, a)});
  const P3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const P3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double nn = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  if (nn > 1e-20) {
    const double h = ((q[0] - a[0]) * n[0] + (q[1] - a[1]) * n[1] + (q[2] - a[2]) * n[2]) / nn;
    const P3 p{q[0] - h * n[0], q[1] - h * n[1], q[2] - h * n[2]};
    // Inside test by the signs of the three sub-areas along n.
    auto side = [&](const P3& s, const P3& e) {
      const P3 x{e[0] - s[0], e[1] - s[1], e[2] - s[2]}, y{p[0] - s[0], p[1] - s[1], p[2] - s[2]};
      const P3 cr{x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
      return cr[0] * n[0] + cr[1] * n[1] + cr[2] * n[2];
    };
    if (side(a, b) >= 0 && side(b, c) >= 0 && side(c, a) >= 0) best = std::min(best, h * h * nn);
  }
  return best;
}

void expect_matches_brute_force(const ElementMesh& m, const std::vector<P3>& queries) {
  const TriangleDistance td(m);
  for (const P3& q : queries) {
    double best = std::numeric_limits<double>::infinity();
    for (const Tri& t : m.tris) best = std::min(best, triangle_d2(q, m.points[t[0]], m.points[t[1]], m.points[t[2]]));
    const auto h = td.closest(q);
    ASSERT_GE(h.tri, 0);
    const double scale = 1e-9 * (1 + best);
    EXPECT_NEAR(h.distance * h.distance, best, scale);
    // The reported point lies on the reported triangle at the reported barycentrics, at that distance.
    const Tri& t = m.tris[h.tri];
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      const double x = h.bary[0] * m.points[t[0]][k] + h.bary[1] * m.points[t[1]][k] + h.bary[2] * m.points[t[2]][k];
      EXPECT_NEAR(x, h.point[k], 1e-9);
      d2 += (q[k] - x) * (q[k] - x);
    }
    EXPECT_NEAR(d2, best, scale);
    EXPECT_LE(td.box_squared_distance(q), best);  // the box bound never exceeds the distance
    EXPECT_NEAR(h.bary[0] + h.bary[1] + h.bary[2], 1.0, 1e-12);
    for (int k = 0; k < 3; ++k) EXPECT_GE(h.bary[k], -1e-12);
  }
}

// The same hit, bit for bit.
bool same_hit(const TriangleDistance::Hit& a, const TriangleDistance::Hit& b) {
  return a.tri == b.tri && a.distance == b.distance && a.point == b.point && a.bary == b.bary;
}

Swatch weave_swatch() {
  Mesh weave;
  make_weave_swatch(weave);
  return make_swatch(weave);
}

}  // namespace

TEST(TriangleDistance, MatchesBruteForceOnAWeaveSwatch) {
  const Swatch s = weave_swatch();
  std::mt19937_64 rng(3);
  std::vector<P3> q;
  std::uniform_real_distribution<double> u(-0.3, 1.3);
  for (int i = 0; i < 400; ++i) {
    P3 p;
    for (int k = 0; k < 3; ++k) p[k] = s.bbox_min[k] + u(rng) * (s.bbox_max[k] - s.bbox_min[k]);
    q.push_back(p);
  }
  for (int i = 0; i < 100; ++i) q.push_back(s.mesh.points[(i * 97) % s.mesh.points.size()]);  // on the surface
  expect_matches_brute_force(s.mesh, q);
}

TEST(TriangleDistance, MatchesBruteForceOnSoupsWithDegenerateTriangles) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0, 1);
  for (int round = 0; round < 5; ++round) {
    ElementMesh m;
    for (int t = 0; t < 300; ++t) {
      const P3 c{g(rng), g(rng), g(rng)};
      const int base = static_cast<int>(m.points.size());
      for (int k = 0; k < 3; ++k) m.points.push_back({c[0] + 0.2 * g(rng), c[1] + 0.2 * g(rng), c[2] + 0.2 * g(rng)});
      if (t % 10 == 0) m.points[base + 2] = {(m.points[base][0] + m.points[base + 1][0]) / 2,  // collinear
                                             (m.points[base][1] + m.points[base + 1][1]) / 2,
                                             (m.points[base][2] + m.points[base + 1][2]) / 2};
      if (t % 25 == 0) m.points[base + 1] = m.points[base + 2] = m.points[base];  // a point
      m.tris.push_back({base, base + 1, base + 2});
    }
    std::vector<P3> q;
    for (int i = 0; i < 300; ++i) q.push_back({1.5 * g(rng), 1.5 * g(rng), 1.5 * g(rng)});
    expect_matches_brute_force(m, q);
  }
}

TEST(TriangleDistance, EmptyMeshAndTiesAreDefined) {
  const TriangleDistance none(ElementMesh{});
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(none.closest({0, 0, 0}).tri, -1);
  EXPECT_EQ(none.box_squared_distance({5, 0, 0}), 0.0);
  // Two copies of one triangle: the first in the mesh is reported, whichever the tree visits first.
  ElementMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 20; ++i) m.tris.push_back({0, 1, 2});
  const TriangleDistance td(m);
  const auto h = td.closest({0.2, 0.2, 1.0});
  EXPECT_EQ(td.box_squared_distance({3, 0.5, 0}), 4.0);  // 2 beyond the box along x
  EXPECT_EQ(td.box_squared_distance({0.2, 0.2, 0}), 0.0);  // inside it
  EXPECT_EQ(h.tri, 0);
  EXPECT_NEAR(h.distance, 1.0, 1e-15);
}

// A non-finite query point gives a NaN distance, not an index out of range.
TEST(TriangleDistance, NonFiniteQueryGivesNaN) {
  const Swatch s = weave_swatch();
  const TriangleDistance td(s.mesh);
  const auto h = td.closest({std::nan(""), 0, 0});
  EXPECT_TRUE(std::isnan(h.distance));
  EXPECT_GE(h.tri, 0);
  EXPECT_LT(h.tri, static_cast<int>(s.mesh.tris.size()));
}

// The hint (the previous query's triangle) only orders the search: any hint,
// far, near, out of range or at a tie, gives the hit of no hint, bit for bit.
TEST(TriangleDistance, AHintNeverChangesTheHit) {
  const Swatch s = weave_swatch();
  const TriangleDistance td(s.mesh);
  const int n = static_cast<int>(s.mesh.tris.size());
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  int hint = -1;
  for (int i = 0; i < 300; ++i) {
    P3 q;
    for (int k = 0; k < 3; ++k) q[k] = s.bbox_min[k] + u(rng) * (s.bbox_max[k] - s.bbox_min[k]);
    const auto plain = td.closest(q);
    EXPECT_TRUE(same_hit(plain, td.closest(q, hint)));            // the previous hit, as the callers pass it
    EXPECT_TRUE(same_hit(plain, td.closest(q, (i * 7919) % n)));  // any triangle
    EXPECT_TRUE(same_hit(plain, td.closest(q, n + i)));           // out of range: ignored
    hint = plain.tri;
  }
  // Ties: twenty copies of one triangle; hinting a later copy still reports the first.
  ElementMesh m;
  m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 20; ++i) m.tris.push_back({0, 1, 2});
  const TriangleDistance tie(m);
  EXPECT_EQ(tie.closest({0.2, 0.2, 1.0}, 17).tri, 0);
}

// Cell lists (build_cell_lists) answer queries inside their grid from a list:
// the same hits as the tree walk, bit for bit, inside, at the margin and
// outside the grid, on a swatch and on soups with degenerate triangles.
TEST(TriangleDistance, CellListsGiveTheTreesHits) {
  const Swatch s = weave_swatch();
  const TriangleDistance tree(s.mesh);
  TriangleDistance cells(s.mesh);
  cells.build_cell_lists(s.mean_edge_length);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  int differ = 0;
  for (int i = 0; i < 2000; ++i) {
    P3 q;
    for (int k = 0; k < 3; ++k) q[k] = s.bbox_min[k] + u(rng) * (s.bbox_max[k] - s.bbox_min[k]);
    differ += !same_hit(tree.closest(q), cells.closest(q));
  }
  for (const P3& p : s.mesh.points)
    differ += !same_hit(tree.closest(p), cells.closest(p));  // on the surface: ties
  EXPECT_EQ(differ, 0);
  std::normal_distribution<double> g(0, 1);
  ElementMesh m;
  for (int t = 0; t < 300; ++t) {
    const int base = static_cast<int>(m.points.size());
    const P3 c{g(rng), g(rng), g(rng)};
    for (int k = 0; k < 3; ++k)
      m.points.push_back({c[0] + 0.2 * g(rng), c[1] + 0.2 * g(rng), c[2] + 0.2 * g(rng)});
    if (t % 10 == 0) m.points[base + 2] = m.points[base + 1];  // degenerate
    m.tris.push_back({base, base + 1, base + 2});
  }
  std::vector<P3> q;
  for (int i = 0; i < 2000; ++i) q.push_back({2 * g(rng), 2 * g(rng), 2 * g(rng)});
  TriangleDistance soup(m);
  soup.build_cell_lists(0.1, 4096);  // coarser than asked: the cell grows to fit 4096 cells
  const TriangleDistance soup_tree(m);
  for (const P3& p : q) differ += !same_hit(soup_tree.closest(p), soup.closest(p));
  EXPECT_EQ(differ, 0);
}

// A query on a swatch vertex is at distance 0 from every triangle around it:
// the first of them in the mesh wins, by the tree walk and by the cell lists,
// whatever bounds skip triangles early (the plane bound keeps a margin for
// its own rounding: without it the triangles whose plane passes through the
// vertex up to rounding are skipped and a later one wins).
TEST(TriangleDistance, AVertexQueryGoesToTheFirstTriangleAroundIt) {
  const Swatch s = weave_swatch();
  std::vector<int> first(s.mesh.points.size(), -1);
  for (std::size_t t = s.mesh.tris.size(); t-- > 0;)
    for (int k = 0; k < 3; ++k) first[static_cast<std::size_t>(s.mesh.tris[t][k])] = static_cast<int>(t);
  const TriangleDistance tree(s.mesh);
  TriangleDistance cells(s.mesh);
  cells.build_cell_lists(0.5 * s.mean_edge_length);
  int wrong_tree = 0, wrong_cells = 0, checked = 0;
  for (std::size_t v = 0; v < s.mesh.points.size(); ++v) {
    if (first[v] < 0) continue;
    ++checked;
    const auto a = tree.closest(s.mesh.points[v]), b = cells.closest(s.mesh.points[v]);
    wrong_tree += a.tri != first[v] || a.distance != 0;
    wrong_cells += b.tri != first[v] || b.distance != 0;
  }
  EXPECT_GT(checked, 1000);
  EXPECT_EQ(wrong_tree, 0);
  EXPECT_EQ(wrong_cells, 0);
}

// closest_within gives closest's hit whenever that lies within the radius
// (the same triangle, distance, point and barycentrics), else none; a query
// on the surface is found at radius 0 (the bound's absolute margin: the
// computed closest point of a face's centroid is off it by rounding).
TEST(TriangleDistance, ClosestWithinARadiusIsTheClosestHitOrNone) {
  const Swatch s = weave_swatch();
  TriangleDistance cells(s.mesh);
  cells.build_cell_lists(0.5 * s.mean_edge_length);
  const TriangleDistance tree(s.mesh);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-0.3, 1.3), r(0.0, 0.6);
  int within = 0, beyond = 0, wrong = 0;
  for (int i = 0; i < 3000; ++i) {
    P3 q;
    for (int k = 0; k < 3; ++k) q[k] = s.bbox_min[k] + u(rng) * (s.bbox_max[k] - s.bbox_min[k]);
    const double radius = r(rng);
    for (const TriangleDistance* td : {&tree, static_cast<const TriangleDistance*>(&cells)}) {
      const auto all = td->closest(q), near = td->closest_within(q, radius);
      if (all.distance <= radius) {
        ++within;
        wrong += !same_hit(all, near);
      } else {
        ++beyond;
        wrong += near.tri >= 0 && !same_hit(all, near);
      }
    }
  }
  EXPECT_GT(within, 500);
  EXPECT_GT(beyond, 500);
  EXPECT_EQ(wrong, 0);
  // Face centroids (the merge's coverage queries), at the distance closest
  // reports for them (0 up to rounding): found.
  int missed = 0;
  for (const Tri& t : s.mesh.tris) {
    P3 c;
    for (int k = 0; k < 3; ++k) c[k] = (s.mesh.points[t[0]][k] + s.mesh.points[t[1]][k] + s.mesh.points[t[2]][k]) / 3.0;
    const auto all = tree.closest(c);
    missed += !same_hit(tree.closest_within(c, 0.0), all) || !same_hit(cells.closest_within(c, all.distance), all);
  }
  EXPECT_EQ(missed, 0);
  EXPECT_THROW(tree.closest_within(s.mesh.points[0], -1.0), InvalidInputError);
  EXPECT_THROW(tree.closest_within(s.mesh.points[0], std::nan("")), InvalidInputError);
}
