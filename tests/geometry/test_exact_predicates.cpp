// SPDX-License-Identifier: AGPL-3.0-or-later
// Exact-predicate regression tests: near-degenerate configurations where a
// naive double evaluation gets the sign wrong. Each answer of surftex::Kernel
// (Epick) is compared with exact arithmetic (Epeck: exact rationals), and the
// same inputs are run through a naive double kernel (Simple_cartesian<double>)
// to show that the cases are hard: if someone swapped surftex::Kernel for a
// plain double kernel, these tests would fail.
#include <gtest/gtest.h>

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/self_intersections.h"

namespace surftex {
namespace {

using Exact = CGAL::Exact_predicates_exact_constructions_kernel;
using Naive = CGAL::Simple_cartesian<double>;

template <class K>
CGAL::Orientation orient2(double px, double py, double qx, double qy, double rx, double ry) {
  using P = typename K::Point_2;
  return CGAL::orientation(P(px, py), P(qx, qy), P(rx, ry));
}

template <class K>
CGAL::Orientation orient3(const std::array<double, 3>& a, const std::array<double, 3>& b,
                          const std::array<double, 3>& c, const std::array<double, 3>& d) {
  using P = typename K::Point_3;
  return CGAL::orientation(P(a[0], a[1], a[2]), P(b[0], b[1], b[2]), P(c[0], c[1], c[2]),
                           P(d[0], d[1], d[2]));
}

using Tri = std::array<std::array<double, 3>, 3>;

template <class K>
bool triangles_intersect(const Tri& s, const Tri& t) {
  using P = typename K::Point_3;
  using T = typename K::Triangle_3;
  auto mk = [](const Tri& x) {
    return T(P(x[0][0], x[0][1], x[0][2]), P(x[1][0], x[1][1], x[1][2]),
             P(x[2][0], x[2][1], x[2][2]));
  };
  return CGAL::do_intersect(mk(s), mk(t));
}

/// The classic failure of orient2d (Kettner et al., "Classroom examples of
/// robustness problems in geometric computations"): p near (0.5, 0.5)
/// perturbed by a few ulps, q = (12, 12), r = (24, 24), all nearly on y = x.
TEST(ExactPredicates, NearlyCollinearOrientation2D) {
  const double u = std::ldexp(1.0, -53);  // half an ulp of 1; ulp of 0.5
  std::size_t cases = 0, naive_wrong = 0, naive_zero_wrong = 0;
  for (int i = 0; i < 32; ++i) {
    for (int j = 0; j < 32; ++j) {
      const double px = 0.5 + i * u, py = 0.5 + j * u;
      const CGAL::Orientation exact = orient2<Exact>(px, py, 12, 12, 24, 24);
      // By hand: det = (qx-px)(ry-py) - (qy-py)(rx-px) = 12 (py - px) for
      // q = (12,12), r = (24,24), so the exact sign is sign(py - px).
      const CGAL::Orientation by_hand =
          py > px ? CGAL::LEFT_TURN : (py < px ? CGAL::RIGHT_TURN : CGAL::COLLINEAR);
      ASSERT_EQ(exact, by_hand) << i << "," << j;
      EXPECT_EQ((orient2<Kernel>(px, py, 12, 12, 24, 24)), exact) << "Epick wrong at " << i << "," << j;
      const CGAL::Orientation naive = orient2<Naive>(px, py, 12, 12, 24, 24);
      ++cases;
      if (naive != exact) {
        ++naive_wrong;
        if (naive == CGAL::COLLINEAR || exact == CGAL::COLLINEAR) ++naive_zero_wrong;
      }
    }
  }
  std::printf("orient2d: %zu cases, naive double wrong on %zu (%zu involving 0)\n", cases,
              naive_wrong, naive_zero_wrong);
  EXPECT_GT(naive_wrong, 0u) << "the cases no longer trip a naive double kernel";
}

/// Four points nearly coplanar: a, b, c span the plane x = y; d lies a few
/// ulps off it near (0.5, 0.5, 0.5), far from a, b, c (the 3D form of the
/// orient2d case above).
TEST(ExactPredicates, NearlyCoplanarOrientation3D) {
  const std::array<double, 3> a{12, 12, 0}, b{24, 24, 0}, c{12, 12, 7};
  const double u = std::ldexp(1.0, -53);
  std::size_t cases = 0, naive_wrong = 0;
  for (int i = 0; i < 24; ++i) {
    for (int j = 0; j < 24; ++j) {
      std::array<double, 3> d{0.5 + i * u, 0.5 + j * u, 0.5};
      const CGAL::Orientation exact = orient3<Exact>(d, a, b, c);
      // By hand: det(a-d, b-d, c-d) = 7 * 12 (dy - dx), so the sign is sign(dy - dx).
      const CGAL::Orientation by_hand =
          d[1] > d[0] ? CGAL::POSITIVE : (d[1] < d[0] ? CGAL::NEGATIVE : CGAL::ZERO);
      ASSERT_EQ(exact, by_hand) << i << "," << j;
      EXPECT_EQ((orient3<Kernel>(d, a, b, c)), exact) << "Epick wrong at " << i << "," << j;
      if (orient3<Naive>(d, a, b, c) != exact) ++naive_wrong;
      ++cases;
    }
  }
  std::printf("orient3d: %zu cases, naive double wrong on %zu\n", cases, naive_wrong);
  EXPECT_GT(naive_wrong, 0u) << "the cases no longer trip a naive double kernel";
}

/// Triangle pairs that touch, overlap in a plane, or miss by one ulp.
TEST(ExactPredicates, TouchingAndCoplanarTriangles) {
  const double one_up = std::nextafter(0.5, 1.0);
  struct Case {
    std::string name;
    Tri s, t;
    bool expected;  // derived by hand; also checked against Epeck below
  };
  const Tri base{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  std::vector<Case> cases = {
      // Only a vertex in common, the other triangle going off upwards.
      {"shared vertex only", base, Tri{{{1, 0, 0}, {2, 0.5, 1}, {2, -0.5, 1}}}, true},
      // Coplanar, overlapping interiors.
      {"coplanar overlap", base, Tri{{{0.2, 0.2, 0}, {2, 0.2, 0}, {0.2, 2, 0}}}, true},
      // Coplanar, a vertex exactly on the hypotenuse x + y = 1.
      {"coplanar touching", base, Tri{{{0.5, 0.5, 0}, {2, 1, 0}, {1, 2, 0}}}, true},
      // Coplanar, that vertex one ulp beyond the hypotenuse: disjoint.
      {"coplanar disjoint by 1 ulp", base, Tri{{{0.5, one_up, 0}, {2, 1, 0}, {1, 2, 0}}}, false},
  };
  // Non-representable coordinates: triangles sharing a vertex v on a skew
  // plane, the second rotated about v; exact answer: they touch (true).
  for (int k = 1; k <= 40; ++k) {
    const double v[3] = {0.1 * k, 0.3, 0.7 / k};
    Tri s{{{v[0], v[1], v[2]}, {v[0] + 1.1, v[1] + 0.3, v[2] - 0.2}, {v[0] + 0.2, v[1] + 1.3, v[2] + 0.1}}};
    Tri t{{{v[0], v[1], v[2]}, {v[0] - 1.1, v[1] - 0.3, v[2] + 0.2}, {v[0] - 0.2, v[1] - 1.3, v[2] - 0.1 * k}}};
    cases.push_back({"shared skew vertex " + std::to_string(k), s, t, true});
  }
  std::size_t naive_wrong = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const bool exact = triangles_intersect<Exact>(c.s, c.t);
    EXPECT_EQ(exact, c.expected);
    EXPECT_EQ(triangles_intersect<Kernel>(c.s, c.t), exact);
    EXPECT_EQ(triangles_intersect<Kernel>(c.t, c.s), exact);
    if (triangles_intersect<Naive>(c.s, c.t) != exact) ++naive_wrong;
  }
  std::printf("triangle pairs: %zu cases, naive double wrong on %zu\n", cases.size(), naive_wrong);
}

// ------------------------------------------- surftex self-intersection detection

Mesh two_faces_sharing_edge(double dx, double dy, double dz) {
  Mesh m;
  VertexIndex a = m.add_vertex(Point3(0, 0, 0)), b = m.add_vertex(Point3(1, 0, 0)),
              c = m.add_vertex(Point3(0, 1, 0)), d = m.add_vertex(Point3(dx, dy, dz));
  m.add_face(a, b, c);
  m.add_face(b, a, d);  // across edge a-b
  return m;
}

TEST(ExactPredicates, SelfIntersectionOfAdjacentFaces) {
  // Unfolded (flat, d below the shared edge): adjacent, no intersection.
  EXPECT_EQ(count_self_intersections(two_faces_sharing_edge(0.5, -0.5, 0)), 0u);
  // Folded at 90 degrees: still only the shared edge.
  EXPECT_EQ(count_self_intersections(two_faces_sharing_edge(0.5, 0, 1)), 0u);
  // Folded flat onto the first face: coplanar overlap -> 1 pair.
  EXPECT_EQ(count_self_intersections(two_faces_sharing_edge(0.3, 0.3, 0)), 1u);
  // Folded almost flat, d off the plane by the smallest double: the faces
  // only share their edge -> 0 pairs (exact orientation test).
  const double tiny = std::numeric_limits<double>::denorm_min();
  EXPECT_EQ(count_self_intersections(two_faces_sharing_edge(0.3, 0.3, tiny)), 0u);
  EXPECT_EQ(count_self_intersections(two_faces_sharing_edge(0.3, 0.3, -tiny)), 0u);
  // Parallel and sequential detection agree.
  SelfIntersectionOptions seq;
  seq.parallel = false;
  EXPECT_EQ(count_self_intersections(two_faces_sharing_edge(0.3, 0.3, 0), seq), 1u);
}

TEST(ExactPredicates, SelfIntersectionOfFacesSharingOnlyAVertex) {
  Mesh m;
  VertexIndex o = m.add_vertex(Point3(0.1, 0.2, 0.3));
  VertexIndex a = m.add_vertex(Point3(1.1, 0.2, 0.3)), b = m.add_vertex(Point3(0.1, 1.2, 0.3));
  VertexIndex c = m.add_vertex(Point3(-0.9, 0.2, 0.3)), d = m.add_vertex(Point3(0.1, -0.8, 0.3));
  m.add_face(o, a, b);
  m.add_face(o, c, d);  // coplanar, opposite quadrant: only o in common
  EXPECT_EQ(count_self_intersections(m), 0u);
  // A third face whose vertex touches the interior of the first face (not
  // adjacent to it): touching counts as an intersection.
  Mesh t;
  VertexIndex p = t.add_vertex(Point3(0, 0, 0)), q = t.add_vertex(Point3(1, 0, 0)),
              r = t.add_vertex(Point3(0, 1, 0));
  t.add_face(p, q, r);
  VertexIndex s0 = t.add_vertex(Point3(0.25, 0.25, 0)), s1 = t.add_vertex(Point3(0.25, 0.25, 1)),
              s2 = t.add_vertex(Point3(0.75, 0.25, 1));
  t.add_face(s0, s1, s2);
  EXPECT_EQ(count_self_intersections(t), 1u);
  // Lift it by one ulp of 0: no contact.
  t.point(s0) = Point3(0.25, 0.25, std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(count_self_intersections(t), 0u);
}

}  // namespace
}  // namespace surftex

// The face-subset check (a recheck after part of a mesh changed) reports
// exactly the pairs of the whole check with both faces in the subset, and
// refuses a face the mesh does not have.
TEST(ExactPredicates, SelfIntersectionsAmongASubsetOfFaces) {
  Mesh m;
  std::uint64_t h = 12345;
  auto rnd = [&] {
    h = h * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(h >> 11) / static_cast<double>(1ull << 53);
  };
  for (int t = 0; t < 200; ++t) {  // a soup of random triangles in the unit cube: many crossings
    const Point3 c(rnd(), rnd(), rnd());
    VertexIndex v[3];
    for (auto& x : v)
      x = m.add_vertex(
          Point3(c.x() + 0.2 * (rnd() - 0.5), c.y() + 0.2 * (rnd() - 0.5), c.z() + 0.2 * (rnd() - 0.5)));
    m.add_face(v[0], v[1], v[2]);
  }
  const std::vector<FacePair> all = self_intersecting_faces(m);
  ASSERT_GT(all.size(), 20u);
  std::vector<std::uint32_t> subset, every;
  for (std::uint32_t f = 0; f < m.number_of_faces(); ++f) {
    every.push_back(f);
    if (f % 3 != 0) subset.push_back(f);
  }
  EXPECT_EQ(self_intersecting_faces(m, every), all);
  std::vector<FacePair> expected;
  for (const FacePair& p : all)
    if (p[0] % 3 != 0 && p[1] % 3 != 0) expected.push_back(p);
  ASSERT_LT(expected.size(), all.size());
  EXPECT_EQ(self_intersecting_faces(m, subset), expected);
  EXPECT_TRUE(self_intersecting_faces(m, std::vector<std::uint32_t>{}).empty());
  EXPECT_THROW(self_intersecting_faces(m, std::vector<std::uint32_t>{999}), InvalidInputError);
}
