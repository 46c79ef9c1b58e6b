// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <map>
#include <set>

#include "atlas_checks.h"
#include "geometry/base_mesh_atlas.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "test_support.h"

using namespace surftex;

namespace {
// Checks every chart of `m` (kFacePatch) is a topological disc: V - E + F = 1
// counted on the chart's own faces, and its border edges form one loop.
void expect_disc_charts(const Mesh& m, int num_charts) {
  auto patch = find(m, kFacePatch).first;
  for (int c = 0; c < num_charts; ++c) {
    std::set<VertexIndex> vs;
    std::set<EdgeIndex> es;
    std::size_t nf = 0;
    std::map<VertexIndex, int> border_degree;
    std::size_t border_edges = 0;
    for (FaceIndex f : m.faces()) {
      if (patch[f] != c) continue;
      ++nf;
      for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
        vs.insert(m.target(h));
        es.insert(m.edge(h));
        HalfedgeIndex o = m.opposite(h);
        if (m.is_border(o) || patch[m.face(o)] != c) {
          ++border_edges;
          border_degree[m.source(h)]++;
          border_degree[m.target(h)]++;
        }
      }
    }
    ASSERT_GT(nf, 0u) << "chart " << c;
    const long chi = static_cast<long>(vs.size()) - static_cast<long>(es.size()) + static_cast<long>(nf);
    EXPECT_EQ(chi, 1) << "chart " << c;
    // One simple border loop: every border vertex has border degree 2 and the
    // number of border vertices equals the number of border edges (a union of
    // loops), and walking from one vertex visits all of them.
    EXPECT_EQ(border_degree.size(), border_edges) << "chart " << c;
    for (auto& [v, d] : border_degree) EXPECT_EQ(d, 2) << "chart " << c;
    // Walk the loop along chart-border halfedges.
    std::map<VertexIndex, VertexIndex> next;
    for (FaceIndex f : m.faces()) {
      if (patch[f] != c) continue;
      for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
        HalfedgeIndex o = m.opposite(h);
        if (m.is_border(o) || patch[m.face(o)] != c) next[m.source(h)] = m.target(h);
      }
    }
    ASSERT_FALSE(next.empty());
    VertexIndex start = next.begin()->first, v = start;
    std::size_t steps = 0;
    do {
      v = next.at(v);
      ++steps;
    } while (v != start && steps <= next.size());
    EXPECT_EQ(steps, next.size()) << "chart " << c << " border is not one loop";
  }
}

void expect_uvs_in_unit_square_and_consistent(const Mesh& m) {
  auto uv = find(m, kCornerUV).first;
  auto patch = find(m, kFacePatch).first;
  std::map<std::pair<int, VertexIndex>, UV> seen;
  for (FaceIndex f : m.faces())
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
      const UV& p = uv[h];
      EXPECT_GE(p[0], 0.0);
      EXPECT_LE(p[0], 1.0);
      EXPECT_GE(p[1], 0.0);
      EXPECT_LE(p[1], 1.0);
      auto [it, ins] = seen.try_emplace({patch[f], m.target(h)}, p);
      if (!ins) {
        EXPECT_EQ(it->second, p) << "corner uvs of one vertex differ inside chart " << patch[f];
      }
    }
}

// An icosphere with radial bumps: its normals turn within a few faces, so the
// 50-degree growth leaves many small charts.
void make_bumpy_sphere(Mesh& m) {
  make_icosphere(m, 4);
  for (VertexIndex v : m.vertices()) {
    const Point3 p = m.point(v);
    const double r = 1 + 0.15 * std::sin(9 * p.x()) * std::sin(9 * p.y()) * std::sin(9 * p.z());
    m.point(v) = Point3(p.x() * r, p.y() * r, p.z() * r);
  }
}

// Triangles of different charts must not overlap in uv: chart bounding boxes are disjoint.
void expect_disjoint_chart_boxes(const Mesh& m, int num_charts) {
  auto uv = find(m, kCornerUV).first;
  auto patch = find(m, kFacePatch).first;
  std::vector<std::array<double, 4>> box(num_charts, {1e9, 1e9, -1e9, -1e9});
  for (FaceIndex f : m.faces())
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
      auto& b = box[patch[f]];
      b = {std::min(b[0], uv[h][0]), std::min(b[1], uv[h][1]), std::max(b[2], uv[h][0]), std::max(b[3], uv[h][1])};
    }
  for (int a = 0; a < num_charts; ++a)
    for (int b = a + 1; b < num_charts; ++b) {
      const bool apart = box[a][2] <= box[b][0] || box[b][2] <= box[a][0] || box[a][3] <= box[b][1] ||
                         box[b][3] <= box[a][1];
      EXPECT_TRUE(apart) << "charts " << a << " and " << b << " overlap in uv";
    }
}
}  // namespace

TEST(BaseMeshAtlas, ChartsAreDiscsOnClosedGenus0Genus1AndOpenMeshes) {
  struct Case {
    const char* name;
    Mesh mesh;
  };
  std::vector<Case> cases(4);
  cases[0].name = "icosphere";
  make_icosphere(cases[0].mesh, 3);
  cases[1].name = "torus";
  make_torus(cases[1].mesh, 1.0, 0.35, 32, 16);
  cases[2].name = "open cylinder";
  make_cylinder(cases[2].mesh, 0.5, 1.5, 24, 10);
  cases[3].name = "grid";
  make_grid(cases[3].mesh, 12, 9, 2.0, 1.0);
  for (auto& c : cases) {
    SCOPED_TRACE(c.name);
    BaseMeshAtlasResult r = compute_base_mesh_atlas(c.mesh);
    ASSERT_GE(r.num_charts, 1);
    std::size_t total = 0;
    for (auto n : r.chart_faces) total += n;
    EXPECT_EQ(total, c.mesh.number_of_faces());
    EXPECT_EQ(r.flipped_faces, 0u);
    EXPECT_GT(r.uv_per_length, 0.0);
    EXPECT_GT(r.packing_efficiency, 0.15);
    std::cout << "[ atlas ] " << c.name << ": " << r.num_charts << " charts, packing " << r.packing_efficiency
              << ", area distortion " << r.mean_area_distortion << "\n";
    EXPECT_LT(r.packing_efficiency, 1.0);
    EXPECT_GE(r.mean_area_distortion, 1.0);
    EXPECT_LT(r.mean_area_distortion, 1.5);
    expect_disc_charts(c.mesh, r.num_charts);
    expect_uvs_in_unit_square_and_consistent(c.mesh);
    expect_disjoint_chart_boxes(c.mesh, r.num_charts);
  }
}

TEST(BaseMeshAtlas, ClosedSurfacesNeedSeveralChartsAndFlatGridOne) {
  Mesh sphere, grid;
  make_icosphere(sphere, 2);
  make_grid(grid, 6, 6);
  // A closed surface can never be one disc; a flat grid is exactly one chart.
  EXPECT_GE(compute_base_mesh_atlas(sphere).num_charts, 2);
  BaseMeshAtlasResult g = compute_base_mesh_atlas(grid);
  EXPECT_EQ(g.num_charts, 1);
  EXPECT_NEAR(g.mean_area_distortion, 1.0, 1e-6);  // LSCM of a planar chart is a similarity
}

TEST(BaseMeshAtlas, FaceBudgetSplitsChartsAndIsDeterministic) {
  Mesh a, b;
  make_torus(a, 1.0, 0.4, 24, 12);
  make_torus(b, 1.0, 0.4, 24, 12);
  BaseMeshAtlasOptions opt;
  opt.max_chart_faces = 40;
  BaseMeshAtlasResult ra = compute_base_mesh_atlas(a, opt), rb = compute_base_mesh_atlas(b, opt);
  for (auto n : ra.chart_faces) EXPECT_LE(n, 40u);
  EXPECT_EQ(ra.num_charts, rb.num_charts);
  auto ua = find(a, kCornerUV).first, ub = find(b, kCornerUV).first;
  for (HalfedgeIndex h : a.halfedges())
    if (!a.is_border(h)) {
      ASSERT_EQ(ua[h], ub[h]);
    }
  expect_disc_charts(a, ra.num_charts);
}

// Regression: LSCM folded charts over themselves (fish_blub's largest chart,
// elephant's: thousands of texels of a 2048 grid covered twice), unseen by
// the flip count. Every flattening is now an embedding.
TEST(BaseMeshAtlas, FlatteningsNeverFoldOverThemselves) {
  for (const char* name : {"meshes/fish_blub.obj", "meshes/elephant.off"}) {
    SCOPED_TRACE(name);
    Mesh m;
    read_mesh(test::shared_data(name), m);
    const BaseMeshAtlasResult r = compute_base_mesh_atlas(m);
    EXPECT_EQ(r.flipped_faces, 0u);
    EXPECT_EQ(test::uv_flipped_faces(m), 0u);
    EXPECT_EQ(test::uv_overlap_texels(m, 2048), 0u);
    expect_disc_charts(m, r.num_charts);
  }
}

TEST(BaseMeshAtlas, MergingLeavesFewerDiscChartsThatNeitherFlipNorOverlap) {
  Mesh plain, merged, again;
  make_bumpy_sphere(plain);
  make_bumpy_sphere(merged);
  make_bumpy_sphere(again);
  BaseMeshAtlasOptions opt;
  opt.margin = 0.03;  // a 2048 px atlas's 32-texel gutter
  const BaseMeshAtlasResult p = compute_base_mesh_atlas(plain, opt);
  opt.merge_charts = true;
  const BaseMeshAtlasResult r = compute_base_mesh_atlas(merged, opt);
  std::cout << "[ atlas ] bumpy sphere: " << p.num_charts << " -> " << r.num_charts << " charts, distortion "
            << p.mean_area_distortion << " -> " << r.mean_area_distortion << ", uv per length "
            << p.uv_per_length << " -> " << r.uv_per_length << "\n";
  EXPECT_GE(p.num_charts, 50);  // the case merging is for
  EXPECT_LT(r.num_charts, p.num_charts / 4);
  EXPECT_GT(r.uv_per_length, p.uv_per_length);  // fewer gaps: more uv per mesh length
  EXPECT_LE(r.mean_area_distortion, std::max(opt.max_merge_distortion, p.mean_area_distortion));
  std::size_t total = 0;
  for (auto n : r.chart_faces) {
    EXPECT_LE(n, opt.max_chart_faces);
    total += n;
  }
  EXPECT_EQ(total, merged.number_of_faces());
  EXPECT_EQ(r.flipped_faces, 0u);
  EXPECT_EQ(test::uv_flipped_faces(merged), 0u);
  EXPECT_EQ(test::uv_overlap_texels(merged, 2048), 0u);
  expect_disc_charts(merged, r.num_charts);
  expect_uvs_in_unit_square_and_consistent(merged);
  expect_disjoint_chart_boxes(merged, r.num_charts);
  // Deterministic: the same input gives the same charts and uvs.
  ASSERT_EQ(compute_base_mesh_atlas(again, opt).num_charts, r.num_charts);
  auto ua = find(merged, kCornerUV).first, ub = find(again, kCornerUV).first;
  for (HalfedgeIndex h : merged.halfedges())
    if (!merged.is_border(h)) {
      ASSERT_EQ(ua[h], ub[h]);
    }
}

namespace {
// The atlas of `name` with `threads` TBB threads: corner uvs and face charts.
std::pair<std::vector<UV>, std::vector<int>> atlas_on_threads(const char* name, bool merge, std::size_t threads) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  Mesh m;
  read_mesh(test::shared_data(name), m);
  BaseMeshAtlasOptions opt;
  opt.merge_charts = merge;
  opt.margin = 0.03;
  compute_base_mesh_atlas(m, opt);
  auto uv = find(m, kCornerUV).first;
  auto patch = find(m, kFacePatch).first;
  std::pair<std::vector<UV>, std::vector<int>> out;
  for (HalfedgeIndex h : m.halfedges()) out.first.push_back(uv[h]);
  for (FaceIndex f : m.faces()) out.second.push_back(patch[f]);
  return out;
}
}  // namespace

// Deterministic parallel stages (decision 210): the charts flattened (and
// split where they fold) in parallel rounds, and the merges' unions
// flattened ahead in parallel, give the same bytes on one and two threads.
// elephant's flattenings fold (FlatteningsNeverFoldOverThemselves), so both
// rounds and splits run; merging is on in the second case.
TEST(BaseMeshAtlas, SameUvOnOneAndTwoThreads) {
  for (bool merge : {false, true}) {
    SCOPED_TRACE(merge ? "merged" : "not merged");
    const auto one = atlas_on_threads("meshes/elephant.off", merge, 1);
    const auto two = atlas_on_threads("meshes/elephant.off", merge, 2);
    EXPECT_TRUE(one.first == two.first);
    EXPECT_TRUE(one.second == two.second);
  }
}

TEST(BaseMeshAtlas, RejectsBadOptions) {
  Mesh m;
  make_grid(m, 2, 2);
  BaseMeshAtlasOptions opt;
  opt.max_normal_angle_deg = 0;
  EXPECT_THROW(compute_base_mesh_atlas(m, opt), InvalidInputError);
  opt = {};
  opt.margin = 0.5;
  EXPECT_THROW(compute_base_mesh_atlas(m, opt), InvalidInputError);
  opt = {};
  opt.max_merge_distortion = 0.9;
  EXPECT_THROW(compute_base_mesh_atlas(m, opt), InvalidInputError);
  Mesh empty;
  EXPECT_THROW(compute_base_mesh_atlas(empty), InvalidInputError);
}
