// SPDX-License-Identifier: AGPL-3.0-or-later
// Tests of make_render_mesh (geometry/render_mesh.h) and rendering a Surface_mesh.
#include <gtest/gtest.h>

#include <cmath>

#include "geometry/errors.h"
#include "geometry/properties.h"
#include "geometry/render_mesh.h"

using namespace surftex;

namespace {
// A unit cube of six outward quads.
Mesh cube() {
  Mesh m;
  VertexIndex v[8];
  for (int i = 0; i < 8; ++i) v[i] = m.add_vertex(Point3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  auto quad = [&](int a, int b, int c, int d) { EXPECT_TRUE(m.add_face(v[a], v[b], v[c], v[d]) != Mesh::null_face()); };
  quad(0, 2, 3, 1);  // z = 0, normal -z
  quad(4, 5, 7, 6);  // z = 1, +z
  quad(0, 4, 6, 2);  // x = 0, -x
  quad(1, 3, 7, 5);  // x = 1, +x
  quad(0, 1, 5, 4);  // y = 0, -y
  quad(2, 6, 7, 3);  // y = 1, +y
  return m;
}
}  // namespace

TEST(RenderMesh, FanTriangulatesPolygonsAndCopiesRequestedProperties) {
  Mesh m;
  VertexIndex a = m.add_vertex(Point3(0, 0, 0)), b = m.add_vertex(Point3(1, 0, 0)),
              c = m.add_vertex(Point3(1, 1, 0)), d = m.add_vertex(Point3(0, 1, 0)),
              e = m.add_vertex(Point3(2, 0.5, 0)), junk = m.add_vertex(Point3(9, 9, 9));
  FaceIndex q = m.add_face(a, b, c, d);
  FaceIndex t = m.add_face(b, e, c);
  ASSERT_TRUE(q != Mesh::null_face() && t != Mesh::null_face());
  m.remove_vertex(junk);  // removed elements must be skipped
  auto col = get_or_add(m, kVertexColor);
  auto uv = get_or_add(m, kCornerUV);
  for (VertexIndex v : m.vertices()) col[v] = {float(m.point(v).x()), float(m.point(v).y()), 0.5f};
  for (HalfedgeIndex h : m.halfedges())
    if (!m.is_border(h)) uv[h] = {m.point(m.target(h)).x() / 2, m.point(m.target(h)).y()};

  RenderMesh r = make_render_mesh(m, {.vertex_colors = true, .corner_uvs = true, .smooth_normals = true});
  ASSERT_EQ(r.positions.size(), 5u);
  ASSERT_EQ(r.triangles.size(), 3u);  // quad -> 2, triangle -> 1
  ASSERT_EQ(r.triangle_face.size(), 3u);
  ASSERT_EQ(r.corner_uvs.size(), 9u);
  ASSERT_EQ(r.vertex_colors.size(), 5u);
  ASSERT_EQ(r.vertex_normals.size(), 5u);
  EXPECT_EQ(r.triangle_face[0], int(q.idx()));
  EXPECT_EQ(r.triangle_face[1], int(q.idx()));
  EXPECT_EQ(r.triangle_face[2], int(t.idx()));
  // Every triangle keeps the face's winding (+z normal) and its corners' UVs and colours.
  for (std::size_t i = 0; i < r.triangles.size(); ++i) {
    const auto& tri = r.triangles[i];
    const Vec3f &p0 = r.positions[tri[0]], &p1 = r.positions[tri[1]], &p2 = r.positions[tri[2]];
    double nz = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
    EXPECT_GT(nz, 0) << i;
    for (int k = 0; k < 3; ++k) {
      const Vec3f& p = r.positions[tri[k]];
      EXPECT_FLOAT_EQ(r.corner_uvs[3 * i + k][0], p[0] / 2);
      EXPECT_FLOAT_EQ(r.corner_uvs[3 * i + k][1], p[1]);
      EXPECT_FLOAT_EQ(r.vertex_colors[tri[k]][0], p[0]);
      EXPECT_FLOAT_EQ(r.vertex_colors[tri[k]][1], p[1]);
    }
  }
  for (const Vec3f& n : r.vertex_normals) EXPECT_NEAR(n[2], 1.f, 1e-6f);

  RenderMesh flat = make_render_mesh(m, {.smooth_normals = false});
  EXPECT_TRUE(flat.vertex_normals.empty());
  EXPECT_TRUE(flat.vertex_colors.empty());
  EXPECT_TRUE(flat.corner_uvs.empty());
}

TEST(RenderMesh, MissingRequestedPropertiesAreErrors) {
  Mesh m = cube();
  EXPECT_THROW(make_render_mesh(m, {.vertex_colors = true}), InvalidInputError);
  EXPECT_THROW(make_render_mesh(m, {.corner_uvs = true}), InvalidInputError);
  EXPECT_THROW(make_render_mesh(Mesh{}), InvalidInputError);
}

TEST(RenderMesh, ClosedCubeRendersFrontFacesLit) {
  Mesh m = cube();
  for (bool smooth : {false, true}) {
    RenderMesh r = make_render_mesh(m, {.smooth_normals = smooth});
    ASSERT_EQ(r.triangles.size(), 12u);
    // Look at the +z face head-on with the light from the camera: full brightness when flat.
    Camera cam;
    cam.eye = {0.5f, 0.5f, 4};
    cam.target = {0.5f, 0.5f, 0};
    RenderOptions opt;
    opt.width = opt.height = 64;
    opt.supersample = 1;
    opt.constant_color = {1, 1, 1};
    opt.ambient = 0.1f;
    opt.light_direction = {0, 0, 1};
    RenderResult res = render(r, cam, opt);
    EXPECT_NEAR(res.depth.at(32, 32), 3.f, 1e-4f);  // the z = 1 face, not the z = 0 one behind it
    if (!smooth) {
      EXPECT_NEAR(res.color.at(32, 32, 0), 1.f, 1e-5f);
    } else {
      // Smooth normals at a cube's corners tilt by up to 54.7 degrees; the centre of a face
      // interpolates towards the face normal.
      EXPECT_GT(res.color.at(32, 32, 0), 0.6f);
    }
  }
}
