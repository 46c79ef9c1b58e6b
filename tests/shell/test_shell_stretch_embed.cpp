// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>

#include "geometry/base_mesh_atlas.h"
#include "geometry/errors.h"
#include "geometry/primitive_meshes.h"
#include "geometry/self_intersections.h"
#include "shell/embed_in_shell.h"
#include "shell/shell_map.h"
#include "shell/shell_space.h"
#include "shell/shell_stretch.h"
#include "shell_test_util.h"

using namespace surftex;
using surftex::test::count_not_positive;

namespace {
constexpr double kPi = 3.14159265358979323846;

ShellSpace sphere_shell(double height) {
  Mesh m;
  make_icosphere(m, test::sanitized() ? 2 : 3);
  compute_base_mesh_atlas(m);
  ShellSpaceOptions opt;
  opt.height = height;
  return build_shell_space(m, opt);
}

// A grid folded by `angle` about x = 1 into a concave V (valley): the right half
// rises toward the left half's normal side.
void make_valley(Mesh& m, int nx, int ny, double angle) {
  make_grid(m, nx, ny, 2.0, 1.0);
  for (VertexIndex v : m.vertices()) {
    const Point3 p = m.point(v);
    if (p.x() > 1.0) {
      const double t = p.x() - 1.0;
      m.point(v) = Point3(1.0 + t * std::cos(angle), p.y(), t * std::sin(angle));
    }
  }
}

// Appends a closed box [c - a, c + a] x [w0, w1] (texture coordinates as points).
void add_box(Mesh& out, double u, double v, double a, double w0, double w1) {
  VertexIndex q[8];
  for (int i = 0; i < 8; ++i)
    q[i] = out.add_vertex(Point3(i & 1 ? u + a : u - a, i & 2 ? v + a : v - a, i & 4 ? w1 : w0));
  const int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (auto& s : f) {
    out.add_face(q[s[0]], q[s[1]], q[s[2]]);
    out.add_face(q[s[0]], q[s[2]], q[s[3]]);
  }
}
}  // namespace

TEST(ShellStretch, MinimizationLowersStretchOnASphereAndKeepsTetsPositive) {
  ShellSpace s = sphere_shell(1.0);
  const ShellSpace before = s;
  ASSERT_EQ(count_not_positive(s), std::make_pair(std::size_t{0}, std::size_t{0}));
  const double st0 = shell_stretch(s).l2_normalized;
  EXPECT_GT(st0, 1.0);
  MinimizeStretchOptions opt;
  opt.iterations = test::sanitized() ? 5 : 20;
  const MinimizeStretchResult r = shell_map_minimize_stretch(s, opt);
  EXPECT_DOUBLE_EQ(r.stretch_before, st0);
  EXPECT_LT(r.stretch_after, r.stretch_before);  // strictly better on a curved base
  EXPECT_GE(r.stretch_after, 1.0);
  EXPECT_DOUBLE_EQ(shell_stretch(s).l2_normalized, r.stretch_after);
  EXPECT_GT(r.moves_accepted, 0u);
  EXPECT_GT(r.free_vertices, 0u);
  EXPECT_GE(r.colors, 2);
  EXPECT_EQ(count_not_positive(s), std::make_pair(std::size_t{0}, std::size_t{0}));
  // Only free offset-surface (u, v) moved; bottom layer, lateral vertices, w and 3D untouched.
  std::size_t moved = 0;
  for (std::size_t i = 0; i < s.texture_points.size(); ++i) {
    EXPECT_EQ(s.shell_points[i], before.shell_points[i]);
    EXPECT_EQ(s.texture_points[i][2], before.texture_points[i][2]);
    if (s.layer[i] == 0 || s.lateral[i]) {
      EXPECT_EQ(s.texture_points[i], before.texture_points[i]) << i;
    }
    moved += s.texture_points[i] != before.texture_points[i];
  }
  EXPECT_GT(moved, 0u);
}

TEST(ShellStretch, MinimizationIsDeterministicAcrossThreadCounts) {
  MinimizeStretchOptions opt;
  opt.iterations = 3;
  opt.seed = 42;
  ShellSpace a = sphere_shell(0.8), b = a, c = a;
  shell_map_minimize_stretch(a, opt);
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    shell_map_minimize_stretch(b, opt);
  }
  EXPECT_EQ(a.texture_points, b.texture_points);
  opt.seed = 43;
  shell_map_minimize_stretch(c, opt);
  EXPECT_NE(a.texture_points, c.texture_points);
}

TEST(ShellStretch, IdentityLikeShellStaysAtOne) {
  Mesh m;
  make_grid(m, 4, 4);
  test::set_planar_uv(m, 0.7, 0.1);
  ShellSpace s = build_shell_space(m);
  const MinimizeStretchResult r = shell_map_minimize_stretch(s);
  EXPECT_NEAR(r.stretch_before, 1.0, 1e-9);
  EXPECT_NEAR(r.stretch_after, 1.0, 1e-9);
  EXPECT_EQ(r.moves_accepted, 0u);  // nothing below the lower bound to find
}

TEST(ShellStretch, RejectsBadOptions) {
  Mesh m;
  make_grid(m, 2, 2);
  test::set_planar_uv(m, 1.0, 0.0);
  ShellSpace s = build_shell_space(m);
  MinimizeStretchOptions opt;
  opt.step_fraction = 0;
  EXPECT_THROW(shell_map_minimize_stretch(s, opt), InvalidInputError);
  opt = {};
  opt.line_samples = 0;
  EXPECT_THROW(shell_map_minimize_stretch(s, opt), InvalidInputError);
  EXPECT_THROW(shell_stretch(ShellSpace{}), InvalidInputError);
}

// Figure 8 of the paper: in a concave region, placing small elements by their
// base triangle's local frame (barycentric position + height along the face
// normal) makes elements of the two sides run into each other; the shell map
// embedding does not.
TEST(EmbedInShell, ConcaveValleyNaiveDisplacementIntersectsShellMapDoesNot) {
  Mesh base;
  make_valley(base, 20, 6, kPi / 2);
  BaseMeshAtlasOptions ao;
  ao.max_normal_angle_deg = 95;  // the whole valley is one (developable) chart
  ASSERT_EQ(compute_base_mesh_atlas(base, ao).num_charts, 1);
  ShellSpaceOptions so;
  so.height = 1.2;
  ShellSpace shell = build_shell_space(base, so);
  ASSERT_EQ(count_not_positive(shell), std::make_pair(std::size_t{0}, std::size_t{0}));
  const ShellMap map(shell);

  // A layer of small boxes on a lattice in texture space, kept where fully inside.
  const double spacing = 0.45 * shell.height * shell.uv_per_length, half = 0.3 * spacing;
  Mesh layer;
  std::vector<std::array<double, 2>> centres;
  for (double u = 0; u <= 1; u += spacing)
    for (double v = 0; v <= 1; v += spacing) {
      bool inside = true;
      for (int i = 0; i < 8 && inside; ++i)
        inside = map.locate_texture({i & 1 ? u + half : u - half, i & 2 ? v + half : v - half, i & 4 ? 0.9 : 0.1})
                     .inside;
      if (!inside) continue;
      add_box(layer, u, v, half, 0.1, 0.9);
      centres.push_back({u, v});
    }
  ASSERT_GT(centres.size(), 50u);
  ASSERT_EQ(count_self_intersections(layer), 0u);  // disjoint in texture space

  // Naive: every box vertex in the frame of the base face under the box centre.
  auto uvmap = find(base, kCornerUV).first;
  Mesh naive = layer;
  std::size_t box = 0;
  std::vector<VertexIndex> verts(naive.vertices().begin(), naive.vertices().end());
  for (std::size_t i = 0; i < verts.size(); i += 8, ++box) {
    const auto loc = map.locate_texture({centres[box][0], centres[box][1], 0.5});
    ASSERT_TRUE(loc.inside);
    const FaceIndex f(static_cast<Mesh::size_type>(shell.tet_face[static_cast<std::size_t>(loc.tet)]));
    HalfedgeIndex h = base.halfedge(f);
    const HalfedgeIndex hs[3] = {h, base.next(h), base.prev(h)};
    Point3 P[3];
    UV T[3];
    for (int k = 0; k < 3; ++k) P[k] = base.point(base.target(hs[k])), T[k] = uvmap[hs[k]];
    const Vector3 n = CGAL::cross_product(P[1] - P[0], P[2] - P[0]);
    const Vector3 nu = n / std::sqrt(n.squared_length());
    const double det = (T[1][0] - T[0][0]) * (T[2][1] - T[0][1]) - (T[1][1] - T[0][1]) * (T[2][0] - T[0][0]);
    for (std::size_t j = i; j < i + 8; ++j) {
      const Point3 q = naive.point(verts[j]);
      const double b1 = ((q.x() - T[0][0]) * (T[2][1] - T[0][1]) - (q.y() - T[0][1]) * (T[2][0] - T[0][0])) / det;
      const double b2 = ((T[1][0] - T[0][0]) * (q.y() - T[0][1]) - (T[1][1] - T[0][1]) * (q.x() - T[0][0])) / det;
      const Vector3 d = b1 * (P[1] - P[0]) + b2 * (P[2] - P[0]);
      naive.point(verts[j]) = P[0] + d + q.z() * shell.height * nu;
    }
  }
  const std::size_t naive_hits = count_self_intersections(naive);
  EXPECT_GT(naive_hits, 0u);

  Mesh embedded = layer;
  const EmbedInShellResult r = embed_in_shell(embedded, map);
  EXPECT_EQ(r.vertices, layer.number_of_vertices());
  EXPECT_EQ(r.outside, 0u);
  EXPECT_TRUE(r.checked);
  EXPECT_EQ(r.self_intersecting_pairs, 0u);
  std::cout << "[ valley ] boxes " << centres.size() << ", naive intersecting pairs " << naive_hits
            << ", shell-map pairs " << r.self_intersecting_pairs << "\n";

  // Away from the crease the two embeddings agree (LSCM unfolds the valley
  // isometrically and vertex normals equal face normals there).
  std::size_t agree = 0;
  std::vector<VertexIndex> ve(embedded.vertices().begin(), embedded.vertices().end());
  for (std::size_t j = 0; j < ve.size(); ++j)
    agree += CGAL::squared_distance(embedded.point(ve[j]), naive.point(verts[j])) < 1e-18 ? 1 : 0;
  EXPECT_GT(agree, ve.size() / 4);
}

TEST(EmbedInShell, OutsideVerticesAreRefusedOrExtrapolatedAndCounted) {
  Mesh base;
  make_grid(base, 3, 3);
  test::set_planar_uv(base, 0.5, 0.25);  // texture space covers [0.25, 0.75]^2
  const ShellSpace shell = build_shell_space(base);
  const ShellMap map(shell);
  Mesh m;
  const VertexIndex a = m.add_vertex(Point3(0.5, 0.5, 0.5)), b = m.add_vertex(Point3(0.6, 0.5, 0.5)),
                    c = m.add_vertex(Point3(0.9, 0.5, 0.5));
  m.add_face(a, b, c);
  Mesh copy = m;
  EmbedInShellOptions opt;
  opt.outside_policy = EmbedInShellOptions::Outside::kRefuse;
  EXPECT_THROW(embed_in_shell(copy, map, opt), InvalidInputError);
  opt.outside_policy = EmbedInShellOptions::Outside::kExtrapolate;
  const EmbedInShellResult r = embed_in_shell(m, map, opt);
  EXPECT_EQ(r.outside, 1u);
  // Flat unit grid, uv = 0.5 * xy + 0.25: (u,v,w) maps to ((u-.25)/.5, (v-.25)/.5, w * h).
  EXPECT_NEAR(m.point(a).x(), 0.5, 1e-12);
  EXPECT_NEAR(m.point(a).z(), 0.5 * shell.height, 1e-12);
  EXPECT_NEAR(m.point(c).x(), 1.3, 1e-9);  // linear extrapolation of the nearest tet
}
