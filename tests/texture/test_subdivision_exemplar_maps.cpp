// SPDX-License-Identifier: AGPL-3.0-or-later
// Exemplar maps through the subdivision synthesis (texture/
// subdivision_exemplar_maps.h) and the tangent-space bake (texture/
// tangent_space_bake.h), issue 16 item 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "geometry/bake_vertex_colors.h"
#include "geometry/errors.h"
#include "geometry/gltf_vertex_frames.h"
#include "geometry/gutter_atlas.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "texture/procedural_texture.h"
#include "texture/subdivision/k_region_matching.h"
#include "texture/subdivision/subdivision_exemplar_maps.h"
#include "texture/subdivision/subdivision_synthesis.h"
#include "texture/tangent_space_bake.h"

using namespace surftex;

namespace {
using D3 = std::array<double, 3>;
double dot(const D3& a, const D3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
D3 unit(const D3& a) {
  const double l = std::sqrt(dot(a, a));
  return {a[0] / l, a[1] / l, a[2] / l};
}
// An 8 x 8 unit grid (normal +z) with the field along +x, 40 texels per unit,
// two sqrt(2) levels: about 2.5 texels per edge.
SubdivisionSynthesisResult synthesize_on_flat_grid(Mesh& m, const Image& ex) {
  make_grid(m, 8, 8);
  SubdivisionSynthesisOptions o;
  o.r_scale = 40;
  o.levels = 2;
  o.keys = {{0, {1, 0, 0}}};
  o.seed = 4;
  return synthesize_on_subdivision(m, ex, o);
}
}  // namespace

// "One synthesis, every channel": the exemplar read as a map at the vertices
// gives back their colours, also when the exemplar was reduced for the vertex
// budget; a grey map (1 - red) follows the same lookups.
TEST(SubdivisionExemplarMaps, LookupsReadBackTheColoursAlsoFromAReducedExemplar) {
  const Image ex = make_cells(64, 4, 7);
  Image grey(64, 64, 1);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) grey.at(x, y) = 1.f - ex.at(x, y, 0);
  for (int reduced = 0; reduced < 2; ++reduced) {
    Mesh m;
    make_icosphere(m, 1);
    SubdivisionSynthesisOptions o;
    if (reduced) {
      o.repeats = 4;
      o.max_vertices = 1000;  // the budget coarsens the texel: the exemplar is reduced
    } else {
      o.r_scale = 30;
      o.levels = 3;
    }
    o.seed = 2;
    const SubdivisionSynthesisResult r = synthesize_on_subdivision(m, ex, o);
    ASSERT_EQ(r.scale.exemplar_scale < 1.0, reduced == 1);
    const VertexMapValues c = read_map_at_vertices(m, r, ex, 64, 64);
    const VertexMapValues g = read_map_at_vertices(m, r, grey, 64, 64);
    ASSERT_EQ(c.channels, 3);
    ASSERT_EQ(g.channels, 1);
    auto col = find(m, kVertexColor).first;
    std::size_t read = 0;
    for (VertexIndex v : m.vertices()) {
      if (r.lookup[v.idx()].level < 0) continue;
      ++read;
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(c.values[3 * v.idx() + k], col[v][k], 1e-5) << v.idx();
      ASSERT_NEAR(g.values[v.idx()], 1.f - col[v][0], 1e-5);
    }
    EXPECT_EQ(read + c.filled, m.number_of_vertices());
    EXPECT_LT(c.filled, m.number_of_vertices() / 100);
  }
  Mesh m;
  make_icosphere(m, 0);
  SubdivisionSynthesisOptions o;
  o.levels = 0;
  const auto r = synthesize_on_subdivision(m, ex, o);
  EXPECT_THROW(read_map_at_vertices(m, r, Image(32, 64, 1), 64, 64), InvalidInputError);
}

// Handedness: on a flat grid (normal +z) with the field along +x, the
// exemplar's columns advance along +x and its rows DOWN along n x d = +y
// (image up = +y), at r texels per unit: along most edges the lookups differ
// by exactly that (graph-cut seams excepted), and a mirrored y fits almost none.
// So a tangent-space (x, y, z) lies on the surface as x d + y (n x d) + z n.
TEST(SubdivisionExemplarMaps, ExemplarXFollowsTheFieldAndImageUpIsNormalCrossField) {
  const Image ex = make_cells(32, 3, 5);
  Mesh m;
  const SubdivisionSynthesisResult r = synthesize_on_flat_grid(m, ex);
  const double texels = 1.0 / r.scale.texel_size;  // per mesh unit
  const int W = r.exemplar.width, H = r.exemplar.height;
  auto wrap = [](double d, int n) { return d - n * std::round(d / n); };
  std::size_t edges = 0, fit = 0, mirrored = 0;
  for (EdgeIndex e : m.edges()) {
    const VertexIndex a = m.vertex(e, 0), b = m.vertex(e, 1);
    const ExemplarLookup &la = r.lookup[a.idx()], &lb = r.lookup[b.idx()];
    if (la.level < 0 || lb.level < 0) continue;
    const auto d = m.point(b) - m.point(a);
    const double dx = wrap(lb.x - la.x, W), dy = wrap(lb.y - la.y, H);
    ++edges;
    fit += std::abs(dx - texels * d.x()) < 0.5 && std::abs(dy + texels * d.y()) < 0.5;
    mirrored += std::abs(dx - texels * d.x()) < 0.5 && std::abs(dy - texels * d.y()) < 0.5 && std::abs(d.y()) > 1e-9;
  }
  EXPECT_GT(fit, edges * 6 / 10);
  EXPECT_LT(mirrored, edges / 10);
  // A map tilted by 45 degrees towards the exemplar's +x and +y together.
  VertexMapValues n;
  n.channels = 3;
  for (std::size_t i = 0; i < m.number_of_vertices(); ++i)
    n.values.insert(n.values.end(), {0.75f, 0.75f, float(0.5 + 0.5 * std::sqrt(0.5))});
  const auto on = object_normals_from_map(m, n);
  for (VertexIndex v : m.vertices()) {
    EXPECT_NEAR(on[v.idx()][0], 0.5, 1e-3);
    EXPECT_NEAR(on[v.idx()][1], 0.5, 1e-3);
    EXPECT_NEAR(on[v.idx()][2], std::sqrt(0.5), 1e-3);
  }
}

// Issue 18: between the vertices the surface carries the exemplar itself.
// On a flat grid with the field along +x, a face whose three corners were
// copied by one transfer (their lookups differ exactly by their offsets) reads,
// at its centroid, the exemplar's level 0 at the carried position: not the
// blend of the three vertex colours, which on 2.5-texel edges of a sharp
// exemplar is far from it.
TEST(SubdivisionExemplarMaps, SourceReadsTheExemplarBetweenVerticesCopiedTogether) {
  const Image ex = make_cells(32, 3, 5);
  Mesh m;
  const SubdivisionSynthesisResult r = synthesize_on_flat_grid(m, ex);
  const double texels = 1.0 / r.scale.texel_size;
  auto col = find(m, kVertexColor).first;
  std::vector<std::array<float, 3>> fallback(m.number_of_vertices());
  for (VertexIndex v : m.vertices()) fallback[v.idx()] = {col[v][0], col[v][1], col[v][2]};
  const SurfaceExemplarSource src(m, r, r.exemplar, fallback);
  const ExemplarLevels level0 = make_exemplar_levels(r.exemplar, false, 1, std::min(r.bounded_levels, 1));
  std::size_t together = 0;
  double blend_error = 0;
  for (FaceIndex f : m.faces()) {
    std::array<std::size_t, 3> v;
    int k = 0;
    for (VertexIndex w : m.vertices_around_face(m.halfedge(f))) v[k++] = w.idx();
    const auto p = [&](int i) { return m.point(VertexIndex(static_cast<Mesh::size_type>(v[i]))); };
    const ExemplarLookup& l0 = r.lookup[v[0]];
    bool same = l0.level >= 0;
    for (int i = 1; i < 3 && same; ++i) {
      const ExemplarLookup& li = r.lookup[v[i]];
      const auto d = p(i) - p(0);
      same = li.level >= 0 && std::abs(li.x - l0.x - texels * d.x()) < 1e-6 && std::abs(li.y - l0.y + texels * d.y()) < 1e-6;
    }
    if (!same) continue;
    ++together;
    const auto c = ((p(1) - p(0)) + (p(2) - p(0))) / 3.0;
    const auto want = texel_bilinear(level0, 0, l0.x + texels * c.x(), l0.y - texels * c.y());
    const auto got = src(v, {1.0 / 3, 1.0 / 3, 1.0 / 3});
    for (int j = 0; j < 3; ++j) {
      ASSERT_NEAR(got[j], want[j], 1e-4) << "face " << f.idx();
      blend_error += std::abs((fallback[v[0]][j] + fallback[v[1]][j] + fallback[v[2]][j]) / 3 - want[j]);
    }
  }
  ASSERT_GT(together, m.number_of_faces() / 3);
  EXPECT_GT(blend_error / (3.0 * together), 0.02) << "the vertex blend would have passed as well";
  // A corner without a lookup gives its fallback value.
  SubdivisionSynthesisResult none = r;
  for (auto& l : none.lookup) l.level = -1;
  const SurfaceExemplarSource fb(m, none, r.exemplar, fallback);
  const auto at0 = fb({0, 1, 2}, {1, 0, 0});
  for (int j = 0; j < 3; ++j) EXPECT_FLOAT_EQ(at0[j], fallback[0][j]);
  fallback.pop_back();
  EXPECT_THROW(SurfaceExemplarSource(m, r, r.exemplar, fallback), InvalidInputError);
}

// Where the vertex budget reduced the exemplar, the source reads the exemplar
// as given at its own resolution: at a vertex, the lookup scaled to it (pixel
// centres onto pixel centres), at any stack level built; reading the reduced
// exemplar there gives other values (its detail is gone).
TEST(SubdivisionExemplarMaps, SourceReadsTheInputAtItsOwnResolutionWhenTheSynthesisReducedIt) {
  const Image ex = make_cells(64, 8, 3);
  Mesh m;
  make_icosphere(m, 1);
  SubdivisionSynthesisOptions o;
  o.repeats = 4;
  o.max_vertices = 1000;
  o.seed = 2;
  const SubdivisionSynthesisResult r = synthesize_on_subdivision(m, ex, o);
  ASSERT_LT(r.scale.exemplar_scale, 1.0);
  std::vector<std::array<float, 3>> fallback(m.number_of_vertices(), {0.f, 0.f, 0.f});
  ExemplarReadOptions read;
  read.scale_x = 64.0 / r.exemplar.width;
  read.scale_y = 64.0 / r.exemplar.height;
  read.levels = 3;
  const SurfaceExemplarSource src(m, r, ex, fallback, read);
  const SurfaceExemplarSource reduced(m, r, r.exemplar, fallback);
  EXPECT_EQ(src.levels(), 3);
  EXPECT_EQ(src.at_level(7).level(), 2);
  const ExemplarLevels stack = make_exemplar_levels(ex, false, 3, r.bounded_levels > 0 ? 3 : 0);
  std::size_t read_at = 0;
  double differs = 0;
  for (VertexIndex v : m.vertices()) {
    const ExemplarLookup& l = r.lookup[v.idx()];
    if (l.level < 0) continue;
    ++read_at;
    const std::array<std::size_t, 3> c{v.idx(), v.idx(), v.idx()};
    const double x = (l.x + 0.5) * read.scale_x - 0.5, y = (l.y + 0.5) * read.scale_y - 0.5;
    for (int lv : {0, 2}) {
      const auto got = src.at_level(lv)(c, {1, 0, 0});
      const auto want = texel_bilinear(stack, lv, x, y);
      for (int j = 0; j < 3; ++j) ASSERT_NEAR(got[j], want[j], 1e-5) << v.idx();
    }
    const auto full = src(c, {1, 0, 0}), small = reduced(c, {1, 0, 0});
    for (int j = 0; j < 3; ++j) differs += std::abs(full[j] - small[j]);
  }
  ASSERT_GT(read_at, m.number_of_vertices() / 2);
  EXPECT_GT(differs / (3.0 * read_at), 0.01);
  read.scale_x = 0;
  EXPECT_THROW(SurfaceExemplarSource(m, r, ex, fallback, read), InvalidInputError);
}

// A copy matched coherently continues its neighbour's copy to the sub-texel
// (not at the rounded integer match): on a flat grid with a 5-texel checker
// and 2.3-texel edges, the lookups of most edges differ by exactly the edge's
// offset in texels, up to whole periods of the checker (the rest: edges
// across copies matched afresh). Matching at integer positions leaves every edge
// across two copies off by the rounding (up to half a texel), which moves a
// fine periodic pattern's phase from copy to copy.
TEST(SubdivisionExemplarMaps, CoherentCopiesContinueTheirNeighboursToTheSubTexel) {
  const Image ex = make_checker(40, 8);
  Mesh m;
  make_grid(m, 8, 8);
  SubdivisionSynthesisOptions o;
  o.r_scale = 37;
  o.levels = 2;
  o.keys = {{0, {1, 0, 0}}};
  o.wrap = ExemplarWrap::Periodic;
  o.seed = 3;
  const SubdivisionSynthesisResult r = synthesize_on_subdivision(m, ex, o);
  const double texels = 1.0 / r.scale.texel_size;
  constexpr int kPeriod = 10;  // two 5-texel cells: lookups this far apart read the same colour
  auto wrap = [](double d, int n) { return d - n * std::round(d / n); };
  std::size_t edges = 0, exact = 0;
  for (EdgeIndex e : m.edges()) {
    const VertexIndex a = m.vertex(e, 0), b = m.vertex(e, 1);
    const ExemplarLookup &la = r.lookup[a.idx()], &lb = r.lookup[b.idx()];
    if (la.level < 0 || lb.level < 0) continue;
    const auto d = m.point(b) - m.point(a);
    ++edges;
    exact += std::abs(wrap(lb.x - la.x - texels * d.x(), kPeriod)) < 0.02 &&
             std::abs(wrap(lb.y - la.y + texels * d.y(), kPeriod)) < 0.02;
  }
  std::cout << exact << " of " << edges << " edges continue the checker's phase exactly\n";
  ASSERT_GT(edges, m.number_of_edges() * 9 / 10);
  EXPECT_GT(exact, edges * 8 / 10);  // 89% (integer matches: 70%)
}

// The baked tangent-space map, decoded through the frames the GLB carries
// (the blend of its NORMAL and TANGENT per texel), gives back the blended
// object-space normals, on a curved mesh with chart seams.
TEST(TangentSpaceBake, DecodesToTheObjectNormalsThroughTheGlbFrames) {
  Mesh m;
  make_icosphere(m, 2);
  compute_gutter_atlas(m, 128);
  std::vector<std::array<float, 3>> on(m.num_vertices());
  for (VertexIndex v : m.vertices()) {  // tilted off the radial normal towards +z
    const auto p = m.point(v);
    const D3 n = unit({p.x() + 0.3, p.y() - 0.2, p.z() + 0.6});
    on[v.idx()] = {float(n[0]), float(n[1]), float(n[2])};
  }
  const Image img = tangent_space_normal_map(m, on, 128);
  const AtlasTexels at = rasterize_atlas(m, 128);
  const GltfVertexFrames fr = gltf_vertex_frames(m);
  std::size_t texels = 0, close = 0;
  for (std::size_t i = 0; i < at.chart.size(); ++i) {
    const int t = at.raster.triangle[i];
    if (t < 0) continue;
    D3 want{0, 0, 0}, N{0, 0, 0}, T{0, 0, 0};
    double w = 0;
    for (int c = 0; c < 3; ++c) {
      const double b = at.raster.bary[i][c];
      const std::size_t h = at.corner[t][c];
      const std::size_t v = m.target(HalfedgeIndex(static_cast<Mesh::size_type>(h))).idx();
      for (int k = 0; k < 3; ++k) {
        want[k] += b * on[v][k];
        N[k] += b * fr.normal[fr.corner[h]][k];
        T[k] += b * fr.tangent[fr.corner[h]][k];
      }
      w += b * fr.tangent[fr.corner[h]][3];
    }
    N = unit(N);
    const double tn = dot(T, N);
    T = unit({T[0] - tn * N[0], T[1] - tn * N[1], T[2] - tn * N[2]});
    const double s = w < 0 ? -1 : 1;
    const D3 B{s * (N[1] * T[2] - N[2] * T[1]), s * (N[2] * T[0] - N[0] * T[2]), s * (N[0] * T[1] - N[1] * T[0])};
    D3 ts;
    for (int k = 0; k < 3; ++k) ts[k] = 2.0 * img.data[3 * i + k] - 1.0;
    const D3 got = unit({ts[0] * T[0] + ts[1] * B[0] + ts[2] * N[0], ts[0] * T[1] + ts[1] * B[1] + ts[2] * N[1],
                         ts[0] * T[2] + ts[1] * B[2] + ts[2] * N[2]});
    ++texels;
    close += dot(got, unit(want)) > std::cos(0.5 * M_PI / 180);
  }
  EXPECT_GT(texels, 1000u);
  EXPECT_EQ(close, texels);
  // gutters filled (no texel left at 0)
  std::size_t zero = 0;
  for (std::size_t i = 0; i < at.chart.size(); ++i) zero += img.data[3 * i + 2] == 0.f;
  EXPECT_EQ(zero, 0u);
  EXPECT_THROW(tangent_space_normal_map(m, {}, 128), InvalidInputError);
}
