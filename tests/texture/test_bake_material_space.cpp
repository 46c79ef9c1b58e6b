// SPDX-License-Identifier: AGPL-3.0-or-later
// Material-space mapping baked into a uv atlas (Ray et al. 2009, sections
// 2-3): the atlas rendered as a plain texture matches the singularity-fixed
// render, and every chart keeps its mip gutter; the mapping driver's update
// and state round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "geometry/atlas_gutter.h"
#include "geometry/bake_vertex_colors.h"
#include "geometry/errors.h"
#include "geometry/gltf_vertex_frames.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/rasterizer.h"
#include "geometry/read_mesh.h"
#include "geometry/render_mesh.h"
#include "test_support.h"
#include "texture/material_space/bake_material_space.h"
#include "texture/material_space/material_mapping.h"
#include "texture/pbr_maps.h"
#include "texture/procedural_texture.h"
#include "texture/material_space/render_material_space.h"

namespace surftex {
namespace {

// Two structured 32-texel layers (cells -> noise): the material blend and
// the singular zones both show.
MaterialTile two_layer_tile() {
  MaterialTile t;
  t.size = 32;
  t.layers_per_pair = 1;
  t.layers = {make_cells(32, 3, 7), make_noise(32, 4, 9)};
  t.material = {0.0, 1.0};
  return t;
}

double psnr(const Image& a, const Image& b) {
  double se = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) se += (a.data[i] - b.data[i]) * (a.data[i] - b.data[i]);
  const double mse = se / static_cast<double>(a.data.size());
  return 10 * std::log10(1.0 / std::max(mse, 1e-20));
}

// The fixed render (callback, three lookups) and the baked atlas rendered as
// an ordinary texture at the atlas uv, same camera.
std::pair<Image, Image> renders(Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile, int atlas,
                                MaterialBakeResult* out = nullptr) {
  RenderMesh rm = make_render_mesh(mesh);
  const Camera cam = fit_camera(bounding_box(rm), 30, 20);
  RenderOptions ro;
  ro.width = ro.height = 256;
  ro.color_source = RenderOptions::ColorSource::Callback;
  ro.callback = material_space_fragment(rm, sing, tile, {});
  Image fixed = render(rm, cam, ro).color;
  MaterialBakeOptions bo;
  bo.size = atlas;
  MaterialBakeResult b = bake_material_space(mesh, sing, tile, bo);
  RenderMeshOptions mo;
  mo.corner_uvs = true;
  RenderMesh tm = make_render_mesh(mesh, mo);
  RenderOptions to;
  to.width = to.height = 256;
  to.color_source = RenderOptions::ColorSource::Texture;
  to.texture = &b.color;
  to.wrap = RenderOptions::Wrap::Clamp;
  Image baked = render(tm, cam, to).color;
  if (out) *out = std::move(b);
  return {fixed, baked};
}

TEST(BakeMaterialSpace, AtlasRenderMatchesTheFixedRenderOnRealMeshes) {
  const MaterialTile tile = two_layer_tile();
  for (const char* name : {"meshes/fish_blub.obj", "meshes/eight_genus2.off"}) {
    Mesh mesh;
    read_mesh(test::shared_data(name), mesh);
    MaterialConstraints c;
    c.material = {{0, 0.0}, {static_cast<std::uint32_t>(mesh.number_of_vertices() / 2), 1.0}};
    MaterialMapping mapping(mesh);
    mapping.map(c);
    ASSERT_GT(mapping.result().singularities.singular_faces, 0u) << name;  // the fix is exercised
    MaterialBakeResult b;
    const auto [fixed, baked] = renders(mesh, mapping.result().singularities, tile, 512, &b);
    EXPECT_GE(psnr(fixed, baked), 30.0) << name;
    EXPECT_EQ(b.gutter, 8) << name;  // 512 -> 64 px: 3 halvings
    EXPECT_EQ(b.gutter_violations, 0u) << name;
  }
}

TEST(BakeMaterialSpace, PlainLookupsDoNotMatchTheFixedRender) {
  // The bake carries the fix: baking without it is measurably further from
  // the fixed render than the bake with it.
  Mesh mesh;
  read_mesh(test::shared_data("meshes/fish_blub.obj"), mesh);
  MaterialMapping mapping(mesh);
  mapping.map({});
  const MaterialTile tile = two_layer_tile();
  const auto [fixed, baked] = renders(mesh, mapping.result().singularities, tile, 1024);
  MaterialBakeOptions bo;
  bo.size = 1024;
  bo.fix_singularities = false;
  const MaterialBakeResult plain = bake_material_space(mesh, mapping.result().singularities, tile, bo);
  RenderMeshOptions mo;
  mo.corner_uvs = true;
  RenderMesh tm = make_render_mesh(mesh, mo);
  RenderOptions to;
  to.width = to.height = 256;
  to.color_source = RenderOptions::ColorSource::Texture;
  to.texture = &plain.color;
  to.wrap = RenderOptions::Wrap::Clamp;
  const Image unfixed = render(tm, fit_camera(bounding_box(tm), 30, 20), to).color;
  EXPECT_GT(psnr(fixed, baked), psnr(fixed, unfixed) + 1.0);
}

// Every mip level k = 0..K (down to 64 px): a 2^k block that holds a texel of
// chart c holds only texels owned by c, and no texel is left as background.
// Both meshes keep the full gutter (elephant's merged charts too).
void expect_clean_mips(const char* name, int full_gutter) {
  SCOPED_TRACE(name);
  Mesh mesh;
  read_mesh(test::shared_data(name), mesh);
  MaterialMapping mapping(mesh);
  mapping.map({});
  MaterialBakeOptions bo;
  bo.size = 512;
  const MaterialBakeResult b = bake_material_space(mesh, mapping.result().singularities, two_layer_tile(), bo);
  if (full_gutter > 0) { EXPECT_EQ(b.gutter, full_gutter); }
  EXPECT_EQ(b.gutter * b.protected_mip_size, 512);
  ASSERT_GT(b.charts, 1);
  const int N = 512;
  for (int o : b.owner) ASSERT_GE(o, 0);  // background filled by the dilation
  EXPECT_EQ(gutter_violations(b.chart, b.owner, N, N, b.gutter), 0u);
  for (int k = 0, s = 1; s <= b.gutter; ++k, s *= 2) {
    std::size_t bad = 0;
    for (int by = 0; by < N; by += s)
      for (int bx = 0; bx < N; bx += s) {
        int c = -1;
        for (int y = by; y < by + s; ++y)
          for (int x = bx; x < bx + s; ++x)
            if (b.chart[static_cast<std::size_t>(y) * N + x] >= 0) c = b.chart[static_cast<std::size_t>(y) * N + x];
        if (c < 0) continue;
        for (int y = by; y < by + s; ++y)
          for (int x = bx; x < bx + s; ++x) bad += b.owner[static_cast<std::size_t>(y) * N + x] != c;
      }
    EXPECT_EQ(bad, 0u) << "mip level " << k;
  }
  // No black texel: the background took chart colours.
  std::size_t black = 0;
  for (std::size_t i = 0; i < b.owner.size(); ++i)
    black += b.color.data[3 * i] == 0.f && b.color.data[3 * i + 1] == 0.f && b.color.data[3 * i + 2] == 0.f;
  EXPECT_LT(black, b.owner.size() / 1000);
}

TEST(BakeMaterialSpace, GutterKeepsEveryMipLevelClean) {
  expect_clean_mips("meshes/fish_blub.obj", 8);  // 512 -> 64 px: 3 halvings
  expect_clean_mips("meshes/elephant.off", 8);
}

TEST(BakeMaterialSpace, RefusesBadSizesAndForeignSingularities) {
  Mesh mesh;
  make_torus(mesh, 1.0, 0.4, 24, 12);
  MaterialMapping mapping(mesh);
  mapping.map({});
  MaterialBakeOptions bo;
  bo.size = 32;
  EXPECT_THROW(bake_material_space(mesh, mapping.result().singularities, two_layer_tile(), bo), InvalidInputError);
  Mesh other;
  make_torus(other, 1.0, 0.4, 12, 6);
  EXPECT_THROW(bake_material_space(other, mapping.result().singularities, two_layer_tile(), {}), InvalidInputError);
}

TEST(MaterialMapping, StateRoundTripAndLocalUpdate) {
  Mesh mesh;
  make_torus(mesh, 3.0, 1.0, 40, 16);
  MaterialMapping a(mesh);
  MaterialConstraints c;
  c.material = {{0, 1.0}};
  a.map(c);
  const std::string dir = test::temp_dir("matmap-state");
  a.save_state(dir + "/s.json", false);
  EXPECT_THROW(a.save_state(dir + "/s.json", false), IOError);  // nothing overwritten silently
  auto stm = find(mesh, kCornerSTM).first;
  std::vector<STM> before;
  for (HalfedgeIndex h : mesh.halfedges()) before.push_back(stm[h]);

  Mesh fresh;
  make_torus(fresh, 3.0, 1.0, 40, 16);
  MaterialMapping b(fresh);
  EXPECT_THROW(b.update(c), InvalidInputError);  // before map/load
  b.load_state(dir + "/s.json");
  auto stm2 = find(fresh, kCornerSTM).first;
  std::size_t i = 0;
  for (HalfedgeIndex h : fresh.halfedges())
    if (!fresh.is_border(h)) EXPECT_EQ(stm2[h], before[i++]);
    else ++i;
  MaterialConstraints u;
  u.material = {{5, 0.0}};
  u.seed_vertices = {5};
  u.effect_radius = 1.5;
  const MaterialMappingResult& r = b.update(u);
  EXPECT_EQ(r.mode, "update");
  EXPECT_GT(r.effect_vertices, 0u);
  EXPECT_LT(r.effect_vertices, fresh.number_of_vertices() / 2);
  EXPECT_THROW(b.update({}), InvalidInputError);  // no constraint
  Mesh small;
  make_torus(small, 3.0, 1.0, 20, 8);
  MaterialMapping wrong(small);
  EXPECT_THROW(wrong.load_state(dir + "/s.json"), InvalidInputError);
}

namespace {

// The singularities of a planar grid parameterised by hand: (s, t) = st(x, y)
// at every corner, m = 0; `singular` makes every face take the three-lookup
// path (its three charts equal to its corners).
PgpSingularities grid_parameterization(const Mesh& mesh, std::array<double, 2> (*st)(double, double), bool singular) {
  PgpSingularities s;
  const std::size_t F = mesh.num_faces();
  s.distorted_face.assign(F, 0);
  s.singular_face.assign(F, singular ? 1 : 0);
  s.singular_vertex.assign(mesh.num_vertices(), singular ? 1 : 0);
  s.mismatched_edge.assign(mesh.num_edges(), 0);
  s.corners.resize(F);
  s.charts.resize(F);
  for (FaceIndex f : mesh.faces()) {
    int k = 0;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      const Point3& p = mesh.point(mesh.target(h));
      const auto c = st(p.x(), p.y());
      s.corners[f.idx()][k++] = {c[0], c[1], 0.0};
    }
    for (auto& chart : s.charts[f.idx()]) chart = s.corners[f.idx()];
  }
  return s;
}

// A one-layer 8x8 grey tile whose normal layer holds the unit normal (nx, ny, nz) everywhere.
MaterialTile tile_with_normal(double nx, double ny, double nz) {
  MaterialTile t;
  t.size = 8;
  t.layers = {Image(8, 8, 3, 0.5f)};
  t.material = {0.0};
  Image n(8, 8, 3);
  for (int i = 0; i < 64; ++i)
    n.data[3 * i] = static_cast<float>(0.5 + 0.5 * nx), n.data[3 * i + 1] = static_cast<float>(0.5 + 0.5 * ny),
    n.data[3 * i + 2] = static_cast<float>(0.5 + 0.5 * nz);
  t.normal_layers = {n};
  return t;
}

}  // namespace

// A tile normal is tangent-space in the tile's (s, t) frame (+x = +s, +y = up
// in the tile image = -t): on a plane, a constant tile normal tilted towards
// +s points along the world direction of increasing s, one tilted up along
// decreasing t, whatever the parameterisation's orientation, with one lookup
// or three.
TEST(BakeMaterialSpace, TileNormalsTurnAlongTheParameterization) {
  Mesh mesh;
  make_grid(mesh, 4, 4, 1.0, 1.0);  // z = 0, normal +z
  const double a = 0.5, sa = std::sin(a), ca = std::cos(a);
  struct Case {
    std::array<double, 2> (*st)(double, double);
    std::array<double, 3> towards_s, up;  // world directions of +s and of -t
  };
  const Case cases[] = {
      {[](double x, double y) { return std::array<double, 2>{2 * x, 2 * y}; }, {1, 0, 0}, {0, -1, 0}},
      {[](double x, double y) { return std::array<double, 2>{2 * y, -2 * x}; }, {0, 1, 0}, {1, 0, 0}},
      {[](double x, double y) { return std::array<double, 2>{x + y, x - y}; }, {M_SQRT1_2, M_SQRT1_2, 0},
       {-M_SQRT1_2, M_SQRT1_2, 0}}};
  for (const Case& c : cases)
    for (bool singular : {false, true})
      for (int dir = 0; dir < 2; ++dir) {
        const PgpSingularities sing = grid_parameterization(mesh, c.st, singular);
        const MaterialTile tile = dir == 0 ? tile_with_normal(sa, 0, ca) : tile_with_normal(0, sa, ca);
        MaterialBakeOptions bo;
        bo.size = 64;
        const MaterialBakeResult r = bake_material_space(mesh, sing, tile, bo);
        ASSERT_EQ(r.object_normal.channels, 3);
        const auto& d = dir == 0 ? c.towards_s : c.up;
        const std::array<double, 3> want{sa * d[0], sa * d[1], ca};
        std::size_t texels = 0;
        for (std::size_t i = 0; i < r.chart.size(); ++i) {
          if (r.chart[i] < 0) continue;
          ++texels;
          for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(r.object_normal.data[3 * i + k], want[k], 1e-4) << "texel " << i << " singular " << singular;
        }
        EXPECT_GT(texels, 64u * 64 / 8);
        EXPECT_TRUE(r.roughness.empty());
        EXPECT_FALSE(r.height_from_tile);
      }
}

// The tile normal reaches a glTF viewer: the tangent-space map, read in the
// frames the viewer rebuilds from the GLB (NORMAL and TANGENT of the glTF
// vertices interpolated per texel, B = cross(N, T) w), gives back on a plane
// the world direction of increasing s for a tile normal tilted towards +s.
TEST(BakeMaterialSpace, TileNormalsReachTheGlbTangentSpace) {
  Mesh mesh;
  make_grid(mesh, 4, 4, 1.0, 1.0);
  const double a = 0.5;
  const MaterialTile tile = tile_with_normal(std::sin(a), 0, std::cos(a));
  // s along world +y, t along world -x.
  const PgpSingularities sing =
      grid_parameterization(mesh, [](double x, double y) { return std::array<double, 2>{2 * y, -2 * x}; }, false);
  MaterialBakeOptions bo;
  bo.size = 64;
  const MaterialBakeResult r = bake_material_space(mesh, sing, tile, bo);
  const Image ts = material_space_tangent_normals(mesh, r);
  ASSERT_EQ(ts.width, 64);
  const GltfVertexFrames fr = gltf_vertex_frames(mesh);
  const AtlasTexels at = rasterize_atlas(mesh, 64);
  std::size_t texels = 0;
  for (std::size_t i = 0; i < at.raster.triangle.size(); ++i) {
    const int t = at.raster.triangle[i];
    if (t < 0 || r.chart[i] < 0) continue;
    std::array<double, 3> N{0, 0, 0}, T{0, 0, 0};
    double w = 0;
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t g = fr.corner[at.corner[t][c]];
      for (int k = 0; k < 3; ++k) {
        N[k] += at.raster.bary[i][c] * fr.normal[g][k];
        T[k] += at.raster.bary[i][c] * fr.tangent[g][k];
      }
      w += at.raster.bary[i][c] * fr.tangent[g][3];
    }
    const double ln = std::sqrt(N[0] * N[0] + N[1] * N[1] + N[2] * N[2]);
    for (double& v : N) v /= ln;
    const double tn = T[0] * N[0] + T[1] * N[1] + T[2] * N[2];
    for (int k = 0; k < 3; ++k) T[k] -= tn * N[k];
    const double lt = std::sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2]);
    for (double& v : T) v /= lt;
    const double sw = w < 0 ? -1 : 1;
    const std::array<double, 3> B{sw * (N[1] * T[2] - N[2] * T[1]), sw * (N[2] * T[0] - N[0] * T[2]),
                                  sw * (N[0] * T[1] - N[1] * T[0])};
    const double x = 2.0 * ts.data[3 * i] - 1, y = 2.0 * ts.data[3 * i + 1] - 1, z = 2.0 * ts.data[3 * i + 2] - 1;
    const std::array<double, 3> world{x * T[0] + y * B[0] + z * N[0], x * T[1] + y * B[1] + z * N[1],
                                      x * T[2] + y * B[2] + z * N[2]};
    ASSERT_NEAR(world[0], 0.0, 1e-3) << "texel " << i;
    ASSERT_NEAR(world[1], std::sin(a), 1e-3) << "texel " << i;
    ASSERT_NEAR(world[2], std::cos(a), 1e-3) << "texel " << i;
    ++texels;
  }
  EXPECT_GT(texels, 64u * 64 / 8);
}

TEST(PbrMaps, NormalFromHeightTiltsAgainstTheSlope) {
  // A height ramp rising along +u (x) tilts the normal towards -u; one rising
  // along +v (upwards in the image, rows decreasing) towards -v; flat = +z.
  Image h(8, 8, 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) h.at(x, y) = 0.1f * x;
  Image n = normal_map_from_height(h, {}, 2.0);
  EXPECT_LT(n.at(4, 4, 0), 0.5f - 0.05f);
  EXPECT_NEAR(n.at(4, 4, 1), 0.5f, 1e-6);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) h.at(x, y) = 0.1f * (7 - y);
  n = normal_map_from_height(h, {}, 2.0);
  EXPECT_NEAR(n.at(4, 4, 0), 0.5f, 1e-6);
  EXPECT_LT(n.at(4, 4, 1), 0.5f - 0.05f);
  // Across a chart border there is no slope: two flat charts of different height.
  std::vector<int> owner(64);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) h.at(x, y) = x < 4 ? 0.f : 1.f, owner[y * 8 + x] = x < 4 ? 0 : 1;
  n = normal_map_from_height(h, owner, 2.0);
  for (float v : n.data) EXPECT_TRUE(std::abs(v - 0.5f) < 1e-6 || std::abs(v - 1.f) < 1e-6);
  EXPECT_THROW(normal_map_from_height(h, owner, -1), InvalidInputError);
}

}  // namespace
}  // namespace surftex
