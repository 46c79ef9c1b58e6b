// SPDX-License-Identifier: AGPL-3.0-or-later
// The exported asset of a subdivision synthesis: the vertex colours baked on
// a triangle copy with its atlas, the maps' sources, the report's keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "geometry/bake_vertex_colors.h"
#include "geometry/gutter_atlas.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "texture/procedural_texture.h"
#include "texture/subdivision/subdivision_asset.h"
#include "texture/subdivision/subdivision_synthesis.h"

namespace surftex {
namespace {

// A unit cube of six quads, each vertex coloured by its position.
Mesh coloured_quad_cube() {
  Mesh m;
  std::vector<VertexIndex> v;
  for (int i = 0; i < 8; ++i) v.push_back(m.add_vertex(Point3(i & 1, (i >> 1) & 1, (i >> 2) & 1)));
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : q) EXPECT_NE(m.add_face(v[f[0]], v[f[1]], v[f[2]], v[f[3]]), Mesh::null_face());
  auto col = get_or_add(m, kVertexColor);
  for (VertexIndex x : m.vertices())
    col[x] = Color3f{float(m.point(x).x()), float(m.point(x).y()), float(m.point(x).z())};
  return m;
}

TEST(SubdivisionAsset, BakesTheColoursOnATriangleCopy) {
  const Mesh m = coloured_quad_cube();
  SubdivisionAssetOptions o;
  o.atlas_size = 64;
  o.texels_per_length = 32;
  const SubdivisionAsset a = bake_subdivision_asset(m, {}, o);
  ASSERT_TRUE(a.mesh);
  const Mesh& t = *a.mesh;
  EXPECT_TRUE(t.is_valid(false));
  EXPECT_EQ(t.number_of_faces(), 12u);
  EXPECT_EQ(t.number_of_vertices(), 8u);
  auto tc = find(t, kVertexColor);
  ASSERT_TRUE(tc.second);
  auto mc = find(m, kVertexColor).first;
  for (VertexIndex v : t.vertices()) EXPECT_EQ(tc.first[v], mc[v]);
  EXPECT_TRUE(find(t, kCornerUV).second) << "the atlas's uvs are on the copy";
  EXPECT_EQ(a.color.image.width, 64);
  EXPECT_EQ(a.height.width, 64);
  EXPECT_EQ(a.normal.width, 64);
  EXPECT_EQ(a.height.channels, 1);
  EXPECT_TRUE(a.metallic_roughness.empty());
  EXPECT_GT(a.color.covered, 64u * 64u / 4);
  EXPECT_FALSE(a.seam_measured);
  // The atlas texel density against the exemplar's: atlas texels per mesh
  // unit over exemplar texels per mesh unit.
  EXPECT_NEAR(a.atlas_texels_per_exemplar_texel, a.atlas.atlas.uv_per_length * 64 / 32.0, 1e-12);
}

// With the sources given, the atlas holds the exemplar read between the
// vertices (SurfaceExemplarSource), the grey height map too, at every texel a
// triangle covers; without them, the blend of the vertex colours.
TEST(SubdivisionAsset, BakesTheExemplarBetweenTheVerticesWhenGivenTheSources) {
  Mesh m;
  make_grid(m, 6, 6);
  SubdivisionSynthesisOptions so;
  so.r_scale = 40;
  so.levels = 2;
  so.keys = {{0, {1, 0, 0}}};
  const Image ex = make_cells(32, 3, 5);
  const SubdivisionSynthesisResult r = synthesize_on_subdivision(m, ex, so);
  Image grey(32, 32, 1);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) grey.at(x, y) = ex.at(x, y, 1);
  SubdivisionExemplarMaps maps;
  maps.height = grey;
  SubdivisionVertexMaps vm = exemplar_maps_at_vertices(m, r, maps, 32, 32);
  SubdivisionAssetOptions o;
  o.atlas_size = 256;
  o.texels_per_length = 40;
  const SubdivisionAsset blended = bake_subdivision_asset(m, vm, o);
  vm.between = subdivision_surface_sources(m, r, maps, 32, 32);
  ASSERT_TRUE(vm.between.color && vm.between.height && !vm.between.roughness);
  const SubdivisionAsset a = bake_subdivision_asset(m, vm, o);
  EXPECT_TRUE(a.color_between_vertices);
  EXPECT_FALSE(blended.color_between_vertices);
  EXPECT_EQ(to_json(a)["color_source"], "exemplar_between_vertices");
  const Mesh& t = *a.mesh;
  ASSERT_EQ(t.number_of_vertices(), m.number_of_vertices());  // a triangle mesh's copy keeps the vertices
  const AtlasTexels at = rasterize_atlas(t, 256);
  std::size_t texels = 0;
  double off = 0;
  for (std::size_t i = 0; i < at.chart.size(); ++i) {
    const int tri = at.raster.triangle[i];
    if (tri < 0) continue;
    std::array<std::size_t, 3> v;
    for (int k = 0; k < 3; ++k) v[k] = t.target(HalfedgeIndex(static_cast<Mesh::size_type>(at.corner[tri][k]))).idx();
    const auto& b = at.raster.bary[i];
    const auto want = (*vm.between.color)(v, {b[0], b[1], b[2]});
    const auto h = (*vm.between.height)(v, {b[0], b[1], b[2]});
    for (int c = 0; c < 3; ++c) {
      ASSERT_FLOAT_EQ(a.color.image.data[3 * i + c], want[c]) << i;
      off += std::abs(blended.color.image.data[3 * i + c] - want[c]);
    }
    ASSERT_NEAR(a.height.data[i], std::clamp(0.2126f * h[0] + 0.7152f * h[1] + 0.0722f * h[2], 0.f, 1.f), 1e-6);
    ++texels;
  }
  ASSERT_GT(texels, 256u * 256u / 10);
  EXPECT_GT(off / (3.0 * texels), 0.02) << "the vertex blend is not the exemplar between the vertices";
  EXPECT_EQ(a.color_stack_level, 0);
  // An atlas sparser than the exemplar's texels (120 per unit) reads a
  // prefiltered level: round(log2(map texels per atlas texel)).
  Mesh fine;
  make_grid(fine, 6, 6);
  so.r_scale = 120;
  const SubdivisionSynthesisResult rf = synthesize_on_subdivision(fine, ex, so);
  SubdivisionVertexMaps fm;
  fm.between = subdivision_surface_sources(fine, rf, {}, 32, 32, &ex);
  SubdivisionAssetOptions sparse = o;
  sparse.atlas_size = 64;
  sparse.texels_per_length = 120;
  sparse.texel_size = rf.scale.texel_size;
  const SubdivisionAsset s = bake_subdivision_asset(fine, fm, sparse);
  const double d = s.atlas.atlas.uv_per_length * 64 * rf.scale.texel_size;  // atlas texels per exemplar texel
  ASSERT_LT(d, 0.7);
  EXPECT_EQ(s.color_stack_level, std::lround(std::log2(1.0 / d)));
  EXPECT_GE(s.color_stack_level, 1);
  EXPECT_EQ(to_json(s)["color_stack_level"], s.color_stack_level);
  const Image other(16, 16, 3);
  EXPECT_THROW(subdivision_surface_sources(m, r, maps, 32, 32, &other), InvalidInputError) << "not the exemplar's size";
}

TEST(SubdivisionAsset, MapsFromVertexValues) {
  const Mesh m = coloured_quad_cube();
  SubdivisionVertexMaps maps;
  maps.height.assign(8, 0.25f);
  maps.roughness.assign(8, 0.75f);
  SubdivisionAssetOptions o;
  o.atlas_size = 64;
  o.texel_size = 0.05;
  const SubdivisionAsset a = bake_subdivision_asset(m, maps, o);
  EXPECT_TRUE(a.height_from_exemplar);
  EXPECT_FALSE(a.normal_from_exemplar);
  ASSERT_FALSE(a.metallic_roughness.empty());
  // The height is the baked vertex value wherever a chart covers the texel.
  int covered = 0;
  for (int i = 0; i < 64 * 64; ++i)
    if (a.color.chart[i] >= 0) {
      ++covered;
      EXPECT_NEAR(a.height.data[i], 0.25f, 1e-5f);
    }
  EXPECT_GT(covered, 0);
  EXPECT_TRUE(a.seam_measured);
  const nlohmann::json j = to_json(a);
  EXPECT_EQ(j["height_source"], "exemplar_height");
  EXPECT_EQ(j["normal_source"], "height");
  EXPECT_EQ(j["roughness"], true);
  EXPECT_TRUE(j.contains("seam"));
}

// The keys the subdiv report's "export.atlas" block carries.
// Decision 208: a default-budget hierarchy (hundreds of thousands of
// faces) cut into charts of the other atlases' 4000 faces loses its texel
// density to the gutters; the asset's larger default chart cap keeps more
// texels per mesh length (measured here on an 80K-face sphere).
TEST(SubdivisionAsset, DefaultChartCapKeepsMoreTexelsOnAFineMeshThanTheGeneralOne) {
  auto density = [](std::size_t cap, int& charts) {
    Mesh m;
    make_icosphere(m, 6);
    const GutterAtlas g = compute_gutter_atlas(m, 1024, 64, cap);
    charts = g.atlas.num_charts;
    return g.atlas.uv_per_length;
  };
  int n_general = 0, n_asset = 0;
  const double general = density(4000, n_general);
  const double asset = density(SubdivisionAssetOptions{}.max_chart_faces, n_asset);
  std::cout << "[ 80K sphere ] charts " << n_general << " -> " << n_asset << ", atlas uv per length " << general
            << " -> " << asset << "\n";
  EXPECT_LT(n_asset, n_general);
  EXPECT_GT(asset, 1.05 * general);
}

// The CLI's default atlas side follows the synthesised vertices: at the 15%
// coverage the mip-safe gutters leave, 1024 px held 0.45 atlas texels per
// synthesis texel on the cow's 195K vertices, 2048 px 0.93 (decision 209).
TEST(SubdivisionAsset, DefaultAtlasSizeHoldsATexelPerVertex) {
  EXPECT_EQ(default_subdivision_atlas_size(0), 1024);
  EXPECT_EQ(default_subdivision_atlas_size(40962), 1024);
  EXPECT_EQ(default_subdivision_atlas_size(157000), 1024);
  EXPECT_EQ(default_subdivision_atlas_size(194978), 2048);
  EXPECT_EQ(default_subdivision_atlas_size(SubdivisionSynthesisOptions{}.max_vertices), 2048);
  EXPECT_EQ(default_subdivision_atlas_size(700000), 4096);
  EXPECT_EQ(default_subdivision_atlas_size(50000000), 4096);
  for (std::size_t v : {1000u, 100000u, 300000u, 2000000u}) {
    const int n = default_subdivision_atlas_size(v);
    EXPECT_TRUE(n == 4096 || 0.15 * n * n >= static_cast<double>(v)) << v;
    EXPECT_TRUE(n == 1024 || 0.15 * (n / 2) * (n / 2) < static_cast<double>(v)) << v << ": not the smallest";
  }
}

TEST(SubdivisionAsset, JsonHasTheReportKeys) {
  const Mesh m = coloured_quad_cube();
  SubdivisionAssetOptions o;
  o.atlas_size = 64;
  o.bump = 3;
  const nlohmann::json j = to_json(bake_subdivision_asset(m, {}, o));
  for (const char* k : {"charts", "size", "coverage", "gutter", "gutter_violations", "margin", "protected_mip_size",
                        "mean_area_distortion", "flipped_faces", "bump", "atlas_texels_per_exemplar_texel",
                        "normal_source", "height_source", "roughness", "seconds"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_FALSE(j.contains("seam")) << "no texel size, no seam figure";
  EXPECT_EQ(j["size"], 64);
  EXPECT_EQ(j["bump"], 3.0);
  EXPECT_EQ(j["height_source"], "luminance");
  EXPECT_EQ(j["roughness"], false);
  EXPECT_TRUE(j["seconds"].contains("bake"));
  EXPECT_GT(j["coverage"].get<double>(), 0.0);
}

}  // namespace
}  // namespace surftex
