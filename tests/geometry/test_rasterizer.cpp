// SPDX-License-Identifier: AGPL-3.0-or-later
// Tests of the software rasterizer (geometry/rasterizer.h) on meshes built in code.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <random>

#include "geometry/errors.h"
#include "geometry/rasterizer.h"

using namespace surftex;

namespace {

constexpr double kPi = 3.14159265358979323846;
using CS = RenderOptions::ColorSource;

// Appends an axis-aligned rectangle (two triangles) with per-corner UVs (0,0)
// at `o`, u along `du`, v along `dv`; returns its first vertex index.
int add_quad(RenderMesh& m, Vec3f o, Vec3f du, Vec3f dv, Vec3f color = {1, 1, 1}) {
  int b = static_cast<int>(m.positions.size());
  auto at = [&](float s, float t) {
    return Vec3f{o[0] + s * du[0] + t * dv[0], o[1] + s * du[1] + t * dv[1], o[2] + s * du[2] + t * dv[2]};
  };
  m.positions.push_back(at(0, 0));
  m.positions.push_back(at(1, 0));
  m.positions.push_back(at(1, 1));
  m.positions.push_back(at(0, 1));
  for (int k = 0; k < 4; ++k) m.vertex_colors.push_back(color);
  m.triangles.push_back({b, b + 1, b + 2});
  m.triangles.push_back({b, b + 2, b + 3});
  m.corner_uvs.insert(m.corner_uvs.end(), {Vec2f{0, 0}, Vec2f{1, 0}, Vec2f{1, 1}});
  m.corner_uvs.insert(m.corner_uvs.end(), {Vec2f{0, 0}, Vec2f{1, 1}, Vec2f{0, 1}});
  return b;
}

// Axis-aligned box [lo, hi], outward-facing, one colour.
void add_box(RenderMesh& m, Vec3f lo, Vec3f hi, Vec3f color) {
  Vec3f d{hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  add_quad(m, lo, {0, d[1], 0}, {d[0], 0, 0}, color);                     // z = lo (normal -z)
  add_quad(m, {lo[0], lo[1], hi[2]}, {d[0], 0, 0}, {0, d[1], 0}, color);  // z = hi (+z)
  add_quad(m, lo, {0, 0, d[2]}, {0, d[1], 0}, color);                     // x = lo
  add_quad(m, {hi[0], lo[1], lo[2]}, {0, d[1], 0}, {0, 0, d[2]}, color);  // x = hi
  add_quad(m, lo, {d[0], 0, 0}, {0, 0, d[2]}, color);                     // y = lo
  add_quad(m, {lo[0], hi[1], lo[2]}, {0, 0, d[2]}, {d[0], 0, 0}, color);  // y = hi
}

// Latitude-longitude unit sphere with smooth normals and position colours.
RenderMesh sphere(int nu, int nv) {
  RenderMesh m;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      double th = kPi * j / nv, ph = 2 * kPi * i / nu;
      Vec3f p{float(std::sin(th) * std::cos(ph)), float(std::cos(th)), float(std::sin(th) * std::sin(ph))};
      m.positions.push_back(p);
      m.vertex_normals.push_back(p);
      m.vertex_colors.push_back({0.5f + 0.5f * p[0], 0.5f + 0.5f * p[1], 0.5f + 0.5f * p[2]});
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      int a = j * nu + i, b = j * nu + (i + 1) % nu, c = a + nu, d = b + nu;
      m.triangles.push_back({a, b, d});
      m.triangles.push_back({a, d, c});
    }
  return m;
}

Camera ortho_camera(Vec3f eye, Vec3f target, float half_height) {
  Camera c;
  c.projection = Camera::Projection::Orthographic;
  c.eye = eye;
  c.target = target;
  c.ortho_half_height = half_height;
  c.near_plane = 0.f;
  return c;
}

float bilinear_clamp(const Image& t, double x, double y, int c) {  // x, y in texel units, centres at i + .5
  x -= 0.5;
  y -= 0.5;
  int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  double ax = x - x0, ay = y - y0;
  auto at = [&](int i, int j) { return t.at(std::clamp(i, 0, t.width - 1), std::clamp(j, 0, t.height - 1), c); };
  return float((at(x0, y0) * (1 - ax) + at(x0 + 1, y0) * ax) * (1 - ay) +
               (at(x0, y0 + 1) * (1 - ax) + at(x0 + 1, y0 + 1) * ax) * ay);
}

}  // namespace

TEST(Rasterizer, TexturedQuadHeadOnReproducesTexture) {
  // An asymmetric smooth texture: a wrong flip, transpose or offset drops the PSNR far below 35 dB.
  Image tex(48, 32, 3);
  for (int y = 0; y < tex.height; ++y)
    for (int x = 0; x < tex.width; ++x) {
      tex.at(x, y, 0) = float(x) / (tex.width - 1);
      tex.at(x, y, 1) = float(y) / (tex.height - 1);
      tex.at(x, y, 2) = float(0.5 + 0.4 * std::sin(0.35 * x + 0.2 * y * y / 8.0));
    }
  RenderMesh m;
  add_quad(m, {0, 0, 0}, {1.5f, 0, 0}, {0, 1, 0});
  RenderOptions opt;
  opt.width = 150;
  opt.height = 100;
  opt.supersample = 1;
  opt.shade = false;
  opt.color_source = CS::Texture;
  opt.texture = &tex;
  opt.wrap = RenderOptions::Wrap::Clamp;
  RenderResult r = render(m, ortho_camera({0.75f, 0.5f, 2}, {0.75f, 0.5f, 0}, 0.5f), opt);
  double se = 0;
  for (int py = 0; py < opt.height; ++py)
    for (int px = 0; px < opt.width; ++px) {
      ASSERT_FLOAT_EQ(r.coverage.at(px, py), 1.f) << px << "," << py;
      // Pixel centre -> (u, v) with v up -> texel coordinates with row 0 at v = 1.
      double u = (px + 0.5) / opt.width, v = 1.0 - (py + 0.5) / opt.height;
      for (int c = 0; c < 3; ++c) {
        double e = r.color.at(px, py, c) - bilinear_clamp(tex, u * tex.width, (1 - v) * tex.height, c);
        se += e * e;
      }
    }
  double mse = se / (3.0 * opt.width * opt.height);
  double psnr = 10 * std::log10(1.0 / std::max(mse, 1e-20));
  EXPECT_GT(psnr, 35.0);
  // Orientation spot checks: red grows to the right, green grows upwards in the texture image (down in v).
  EXPECT_LT(r.color.at(2, 50, 0), 0.1f);
  EXPECT_GT(r.color.at(147, 50, 0), 0.9f);
  EXPECT_LT(r.color.at(75, 1, 1), 0.1f);
  EXPECT_GT(r.color.at(75, 98, 1), 0.9f);
}

TEST(Rasterizer, SampleTextureHitsTexelCentresAndWraps) {
  Image tex(4, 2, 1);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) tex.at(x, y) = float(10 * y + x);
  using W = RenderOptions::Wrap;
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.125f, 0.75f, W::Clamp)[0], 0.f);   // texel (0,0): top row is v = 1
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.625f, 0.25f, W::Clamp)[1], 12.f);  // texel (2,1)
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.25f, 0.75f, W::Clamp)[2], 0.5f);   // between (0,0) and (1,0)
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.f, 0.75f, W::Clamp)[0], 0.f);      // clamp at the left edge
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.f, 0.75f, W::Repeat)[0], 1.5f);    // halfway between texels 3 and 0
  EXPECT_FLOAT_EQ(sample_texture(tex, 1.125f, -0.75f, W::Repeat)[0], 10.f);  // wraps to texel (0,1)
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.125f, 0.f, W::Repeat)[0], 5.f);      // halfway between rows 1 and 0
  EXPECT_FLOAT_EQ(sample_texture(tex, 1.125f, 0.75f, W::Mirror)[0], 3.f);   // past u = 1 back over texel 3
  EXPECT_FLOAT_EQ(sample_texture(tex, -0.125f, 0.75f, W::Mirror)[0], 0.f);  // before u = 0 over texel 0
  EXPECT_FLOAT_EQ(sample_texture(tex, 1.125f, 0.75f, W::Repeat, W::Clamp)[0], 0.f);  // a wrap per axis
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.125f, 1.25f, W::Repeat, W::Clamp)[0], 0.f);
  EXPECT_FLOAT_EQ(sample_texture(tex, 0.125f, 1.25f, W::Clamp, W::Repeat)[0], 10.f);
}

TEST(Rasterizer, CubeOccludesPlaneWhateverTheDrawOrder) {
  const Vec3f red{1, 0, 0}, green{0, 1, 0};
  RenderMesh plane_first, cube_first;
  add_quad(plane_first, {-2, -2, 0}, {4, 0, 0}, {0, 4, 0}, red);
  add_box(plane_first, {-0.5f, -0.5f, 0.5f}, {0.5f, 0.5f, 1.5f}, green);
  add_box(cube_first, {-0.5f, -0.5f, 0.5f}, {0.5f, 0.5f, 1.5f}, green);
  add_quad(cube_first, {-2, -2, 0}, {4, 0, 0}, {0, 4, 0}, red);
  Camera cam;
  cam.eye = {0, 0, 5};
  cam.target = {0, 0, 0};
  cam.fov_y_deg = 40;
  RenderOptions opt;
  opt.width = opt.height = 96;
  opt.supersample = 1;
  opt.shade = false;
  opt.color_source = CS::VertexColors;
  for (const RenderMesh* m : {&plane_first, &cube_first}) {
    RenderResult r = render(*m, cam, opt);
    // Centre: the cube's front face at z = 1.5, i.e. 3.5 in front of the eye.
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(r.color.at(48, 48, c), green[c]);
    EXPECT_NEAR(r.depth.at(48, 48), 3.5f, 1e-3f);
    // The cube's front face spans |x| <= 0.5 at distance 3.5: tan = 0.143, the image half-height tan(20deg) = 0.364.
    for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(r.color.at(48 + 15, 48 - 15, c), green[c]);
    // Near the corners the plane shows (distance 5, |x| up to 1.82 < 2).
    for (auto [x, y] : {std::pair{3, 3}, std::pair{92, 3}, std::pair{3, 92}, std::pair{92, 92}, std::pair{48, 5}}) {
      for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(r.color.at(x, y, c), red[c]) << x << "," << y;
      EXPECT_NEAR(r.depth.at(x, y), 5.f, 1e-3f);
    }
  }
}

TEST(Rasterizer, VertexColoursInterpolateAcrossATriangle) {
  RenderMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  m.vertex_colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  RenderOptions opt;
  opt.width = opt.height = 90;
  opt.supersample = 1;
  opt.shade = false;
  opt.background = {0, 0, 0};
  opt.color_source = CS::VertexColors;
  RenderResult r = render(m, ortho_camera({0.5f, 0.5f, 1}, {0.5f, 0.5f, 0}, 0.5f), opt);
  // Pixel centre (px + .5, py + .5) <-> world (x, 1 - y) / 90. Centroid (1/3, 1/3) -> pixel (29.5, 59.5).
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.color.at(29, 59, c), 1.f / 3, 0.02f);
  // Next to the vertices.
  const float expect[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int pix[3][2] = {{1, 88}, {86, 88}, {1, 3}};
  for (int v = 0; v < 3; ++v)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.color.at(pix[v][0], pix[v][1], c), expect[v][c], 0.06f) << v;
  // Exactly linear in between: red = 1 - x - y, green = x, blue = y at the pixel centre.
  for (auto [px, py] : {std::pair{45, 88}, std::pair{10, 40}, std::pair{40, 50}}) {
    float x = (px + 0.5f) / 90, y = 1 - (py + 0.5f) / 90;
    EXPECT_NEAR(r.color.at(px, py, 0), 1 - x - y, 1e-4f);
    EXPECT_NEAR(r.color.at(px, py, 1), x, 1e-4f);
    EXPECT_NEAR(r.color.at(px, py, 2), y, 1e-4f);
  }
  // Outside the triangle: background.
  EXPECT_FLOAT_EQ(r.coverage.at(80, 10), 0.f);
  EXPECT_FLOAT_EQ(r.color.at(80, 10, 0), 0.f);
}

TEST(Rasterizer, SharedEdgesLeaveNoCrackAndNoDoubleHit) {
  const Vec3f col{0.3f, 0.6f, 0.9f};
  RenderOptions opt;
  opt.shade = false;
  opt.constant_color = col;
  opt.background = {0, 0, 0};
  for (int ss : {1, 2, 3}) {
    // A quad exactly filling a square frame: its diagonal runs through sample centres.
    RenderMesh quad;
    add_quad(quad, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0});
    opt.width = opt.height = 64;
    opt.supersample = ss;
    RenderResult r = render(quad, ortho_camera({0, 0, 1}, {0, 0, 0}, 1.f), opt);
    const std::size_t samples = std::size_t(64) * 64 * ss * ss;
    EXPECT_EQ(r.fragments, samples) << "supersample " << ss;
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        ASSERT_EQ(r.coverage.at(x, y), 1.f) << x << "," << y;
        // Exact with one sample; the N x N box average may round in the last bit.
        for (int c = 0; c < 3; ++c)
          if (ss == 1) ASSERT_EQ(r.color.at(x, y, c), col[c]) << x << "," << y;
          else ASSERT_NEAR(r.color.at(x, y, c), col[c], 1e-6f) << x << "," << y;
      }
  }
  // A fan of 8 triangles around a vertex that lies exactly on a sample centre
  // (odd image size, odd supersampling), its spokes through sample centres too.
  RenderMesh fan;
  fan.positions.push_back({0, 0, 0});
  for (int k = 0; k < 8; ++k) {
    const int ring[8][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}};
    fan.positions.push_back({1.5f * ring[k][0], 1.5f * ring[k][1], 0});
    fan.triangles.push_back({0, 1 + k, 1 + (k + 1) % 8});
  }
  opt.width = opt.height = 65;
  for (int ss : {1, 3}) {
    opt.supersample = ss;
    RenderResult r = render(fan, ortho_camera({0, 0, 1}, {0, 0, 0}, 1.f), opt);
    EXPECT_EQ(r.fragments, std::size_t(65) * 65 * ss * ss) << "supersample " << ss;
  }
  // A jittered grid seen in perspective at an angle, larger than the frame:
  // every sample is hit exactly once, through edges and vertices in all directions.
  RenderMesh grid;
  const int n = 24;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> jitter(-0.35f, 0.35f);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      float dx = (i > 0 && i < n) ? jitter(rng) : 0.f, dy = (j > 0 && j < n) ? jitter(rng) : 0.f;
      grid.positions.push_back({-5 + 10.f * (i + dx) / n, -5 + 10.f * (j + dy) / n, 0});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      if ((i + j) % 2) {
        grid.triangles.push_back({a, b, d});
        grid.triangles.push_back({a, d, c});
      } else {
        grid.triangles.push_back({a, b, c});
        grid.triangles.push_back({b, d, c});
      }
    }
  Camera cam;
  cam.eye = {0.4f, -1.3f, 2.2f};
  cam.target = {0.1f, 0.2f, 0};
  cam.up = {0.3f, 1, 0};
  cam.fov_y_deg = 50;
  opt.width = 97;
  opt.height = 71;
  for (int ss : {1, 2}) {
    opt.supersample = ss;
    RenderResult r = render(grid, cam, opt);
    for (int y = 0; y < opt.height; ++y)
      for (int x = 0; x < opt.width; ++x) ASSERT_EQ(r.coverage.at(x, y), 1.f) << x << "," << y;
    EXPECT_EQ(r.fragments, std::size_t(opt.width) * opt.height * ss * ss) << "supersample " << ss;
  }
}

TEST(Rasterizer, PerspectiveCorrectStripesLandWhereTheProjectionSays) {
  // Ground plane y = 0, z from 0 to -10, v = -z / 10; a 1 x 10 texture of alternating rows.
  RenderMesh m;
  add_quad(m, {-1, 0, 0}, {2, 0, 0}, {0, 0, -10});
  Image tex(1, 10, 1);
  for (int y = 0; y < 10; ++y) tex.at(0, y) = float(y % 2);
  Camera cam;
  cam.eye = {0, 0.5f, 1.5f};
  cam.target = {0, 0, -3};
  cam.fov_y_deg = 60;
  RenderOptions opt;
  opt.width = 64;
  opt.height = 240;
  opt.supersample = 1;
  opt.shade = false;
  opt.color_source = CS::Texture;
  opt.texture = &tex;
  opt.wrap = RenderOptions::Wrap::Clamp;
  RenderResult r = render(m, cam, opt);
  // Analytic rows of the stripe boundaries z = -1 .. -9 (bilinear crosses 0.5 exactly there).
  const double fx = cam.target[0] - cam.eye[0], fy = cam.target[1] - cam.eye[1], fz = cam.target[2] - cam.eye[2];
  const double fl = std::sqrt(fx * fx + fy * fy + fz * fz);
  const double F[3] = {fx / fl, fy / fl, fz / fl};
  const double U[3] = {0, -F[2], F[1]};  // right = (1,0,0) here, up = right x forward... = (0, F[2]*-1, F[1])
  const double ul = std::sqrt(U[1] * U[1] + U[2] * U[2]);
  const double t = std::tan(30.0 * kPi / 180.0);
  std::vector<double> expected;
  for (int k = 1; k <= 9; ++k) {
    double d[3] = {0 - cam.eye[0], 0 - cam.eye[1], -k - cam.eye[2]};
    double zv = d[0] * F[0] + d[1] * F[1] + d[2] * F[2];
    double yv = (d[1] * U[1] + d[2] * U[2]) / ul;
    expected.push_back((0.5 - 0.5 * yv / (zv * t)) * opt.height);
  }
  // Measured: where the centre column crosses 0.5 (pixel centres at row + .5).
  std::vector<double> measured;
  const int x = 32;
  for (int y = 0; y + 1 < opt.height; ++y) {
    if (r.coverage.at(x, y) < 1.f || r.coverage.at(x, y + 1) < 1.f) continue;
    float a = r.color.at(x, y, 0), b = r.color.at(x, y + 1, 0);
    if ((a - 0.5f) * (b - 0.5f) < 0) measured.push_back(y + 0.5 + (0.5 - a) / (b - a));
  }
  ASSERT_EQ(measured.size(), expected.size());
  std::sort(expected.begin(), expected.end());
  double worst = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) worst = std::max(worst, std::abs(measured[i] - expected[i]));
  EXPECT_LT(worst, 1.0);
  // The far boundaries are squeezed together: affine interpolation would space them evenly.
  EXPECT_GT(expected.back() - expected[expected.size() - 2], 4 * (expected[1] - expected[0]));
}

TEST(Rasterizer, NearPlaneClippingRendersTheVisiblePartCorrectly) {
  // A huge ground plane under the camera, extending behind it.
  RenderMesh m;
  add_quad(m, {-100, 0, 100}, {200, 0, 0}, {0, 0, -200});
  Camera cam;
  cam.eye = {0, 1, 0};
  cam.target = {0, 0, -3};
  cam.fov_y_deg = 60;
  cam.near_plane = 0.05f;
  RenderOptions opt;
  opt.width = 80;
  opt.height = 60;
  opt.supersample = 1;
  opt.shade = false;
  opt.background = {0, 0, 1};
  // Colour = world position, recovered from the callback's barycentrics.
  opt.color_source = CS::Callback;
  opt.callback = [&m](int t, const Vec3f& b) {
    Vec3f p{0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 3; ++c) p[c] += b[k] * m.positions[m.triangles[t][k]][c];
    return Vec3f{p[0], p[2], 0};
  };
  RenderResult r = render(m, cam, opt);
  EXPECT_EQ(r.triangles_clipped, 2u);
  EXPECT_FLOAT_EQ(r.coverage.at(40, 59), 1.f);  // the ground below
  EXPECT_FLOAT_EQ(r.coverage.at(40, 0), 0.f);   // the sky above
  EXPECT_FLOAT_EQ(r.color.at(40, 0, 2), 1.f);
  // Cast rays through a few ground pixels and compare the world point.
  const double f[3] = {0, -1 / std::sqrt(10.0), -3 / std::sqrt(10.0)};
  const double up[3] = {0, 3 / std::sqrt(10.0), -1 / std::sqrt(10.0)};
  const double t = std::tan(30.0 * kPi / 180.0), aspect = 80.0 / 60.0;
  int checked = 0;
  for (auto [px, py] : {std::pair{40, 59}, std::pair{5, 55}, std::pair{70, 45}, std::pair{20, 35}}) {
    double nx = ((px + 0.5) / 80 * 2 - 1) * t * aspect, ny = (1 - (py + 0.5) / 60 * 2) * t;
    double dir[3] = {nx + f[0] + ny * up[0], f[1] + ny * up[1], f[2] + ny * up[2]};
    if (dir[1] >= 0) continue;
    double s = -1.0 / dir[1];
    double wx = s * dir[0], wz = s * dir[2];
    if (std::abs(wz) > 100) continue;
    ASSERT_FLOAT_EQ(r.coverage.at(px, py), 1.f);
    EXPECT_NEAR(r.color.at(px, py, 0), wx, 1e-3 * std::max(1.0, std::abs(wz))) << px << "," << py;
    EXPECT_NEAR(r.color.at(px, py, 1), wz, 1e-3 * std::max(1.0, std::abs(wz))) << px << "," << py;
    ++checked;
  }
  EXPECT_EQ(checked, 4);
  // Entirely behind the camera: nothing drawn, no crash.
  RenderMesh behind;
  add_quad(behind, {-1, -1, 5}, {2, 0, 0}, {0, 2, 0});
  RenderResult rb = render(behind, cam, opt);
  EXPECT_EQ(rb.fragments, 0u);
  EXPECT_EQ(rb.triangles_drawn, 0u);
}

TEST(Rasterizer, OutputIsIdenticalWithOneAndTwoThreads) {
  RenderMesh m = sphere(96, 64);
  Camera cam = fit_camera(bounding_box(m), 30, 20);
  RenderOptions opt;
  opt.width = 200;
  opt.height = 150;
  opt.supersample = 2;
  opt.color_source = CS::VertexColors;
  RenderResult a, b;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 1);
    a = render(m, cam, opt);
  }
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    b = render(m, cam, opt);
  }
  ASSERT_EQ(a.color.data.size(), b.color.data.size());
  EXPECT_EQ(0, std::memcmp(a.color.data.data(), b.color.data.data(), a.color.data.size() * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(a.depth.data.data(), b.depth.data.data(), a.depth.data.size() * sizeof(float)));
  EXPECT_EQ(a.fragments, b.fragments);
  EXPECT_GT(a.fragments, 0u);
}

TEST(Rasterizer, CallbackReceivesBarycentricsSummingToOne) {
  RenderMesh m = sphere(24, 16);
  std::mutex mu;
  double worst_sum = 0, min_component = 1;
  std::size_t calls = 0;
  bool bad_index = false;
  RenderOptions opt;
  opt.width = opt.height = 64;
  opt.supersample = 2;
  opt.shade = false;
  opt.color_source = CS::Callback;
  opt.callback = [&](int t, const Vec3f& b) {
    std::lock_guard<std::mutex> lock(mu);
    ++calls;
    if (t < 0 || t >= int(m.triangles.size())) bad_index = true;
    worst_sum = std::max(worst_sum, std::abs(double(b[0]) + b[1] + b[2] - 1));
    min_component = std::min({min_component, double(b[0]), double(b[1]), double(b[2])});
    return b;
  };
  RenderResult r = render(m, fit_camera(bounding_box(m), 10, 10), opt);
  EXPECT_FALSE(bad_index);
  EXPECT_LT(worst_sum, 1e-5);
  EXPECT_GT(min_component, -1e-6);
  // One call per covered sample.
  double covered = 0;
  for (float c : r.coverage.data) covered += c * 4;
  EXPECT_EQ(calls, std::size_t(std::lround(covered)));
  EXPECT_GT(calls, 1000u);
}

TEST(Rasterizer, FitCameraFramesTheWholeMesh) {
  RenderMesh m = sphere(48, 32);
  for (auto& p : m.positions) p = {2 * p[0] + 5, 0.5f * p[1] - 3, p[2] + 1};  // an ellipsoid off the origin
  RenderOptions opt;
  opt.width = 120;
  opt.height = 80;
  opt.supersample = 1;
  for (auto proj : {Camera::Projection::Perspective, Camera::Projection::Orthographic})
    for (auto [az, el] : {std::pair{0.f, 0.f}, std::pair{90.f, 30.f}, std::pair{-45.f, 90.f}, std::pair{200.f, -90.f}}) {
      Camera cam = fit_camera(bounding_box(m), az, el, proj, float(opt.width) / opt.height);
      RenderResult r = render(m, cam, opt);
      EXPECT_EQ(r.triangles_clipped, 0u);
      int minx = opt.width, maxx = -1, miny = opt.height, maxy = -1;
      for (int y = 0; y < opt.height; ++y)
        for (int x = 0; x < opt.width; ++x)
          if (r.coverage.at(x, y) > 0) {
            minx = std::min(minx, x);
            maxx = std::max(maxx, x);
            miny = std::min(miny, y);
            maxy = std::max(maxy, y);
          }
      EXPECT_GT(minx, 0) << az << "," << el;
      EXPECT_GT(miny, 0) << az << "," << el;
      EXPECT_LT(maxx, opt.width - 1) << az << "," << el;
      EXPECT_LT(maxy, opt.height - 1) << az << "," << el;
      EXPECT_GT(std::max(maxx - minx, maxy - miny), 30) << az << "," << el;  // not a speck
    }
}

TEST(Rasterizer, LambertShadingIsTwoSided) {
  // One triangle facing the camera and one facing away, both head-on with the light from the camera.
  RenderMesh front, back;
  front.positions = back.positions = {{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}};
  front.triangles = {{0, 1, 2}};
  back.triangles = {{0, 2, 1}};
  RenderOptions opt;
  opt.width = opt.height = 32;
  opt.supersample = 1;
  opt.constant_color = {1, 1, 1};
  opt.ambient = 0.2f;
  opt.light_direction = {0, 0, 1};  // from the viewer
  Camera cam = ortho_camera({0, 0, 4}, {0, 0, 0}, 1.f);
  for (const RenderMesh* m : {&front, &back}) {
    RenderResult r = render(*m, cam, opt);
    EXPECT_NEAR(r.color.at(16, 20, 0), 1.f, 1e-5f);
  }
  // Light at 60 degrees: 0.2 + 0.8 * cos(60) = 0.6.
  opt.light_direction = {float(std::sin(kPi / 3)), 0, 0.5f};
  EXPECT_NEAR(render(back, cam, opt).color.at(16, 20, 0), 0.6f, 1e-5f);
  // Light from behind the surface: ambient only.
  opt.light_direction = {0, 0, -1};
  EXPECT_NEAR(render(front, cam, opt).color.at(16, 20, 0), 0.2f, 1e-5f);
  // Smooth normals on a sphere: the point facing the light is brightest, the rim darker.
  RenderMesh s = sphere(64, 48);
  opt.light_direction = {0, 0, 1};
  RenderResult r = render(s, ortho_camera({0, 0, 4}, {0, 0, 0}, 1.1f), opt);
  EXPECT_NEAR(r.color.at(16, 16, 0), 1.f, 0.01f);
  EXPECT_LT(r.color.at(16, 3, 0), 0.7f);
}

TEST(Rasterizer, RejectsBadInputNamingTheField) {
  RenderMesh m;
  add_quad(m, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  Camera cam;
  RenderOptions opt;
  opt.width = opt.height = 16;
  auto expect_error = [&](const RenderMesh& mm, const Camera& c, const RenderOptions& o, const char* what) {
    try {
      render(mm, c, o);
      ADD_FAILURE() << "no error for " << what;
    } catch (const InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  RenderOptions o = opt;
  o.width = 0;
  expect_error(m, cam, o, "width");
  o = opt;
  o.supersample = 5;
  expect_error(m, cam, o, "supersample");
  o = opt;
  o.color_source = CS::Texture;
  expect_error(m, cam, o, "texture");
  o = opt;
  o.color_source = CS::Callback;
  expect_error(m, cam, o, "callback");
  RenderMesh bad = m;
  bad.triangles[1][2] = 17;
  expect_error(bad, cam, opt, "index 17");
  bad = m;
  bad.positions[2][1] = std::nanf("");
  expect_error(bad, cam, opt, "position 2");
  bad = m;
  bad.vertex_colors.pop_back();
  o = opt;
  o.color_source = CS::VertexColors;
  expect_error(bad, cam, o, "vertex_colors");
  Camera c = cam;
  c.target = c.eye;
  expect_error(m, c, opt, "coincide");
  c = cam;
  c.up = {0, 0, 1};
  expect_error(m, c, opt, "parallel");
  c = cam;
  c.fov_y_deg = 180;
  expect_error(m, c, opt, "fov_y_deg");
  EXPECT_THROW(fit_camera(bounding_box(m), std::nanf(""), 0), InvalidInputError);
  EXPECT_THROW(fit_camera(bounding_box(m), 0, 91), InvalidInputError);
  EXPECT_THROW(bounding_box(RenderMesh{}), InvalidInputError);
}
