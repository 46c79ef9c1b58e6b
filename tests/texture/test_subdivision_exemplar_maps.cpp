// SPDX-License-Identifier: AGPL-3.0-or-later
// Exemplar maps through the subdivision synthesis (texture/
// subdivision_exemplar_maps.h) and the tangent-space bake (texture/
// tangent_space_bake.h), issue 16 item 2.
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/bake_vertex_colors.h"
#include "geometry/errors.h"
#include "geometry/gltf_vertex_frames.h"
#include "geometry/gutter_atlas.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "texture/procedural_texture.h"
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
  make_grid(m, 8, 8);
  SubdivisionSynthesisOptions o;
  o.r_scale = 40;
  o.levels = 2;
  o.keys = {{0, {1, 0, 0}}};
  o.seed = 4;
  const SubdivisionSynthesisResult r = synthesize_on_subdivision(m, ex, o);
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
