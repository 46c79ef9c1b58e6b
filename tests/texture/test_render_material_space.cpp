// SPDX-License-Identifier: AGPL-3.0-or-later
// Rendering a material-space mapping with and without the singularity fix
// (Ray et al. 2009, section 3), and the 3D tile lookup it uses.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "texture/material_space/periodic_global_parameterization.h"
#include "texture/material_space/pgp_singularities.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/rasterizer.h"
#include "geometry/render_mesh.h"
#include "texture/material_space/material_tile_io.h"
#include "texture/material_space/render_material_space.h"

namespace surftex {
namespace {

// A smooth periodic 2-layer tile: red follows s, green follows t, blue = layer.
MaterialTile smooth_tile(int n = 32) {
  MaterialTile t;
  t.size = n;
  t.layers_per_pair = 1;
  for (int l = 0; l < 2; ++l) {
    Image img(n, n, 3);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        img.at(x, y, 0) = 0.5f + 0.5f * static_cast<float>(std::cos(2 * M_PI * (x + 0.5) / n));
        img.at(x, y, 1) = 0.5f + 0.5f * static_cast<float>(std::sin(2 * M_PI * (y + 0.5) / n));
        img.at(x, y, 2) = static_cast<float>(l);
      }
    t.layers.push_back(img);
    t.material.push_back(l);
  }
  return t;
}

// A flat 2x2 grid with a radial direction field: index +1 at the centre, so the
// PGP cannot be consistent (t runs around the centre with a non-integer period
// count): a planted pole with mismatched edges.
// The planted radial field is solved without the curl correction: its
// conformal factor 1/r would make the texture up to 4x denser around the
// singularity (a radial field's log-polar map), and the edge statistics below
// assume the texture changes slowly over a few pixels.
PgpSingularityOptions planted_options() {
  PgpSingularityOptions o;
  o.pgp.curl_correction = false;
  return o;
}

void planted_singularity(Mesh& m) {
  const int n = 40;  // not shrunk under sanitizers: the edge statistics need the resolution
  make_grid(m, n, n, 2.0, 2.0);
  auto dir = get_or_add(m, kFaceDirection, Vector3(1, 0, 0));
  for (FaceIndex f : m.faces()) {
    Vector3 c(0, 0, 0);
    for (VertexIndex v : CGAL::vertices_around_face(m.halfedge(f), m)) c = c + (m.point(v) - CGAL::ORIGIN) / 3.0;
    Vector3 r(c.x() - 1.0, c.y() - 1.0, 0.0);
    if (r.squared_length() < 1e-12) r = Vector3(1, 0, 0);
    dir[f] = r / std::sqrt(r.squared_length());
  }
  auto sc = get_or_add(m, kVertexScale, 0.0);
  for (VertexIndex v : m.vertices()) sc[v] = 0.23;
  auto mat = get_or_add(m, kVertexMaterial, 0.0);
  for (VertexIndex v : m.vertices()) mat[v] = 0.5 * m.point(v).x();
  periodic_global_parameterization(m, planted_options().pgp);
}

struct EdgeJumps {
  double mismatched = 0, regular = 0;
  int n_mismatched = 0, n_regular = 0;
};

// Colour difference between pixels on both sides of each projected interior
// edge (1.5 pixels from its midpoint along the edge normal), averaged over
// mismatched and over regular edges.
EdgeJumps edge_jumps(const Mesh& m, const PgpSingularities& s, const Image& img, double half_height) {
  EdgeJumps out;
  const int W = img.width, H = img.height;
  auto to_px = [&](const Point3& p, double& x, double& y) {
    x = (p.x() - 1.0) / half_height * (H / 2.0) + W / 2.0;
    y = H / 2.0 - (p.y() - 1.0) / half_height * (H / 2.0);
  };
  auto colour = [&](double x, double y, float* c) {
    const int ix = static_cast<int>(std::floor(x)), iy = static_cast<int>(std::floor(y));
    for (int k = 0; k < 3; ++k) c[k] = img.at(ix, iy, k);
  };
  for (EdgeIndex e : m.edges()) {
    if (m.is_border(e)) continue;
    const HalfedgeIndex h = m.halfedge(e);
    double x0, y0, x1, y1;
    to_px(m.point(m.source(h)), x0, y0);
    to_px(m.point(m.target(h)), x1, y1);
    const double len = std::hypot(x1 - x0, y1 - y0);
    const double nx = -(y1 - y0) / len, ny = (x1 - x0) / len;
    const double mx = 0.5 * (x0 + x1), my = 0.5 * (y0 + y1);
    float a[3], b[3];
    colour(mx + 1.5 * nx, my + 1.5 * ny, a);
    colour(mx - 1.5 * nx, my - 1.5 * ny, b);
    const double d = std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
    if (s.mismatched_edge[e.idx()]) {
      out.mismatched += d;
      ++out.n_mismatched;
    } else if (!s.singular_face[m.face(h).idx()] && !s.singular_face[m.face(m.opposite(h)).idx()]) {
      out.regular += d;
      ++out.n_regular;
    }
  }
  if (out.n_mismatched) out.mismatched /= out.n_mismatched;
  if (out.n_regular) out.regular /= out.n_regular;
  return out;
}

TEST(RenderMaterialSpace, RenderMeshCornersAreThePgpCorners) {
  Mesh m;
  make_icosphere(m, 1);
  const RenderMesh rm = make_render_mesh(m);
  ASSERT_EQ(rm.triangle_face.size(), m.number_of_faces());
  for (std::size_t t = 0; t < rm.triangles.size(); ++t) {
    const FaceIndex f(static_cast<std::uint32_t>(rm.triangle_face[t]));
    HalfedgeIndex h = m.halfedge(f);
    for (int k = 0; k < 3; ++k, h = m.next(h)) {
      const Point3& p = m.point(m.target(h));
      const Vec3f& q = rm.positions[rm.triangles[t][k]];
      EXPECT_FLOAT_EQ(static_cast<float>(p.x()), q[0]);
      EXPECT_FLOAT_EQ(static_cast<float>(p.y()), q[1]);
      EXPECT_FLOAT_EQ(static_cast<float>(p.z()), q[2]);
    }
  }
}

TEST(RenderMaterialSpace, BlendedLookupHidesAPlantedSingularityInTheImage) {
  Mesh m;
  planted_singularity(m);
  const PgpSingularities s = detect_pgp_singularities(m, planted_options());
  std::size_t mismatched = 0;
  for (char x : s.mismatched_edge) mismatched += x;
  ASSERT_GT(mismatched, 5u) << "the radial field must produce mismatched edges";

  const MaterialTile tile = smooth_tile();
  const RenderMesh rm = make_render_mesh(m);
  Camera cam;
  cam.projection = Camera::Projection::Orthographic;
  cam.eye = {1.f, 1.f, 3.f};
  cam.target = {1.f, 1.f, 0.f};
  cam.ortho_half_height = 1.05f;
  RenderOptions ro;
  ro.width = ro.height = 512;
  ro.supersample = 1;
  ro.shade = false;
  ro.color_source = RenderOptions::ColorSource::Callback;
  MaterialRenderOptions mo;
  mo.lookup = MaterialRenderOptions::Lookup::Plain;
  ro.callback = material_space_fragment(rm, s, tile, mo);
  const Image plain = render(rm, cam, ro).color;
  mo.lookup = MaterialRenderOptions::Lookup::Blended;
  ro.callback = material_space_fragment(rm, s, tile, mo);
  const Image fixed = render(rm, cam, ro).color;

  const EdgeJumps jp = edge_jumps(m, s, plain, 1.05), jf = edge_jumps(m, s, fixed, 1.05);
  ASSERT_GT(jp.n_mismatched, 5);
  ASSERT_GT(jp.n_regular, 100);
  // Without the fix the mismatched edges show as seams, far above the smooth
  // texture's own change over 3 pixels; with it they drop to that level.
  EXPECT_GT(jp.mismatched, 3 * jp.regular) << "plain: mismatched " << jp.mismatched << " regular " << jp.regular;
  EXPECT_LT(jf.mismatched, 0.4 * jp.mismatched) << "fixed " << jf.mismatched << " plain " << jp.mismatched;
  EXPECT_LT(jf.mismatched, 2.0 * jf.regular) << "fixed: mismatched " << jf.mismatched << " regular " << jf.regular;
  // Regular faces are rendered identically by both.
  EXPECT_NEAR(jf.regular, jp.regular, 1e-6);
}

TEST(RenderMaterialSpace, NormalMapPerturbsShadingFollowingTheTile) {
  Mesh m;
  make_grid(m, 8, 8, 2.0, 2.0);
  auto dir = get_or_add(m, kFaceDirection, Vector3(1, 0, 0));
  for (FaceIndex f : m.faces()) dir[f] = Vector3(1, 0, 0);
  auto sc = get_or_add(m, kVertexScale, 0.0);
  for (VertexIndex v : m.vertices()) sc[v] = 0.5;
  periodic_global_parameterization(m);
  const PgpSingularities s = detect_pgp_singularities(m);
  EXPECT_EQ(s.singular_faces, 0u);
  const RenderMesh rm = make_render_mesh(m);
  Camera cam;
  cam.projection = Camera::Projection::Orthographic;
  cam.eye = {1.f, 1.f, 3.f};
  cam.target = {1.f, 1.f, 0.f};
  MaterialRenderOptions mo;
  mo.output = MaterialRenderOptions::Output::NormalMap;
  mo.light_world = {1.f, 0.f, 1.f};
  mo.bump_strength = 0.5;
  MaterialTile tile = smooth_tile();
  const FragmentCallback cb = material_space_fragment(rm, s, tile, mo);
  // Shading varies along s (the red channel is the height's s-variation) and
  // is two-sided Lambert: with zero strength it is constant.
  float lo = 1e9f, hi = -1e9f;
  for (int i = 0; i < 20; ++i) {
    const float b0 = 0.05f + 0.045f * i;
    const Vec3f c = cb(5, {b0, 0.5f * (1 - b0), 0.5f * (1 - b0)});
    lo = std::min(lo, c[0]);
    hi = std::max(hi, c[0]);
  }
  EXPECT_GT(hi - lo, 0.02f);
  mo.bump_strength = 0;
  const FragmentCallback flat = material_space_fragment(rm, s, tile, mo);
  const Vec3f c0 = flat(5, {0.2f, 0.4f, 0.4f}), c1 = flat(5, {0.6f, 0.2f, 0.2f});
  EXPECT_NEAR(c0[0], c1[0], 1e-5f);
  EXPECT_NEAR(c0[0], mo.base_color[0] * (mo.ambient + (1 - mo.ambient) * std::sqrt(0.5f)), 1e-4f);
}

TEST(RenderMaterialSpace, RejectsARenderMeshWithoutFaceMap) {
  Mesh m;
  make_grid(m, 2, 2);
  auto dir = get_or_add(m, kFaceDirection, Vector3(1, 0, 0));
  for (FaceIndex f : m.faces()) dir[f] = Vector3(1, 0, 0);
  periodic_global_parameterization(m);
  const PgpSingularities s = detect_pgp_singularities(m);
  RenderMesh rm = make_render_mesh(m);
  rm.triangle_face.clear();
  EXPECT_THROW(material_space_fragment(rm, s, smooth_tile()), InvalidInputError);
}

}  // namespace
}  // namespace surftex
