// SPDX-License-Identifier: AGPL-3.0-or-later
// The glTF vertex frames shared by write_mesh's .glb and the tangent-space
// baker (geometry/gltf_vertex_frames.h): the same numbers as the file holds.
#include <gtest/gtest.h>

#include <cmath>

#include "apps/asset_checks.h"
#include "geometry/errors.h"
#include "geometry/gltf_vertex_frames.h"
#include "geometry/gutter_atlas.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

namespace surftex {
namespace {

// An atlas with seams (charts split vertices): every face corner's glTF vertex
// carries exactly the NORMAL and TANGENT the GLB stores for it.
TEST(GltfVertexFrames, EqualTheAttributesOfTheWrittenGlb) {
  Mesh m;
  make_icosphere(m, 2);
  compute_gutter_atlas(m, 128);
  const GltfVertexFrames fr = gltf_vertex_frames(m);
  const Image tex(8, 8, 3, 0.5f);
  WriteMeshOptions o;
  o.texture = &tex;
  o.normal_texture = &tex;
  o.write_colors = false;
  const std::string path = test::temp_dir("gltf_frames") + "/s.glb";
  write_mesh(path, m, o);
  const test::Glb g = test::read_glb(path);
  const auto& prim = g.json["meshes"][0]["primitives"][0];
  const auto N = g.accessor<float>(prim["attributes"]["NORMAL"].get<int>());
  const auto T = g.accessor<float>(prim["attributes"]["TANGENT"].get<int>());
  const auto idx = g.accessor<std::uint32_t>(prim["indices"].get<int>());
  ASSERT_EQ(fr.normal.size() * 3, N.size());
  ASSERT_EQ(fr.tangent.size() * 4, T.size());
  for (std::size_t i = 0; i < fr.normal.size(); ++i) {
    for (int k = 0; k < 3; ++k) ASSERT_EQ(fr.normal[i][k], N[3 * i + k]) << i;
    for (int k = 0; k < 4; ++k) ASSERT_EQ(fr.tangent[i][k], T[4 * i + k]) << i;
  }
  // The file's triangles list the corners' glTF vertices in face order.
  std::size_t k = 0;
  for (FaceIndex f : m.faces())
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) ASSERT_EQ(fr.corner[h.idx()], idx[k++]);
  EXPECT_GT(fr.normal.size(), m.number_of_vertices());  // the seams split vertices
  Mesh bare;
  make_icosphere(bare, 0);
  EXPECT_THROW(gltf_vertex_frames(bare), InvalidInputError);  // no uv
}

}  // namespace
}  // namespace surftex
