// SPDX-License-Identifier: AGPL-3.0-or-later
// bake_texel_values (geometry/bake_vertex_colors.h): any per-texel values in
// the atlas, the same bytes for any thread count; bake_vertex_values on it.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include "geometry/bake_vertex_colors.h"
#include "geometry/errors.h"
#include "geometry/gutter_atlas.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

// value = (first corner's vertex, its barycentric, the triangle's corner sum)
// at each covered texel; the vertex blend of bake_vertex_values is the
// barycentric sum of the per-vertex values.
TEST(BakeTexelValues, WritesTheCallbackAtEveryCoveredTexelForAnyThreadCount) {
  Mesh m;
  make_icosphere(m, 2);
  compute_gutter_atlas(m, 128);
  const auto fn = [&](const std::array<std::size_t, 3>& c, const std::array<float, 3>& b, float* out) {
    out[0] = static_cast<float>(m.target(HalfedgeIndex(static_cast<Mesh::size_type>(c[0]))).idx());
    out[1] = b[0];
  };
  BakeOptions o;
  o.size = 128;
  const BakeResult one = [&] {
    tbb::global_control g(tbb::global_control::max_allowed_parallelism, 1);
    return bake_texel_values(m, 2, fn, o);
  }();
  const BakeResult many = bake_texel_values(m, 2, fn, o);
  EXPECT_EQ(one.image.data, many.image.data);
  const AtlasTexels at = rasterize_atlas(m, 128);
  std::vector<float> values(m.number_of_vertices());
  for (VertexIndex v : m.vertices()) values[v.idx()] = static_cast<float>(v.idx() % 7);
  const BakeResult blend = bake_vertex_values(m, values, 1, o);
  std::size_t covered = 0;
  for (std::size_t i = 0; i < at.chart.size(); ++i) {
    const int t = at.raster.triangle[i];
    if (t < 0) continue;
    ++covered;
    const auto& c = at.corner[t];
    const auto vtx = [&](int k) { return m.target(HalfedgeIndex(static_cast<Mesh::size_type>(c[k]))).idx(); };
    ASSERT_EQ(one.image.data[2 * i], static_cast<float>(vtx(0)));
    ASSERT_EQ(one.image.data[2 * i + 1], at.raster.bary[i][0]);
    float want = 0;
    for (int k = 0; k < 3; ++k) want += at.raster.bary[i][k] * values[vtx(k)];
    ASSERT_FLOAT_EQ(blend.image.data[i], want);
  }
  EXPECT_EQ(covered, one.covered);
  EXPECT_GT(covered, 128u * 128u / 10);
  EXPECT_THROW(bake_texel_values(m, 0, fn, o), InvalidInputError);
  EXPECT_THROW(bake_texel_values(m, 5, fn, o), InvalidInputError);
}

}  // namespace
}  // namespace surftex
