// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include "geometry/errors.h"
#include "geometry/image.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/render_view.h"

using namespace surftex;

namespace {
// Centre pixel of a view that looks straight at the grid (z = 0 plane).
std::array<float, 3> centre(const Image& img) {
  const int c = img.width / 2;
  return {img.at(c, c, 0), img.at(c, c, 1), img.at(c, c, 2)};
}
ViewOptions front() {
  ViewOptions v;
  v.size = 64;
  v.azimuth_deg = 0.f;
  v.elevation_deg = 0.f;
  return v;
}
}  // namespace

TEST(RenderView, AutoPicksTextureThenVertexColoursThenConstant) {
  Mesh grid;
  make_grid(grid, 4, 4);
  // Constant: a grey-ish surface colour, not the white background.
  const auto grey = centre(render_view(grid, front()));
  EXPECT_LT(grey[0], 0.95f);
  EXPECT_NEAR(grey[0], grey[1], 0.05f);

  // Vertex colours present: pure green everywhere.
  auto col = get_or_add(grid, kVertexColor);
  for (VertexIndex v : grid.vertices()) col[v] = {0.f, 1.f, 0.f};
  const auto green = centre(render_view(grid, front()));
  EXPECT_GT(green[1], 0.3f);
  EXPECT_LT(green[0], 0.02f);
  EXPECT_LT(green[2], 0.02f);

  // A texture given: the (red) texture wins over the vertex colours.
  auto uv = get_or_add(grid, kCornerUV);
  for (HalfedgeIndex h : grid.halfedges())
    if (!grid.is_border(h)) uv[h] = {0.5, 0.5};
  Image red(4, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) red.at(x, y, 0) = 1.f;
  ViewOptions v = front();
  v.texture = &red;
  const auto r = centre(render_view(grid, v));
  EXPECT_GT(r[0], 0.3f);
  EXPECT_LT(r[1], 0.02f);
}

TEST(RenderView, MissingColoursAreRefused) {
  Mesh grid;
  make_grid(grid, 2, 2);
  ViewOptions v = front();
  v.colors = ViewOptions::Colors::VertexColors;
  EXPECT_THROW(render_view(grid, v), InvalidInputError);  // no v:color
  v.colors = ViewOptions::Colors::Texture;
  EXPECT_THROW(render_view(grid, v), InvalidInputError);  // no texture image
  Image tex(2, 2, 3);
  v.texture = &tex;
  EXPECT_THROW(render_view(grid, v), InvalidInputError);  // no h:uv
}

TEST(RenderView, ZUpSceneIsSeenAsItsYUpTurnWould) {
  // A cylinder along z (the quilting scenes' height axis), tilted a little so
  // no view is symmetric.
  Mesh zup;
  make_cylinder(zup, 0.3, 2.0, 24, 6);
  for (VertexIndex v : zup.vertices()) {
    const Point3 p = zup.point(v);
    zup.point(v) = Point3(p.x() + 0.2 * p.z(), p.y(), p.z());
  }
  Mesh yup = zup;
  for (VertexIndex v : yup.vertices()) {
    const Point3 p = yup.point(v);
    yup.point(v) = Point3(p.x(), p.z(), -p.y());
  }
  ViewOptions v;
  v.size = 96;
  v.azimuth_deg = 30.f;
  v.elevation_deg = 35.f;
  v.up = ViewOptions::Up::Z;
  const Image a = render_view(zup, v);
  v.up = ViewOptions::Up::Y;
  const Image b = render_view(yup, v);
  EXPECT_EQ(a.data, b.data);
  // ... and differs from the z-up mesh taken as y-up (lying on its side).
  const Image c = render_view(zup, v);
  EXPECT_NE(a.data, c.data);
}
