// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/rasterizer.h"
#include "geometry/constants.h"
#include "geometry/vec3.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "geometry/errors.h"

namespace surftex {
namespace {

// ---------------------------------------------------------------- vectors
using V3 = std::array<double, 3>;
V3 to_d(const Vec3f& a) { return {a[0], a[1], a[2]}; }
using vec3::add;
using vec3::cross;
using vec3::dot;
using vec3::mul;
using vec3::norm;
using vec3::sub;
bool finite3(const Vec3f& a) {
  return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]);
}
std::string str3(const Vec3f& a) {
  return "(" + std::to_string(a[0]) + ", " + std::to_string(a[1]) + ", " + std::to_string(a[2]) + ")";
}

// ---------------------------------------------------------------- constants
constexpr int kSubBits = 8;                 // fixed point: 1/256 sample
constexpr std::int64_t kOne = 1 << kSubBits;
constexpr std::int64_t kHalf = kOne / 2;    // sample centres sit at half-integers
constexpr double kGuard = 4.0;              // guard band in NDC units: |x/w|, |y/w| <= 4
constexpr int kTileSamples = 64;            // tile edge, in samples (about)

std::int64_t floor_div(std::int64_t a, std::int64_t b) {  // b > 0
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

// Camera frame and projection, resolved once.
struct View {
  V3 eye, right, up, forward;
  bool perspective = true;
  double sx = 1, sy = 1;  // clip X = x_view * sx, Y = y_view * sy
  double near_plane = 0.01;
  V3 light_world;         // unit, towards the light
};

// A vertex in clip space with its barycentric weights w.r.t. the source triangle.
struct ClipVertex {
  double X, Y, Z, W;  // Z = view depth (for the near plane), W = perspective divisor
  float b[3];
};

// A triangle ready for scanning (after clipping, snapping and orientation).
struct ScreenTri {
  std::int64_t x[3], y[3];  // fixed-point sample coordinates
  double inv_area;          // 1 / (twice the signed area), > 0
  float key[3];             // screen-affine depth key, smaller = nearer
  float inv_w[3];           // 1 / W per vertex (1 for orthographic)
  float bary[3][3];         // vertex k's barycentrics in the source triangle
  float normal[3];          // unit face normal, flipped when seen from the back
  int tri;                  // source triangle
  int x0, y0, x1, y1;       // inclusive sample bounds, clamped to the image
  bool back;                // seen from the back: normals are flipped for shading
};

View make_view(const Camera& cam, const RenderOptions& opt) {
  if (!finite3(cam.eye) || !finite3(cam.target) || !finite3(cam.up))
    throw InvalidInputError("camera: eye " + str3(cam.eye) + ", target " + str3(cam.target) +
                            ", up " + str3(cam.up) + " must be finite");
  View v;
  v.eye = to_d(cam.eye);
  V3 f = sub(to_d(cam.target), v.eye);
  double fl = norm(f);
  if (!(fl > 0)) throw InvalidInputError("camera: eye and target coincide at " + str3(cam.eye));
  v.forward = mul(f, 1.0 / fl);
  V3 r = cross(v.forward, to_d(cam.up));
  double rl = norm(r);
  if (!(rl > 1e-9 * std::max(1.0, norm(to_d(cam.up)))))
    throw InvalidInputError("camera: up " + str3(cam.up) + " is zero or parallel to the view direction");
  v.right = mul(r, 1.0 / rl);
  v.up = cross(v.right, v.forward);
  double aspect = static_cast<double>(opt.width) / opt.height;
  if (!std::isfinite(cam.near_plane))
    throw InvalidInputError("camera: near_plane " + std::to_string(cam.near_plane) + " must be finite");
  v.near_plane = cam.near_plane;
  if (cam.projection == Camera::Projection::Perspective) {
    if (!(cam.fov_y_deg > 0.f && cam.fov_y_deg < 180.f))
      throw InvalidInputError("camera: fov_y_deg " + std::to_string(cam.fov_y_deg) +
                              " out of range (0, 180)");
    if (!(cam.near_plane > 0.f))
      throw InvalidInputError("camera: near_plane " + std::to_string(cam.near_plane) +
                              " must be > 0 for a perspective camera");
    double t = std::tan(cam.fov_y_deg * kPi / 360.0);
    v.perspective = true;
    v.sy = 1.0 / t;
    v.sx = 1.0 / (t * aspect);
  } else {
    if (!(cam.ortho_half_height > 0.f) || !std::isfinite(cam.ortho_half_height))
      throw InvalidInputError("camera: ortho_half_height " + std::to_string(cam.ortho_half_height) +
                              " must be finite and > 0");
    v.perspective = false;
    v.sy = 1.0 / cam.ortho_half_height;
    v.sx = 1.0 / (cam.ortho_half_height * aspect);
  }
  V3 l = to_d(opt.light_direction);
  V3 lw = add(add(mul(v.right, l[0]), mul(v.up, l[1])), mul(v.forward, -l[2]));
  double ll = norm(lw);
  if (!(ll > 0) || !std::isfinite(ll))
    throw InvalidInputError("render: light_direction " + str3(opt.light_direction) +
                            " must be finite and non-zero");
  v.light_world = mul(lw, 1.0 / ll);
  return v;
}

void validate(const RenderMesh& mesh, const RenderOptions& opt) {
  auto bad = [](const std::string& m) { throw InvalidInputError("render: " + m); };
  if (opt.width < 1 || opt.width > 16384) bad("width " + std::to_string(opt.width) + " out of range 1..16384");
  if (opt.height < 1 || opt.height > 16384) bad("height " + std::to_string(opt.height) + " out of range 1..16384");
  if (opt.supersample < 1 || opt.supersample > 4)
    bad("supersample " + std::to_string(opt.supersample) + " out of range 1..4");
  if (!(opt.ambient >= 0.f && opt.ambient <= 1.f)) bad("ambient " + std::to_string(opt.ambient) + " out of range [0,1]");
  if (!finite3(opt.background)) bad("background " + str3(opt.background) + " must be finite");
  if (!finite3(opt.constant_color)) bad("constant_color " + str3(opt.constant_color) + " must be finite");
  const std::size_t nv = mesh.positions.size(), nt = mesh.triangles.size();
  if (nv > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
      nt > static_cast<std::size_t>(std::numeric_limits<int>::max() / 3))
    bad("mesh too large (" + std::to_string(nv) + " positions, " + std::to_string(nt) + " triangles)");
  for (std::size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      int i = mesh.triangles[t][k];
      if (i < 0 || static_cast<std::size_t>(i) >= nv)
        bad("triangle " + std::to_string(t) + " corner " + std::to_string(k) + " index " +
            std::to_string(i) + " out of range [0," + std::to_string(nv) + ")");
    }
  for (std::size_t i = 0; i < nv; ++i)
    if (!finite3(mesh.positions[i])) bad("position " + std::to_string(i) + " " + str3(mesh.positions[i]) + " is not finite");
  if (!mesh.vertex_normals.empty() && mesh.vertex_normals.size() != nv)
    bad("vertex_normals has " + std::to_string(mesh.vertex_normals.size()) + " entries, expected " + std::to_string(nv));
  if (!mesh.triangle_face.empty() && mesh.triangle_face.size() != nt)
    bad("triangle_face has " + std::to_string(mesh.triangle_face.size()) + " entries, expected " + std::to_string(nt));
  using CS = RenderOptions::ColorSource;
  switch (opt.color_source) {
    case CS::Constant: break;
    case CS::VertexColors:
      if (mesh.vertex_colors.size() != nv)
        bad("vertex colours requested but vertex_colors has " + std::to_string(mesh.vertex_colors.size()) +
            " entries for " + std::to_string(nv) + " positions");
      break;
    case CS::Texture:
      if (!opt.texture || opt.texture->empty()) bad("texture colours requested but no texture given");
      if (opt.texture->data.size() != static_cast<std::size_t>(opt.texture->width) * opt.texture->height * opt.texture->channels)
        bad("texture data size does not match its dimensions");
      if (mesh.corner_uvs.size() != 3 * nt)
        bad("texture colours requested but corner_uvs has " + std::to_string(mesh.corner_uvs.size()) +
            " entries, expected 3 x " + std::to_string(nt) + " triangles");
      for (std::size_t i = 0; i < mesh.corner_uvs.size(); ++i)
        if (!std::isfinite(mesh.corner_uvs[i][0]) || !std::isfinite(mesh.corner_uvs[i][1]))
          bad("corner uv " + std::to_string(i) + " is not finite");
      break;
    case CS::Callback:
      if (!opt.callback) bad("callback colours requested but no callback given");
      break;
  }
}

// Sutherland-Hodgman against one plane: keeps d(v) >= 0.
template <class Dist>
int clip_polygon(const ClipVertex* in, int n, ClipVertex* out, Dist dist) {
  int m = 0;
  for (int i = 0; i < n; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % n];
    double da = dist(a), db = dist(b);
    if (da >= 0) out[m++] = a;
    if ((da >= 0) != (db >= 0)) {
      double t = da / (da - db);
      ClipVertex c;
      c.X = a.X + t * (b.X - a.X);
      c.Y = a.Y + t * (b.Y - a.Y);
      c.Z = a.Z + t * (b.Z - a.Z);
      c.W = a.W + t * (b.W - a.W);
      for (int k = 0; k < 3; ++k) c.b[k] = static_cast<float>(a.b[k] + t * (b.b[k] - a.b[k]));
      out[m++] = c;
    }
  }
  return m;
}

class Renderer {
 public:
  Renderer(const RenderMesh& mesh, const Camera& cam, const RenderOptions& opt)
      : mesh_(mesh), opt_(opt), view_(make_view(cam, opt)) {
    N_ = opt.supersample;
    ws_ = opt.width * N_;
    hs_ = opt.height * N_;
    tile_px_ = std::max(8, kTileSamples / N_);
    tile_s_ = tile_px_ * N_;
    tiles_x_ = (opt.width + tile_px_ - 1) / tile_px_;
    tiles_y_ = (opt.height + tile_px_ - 1) / tile_px_;
  }

  RenderResult run() {
    transform_vertices();
    setup_triangles();
    bin_triangles();
    RenderResult res;
    res.color = Image(opt_.width, opt_.height, 3);
    res.depth = Image(opt_.width, opt_.height, 1);
    res.coverage = Image(opt_.width, opt_.height, 1);
    res.triangles_drawn = tris_.size();
    res.triangles_clipped = clipped_count_;
    std::vector<std::size_t> tile_fragments(ntiles_, 0);
    tbb::enumerable_thread_specific<TileBuffer> buffers;
    tbb::parallel_for(tbb::blocked_range<int>(0, static_cast<int>(ntiles_)),
                      [&](const tbb::blocked_range<int>& r) {
                        TileBuffer& buf = buffers.local();
                        for (int t = r.begin(); t != r.end(); ++t)
                          tile_fragments[t] = render_tile(t, buf, res);
                      });
    for (std::size_t f : tile_fragments) res.fragments += f;
    return res;
  }

 private:
  struct TileBuffer {
    std::vector<float> key, l1, l2;
    std::vector<int> id;
  };

  void transform_vertices() {
    const std::size_t n = mesh_.positions.size();
    clip_.resize(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        V3 d = sub(to_d(mesh_.positions[i]), view_.eye);
        double x = dot(d, view_.right), y = dot(d, view_.up), z = dot(d, view_.forward);
        ClipVertex& c = clip_[i];
        c.X = x * view_.sx;
        c.Y = y * view_.sy;
        c.Z = z;
        c.W = view_.perspective ? z : 1.0;
      }
    });
  }

  // Clips, projects, snaps and orients triangle t; appends the results to `out`.
  void setup_one(int t, std::vector<ScreenTri>& out, std::size_t& clipped) const {
    const auto& tri = mesh_.triangles[t];
    ClipVertex poly[2][16];
    int n = 3;
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      poly[0][k] = clip_[tri[k]];
      for (int j = 0; j < 3; ++j) poly[0][k].b[j] = (j == k) ? 1.f : 0.f;
      const ClipVertex& c = poly[0][k];
      if (c.Z < view_.near_plane || std::abs(c.X) > kGuard * c.W || std::abs(c.Y) > kGuard * c.W)
        inside = false;
    }
    // Face normal (world) and facing, from the unclipped triangle.
    V3 p0 = to_d(mesh_.positions[tri[0]]), p1 = to_d(mesh_.positions[tri[1]]),
       p2 = to_d(mesh_.positions[tri[2]]);
    V3 fn = cross(sub(p1, p0), sub(p2, p0));
    double fl = norm(fn);
    fn = fl > 0 ? mul(fn, 1.0 / fl) : V3{0, 0, 0};
    V3 to_eye = view_.perspective ? sub(view_.eye, p0) : mul(view_.forward, -1.0);
    const bool back = dot(fn, to_eye) < 0;
    if (back) fn = mul(fn, -1.0);

    int cur = 0;
    if (!inside) {
      ++clipped;
      const double nearp = view_.near_plane;
      n = clip_polygon(poly[cur], n, poly[1 - cur], [nearp](const ClipVertex& v) { return v.Z - nearp; });
      cur = 1 - cur;
      n = clip_polygon(poly[cur], n, poly[1 - cur], [](const ClipVertex& v) { return kGuard * v.W - v.X; });
      cur = 1 - cur;
      n = clip_polygon(poly[cur], n, poly[1 - cur], [](const ClipVertex& v) { return kGuard * v.W + v.X; });
      cur = 1 - cur;
      n = clip_polygon(poly[cur], n, poly[1 - cur], [](const ClipVertex& v) { return kGuard * v.W - v.Y; });
      cur = 1 - cur;
      n = clip_polygon(poly[cur], n, poly[1 - cur], [](const ClipVertex& v) { return kGuard * v.W + v.Y; });
      cur = 1 - cur;
      if (n < 3) return;
    }
    const ClipVertex* P = poly[cur];
    // Project and snap every polygon vertex once.
    std::int64_t fx[16], fy[16];
    float key[16], iw[16];
    for (int k = 0; k < n; ++k) {
      double inv_w = 1.0 / P[k].W;
      double sx = (P[k].X * inv_w * 0.5 + 0.5) * ws_;
      double sy = (0.5 - P[k].Y * inv_w * 0.5) * hs_;
      fx[k] = std::llround(sx * kOne);
      fy[k] = std::llround(sy * kOne);
      iw[k] = view_.perspective ? static_cast<float>(inv_w) : 1.f;
      key[k] = view_.perspective ? static_cast<float>(-inv_w) : static_cast<float>(P[k].Z);
    }
    for (int k = 1; k + 1 < n; ++k) {  // fan
      int idx[3] = {0, k, k + 1};
      std::int64_t area = (fx[idx[1]] - fx[idx[0]]) * (fy[idx[2]] - fy[idx[0]]) -
                          (fy[idx[1]] - fy[idx[0]]) * (fx[idx[2]] - fx[idx[0]]);
      if (area == 0) continue;
      if (area < 0) {
        std::swap(idx[1], idx[2]);
        area = -area;
      }
      ScreenTri s;
      std::int64_t minx = INT64_MAX, maxx = INT64_MIN, miny = INT64_MAX, maxy = INT64_MIN;
      for (int j = 0; j < 3; ++j) {
        int v = idx[j];
        s.x[j] = fx[v];
        s.y[j] = fy[v];
        s.key[j] = key[v];
        s.inv_w[j] = iw[v];
        for (int q = 0; q < 3; ++q) s.bary[j][q] = P[v].b[q];
        minx = std::min(minx, fx[v]);
        maxx = std::max(maxx, fx[v]);
        miny = std::min(miny, fy[v]);
        maxy = std::max(maxy, fy[v]);
      }
      // Samples whose centre (i + 1/2) may lie inside.
      std::int64_t x0 = std::max<std::int64_t>(0, floor_div(minx - kHalf + kOne - 1, kOne));
      std::int64_t x1 = std::min<std::int64_t>(ws_ - 1, floor_div(maxx - kHalf, kOne));
      std::int64_t y0 = std::max<std::int64_t>(0, floor_div(miny - kHalf + kOne - 1, kOne));
      std::int64_t y1 = std::min<std::int64_t>(hs_ - 1, floor_div(maxy - kHalf, kOne));
      if (x0 > x1 || y0 > y1) continue;
      s.x0 = static_cast<int>(x0);
      s.x1 = static_cast<int>(x1);
      s.y0 = static_cast<int>(y0);
      s.y1 = static_cast<int>(y1);
      s.inv_area = 1.0 / static_cast<double>(area);
      for (int q = 0; q < 3; ++q) s.normal[q] = static_cast<float>(fn[q]);
      s.tri = t;
      s.back = back;
      out.push_back(s);
    }
  }

  void setup_triangles() {
    const int nt = static_cast<int>(mesh_.triangles.size());
    constexpr int kChunk = 4096;
    const int nchunks = (nt + kChunk - 1) / kChunk;
    std::vector<std::vector<ScreenTri>> parts(nchunks);
    std::vector<std::size_t> clipped(nchunks, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, nchunks), [&](const tbb::blocked_range<int>& r) {
      for (int c = r.begin(); c != r.end(); ++c) {
        parts[c].reserve(kChunk);
        for (int t = c * kChunk, e = std::min(nt, (c + 1) * kChunk); t < e; ++t)
          setup_one(t, parts[c], clipped[c]);
      }
    });
    std::size_t total = 0;
    for (auto& p : parts) total += p.size();
    tris_.reserve(total);
    for (int c = 0; c < nchunks; ++c) {
      tris_.insert(tris_.end(), parts[c].begin(), parts[c].end());
      clipped_count_ += clipped[c];
    }
  }

  // Counting sort of screen triangles into tiles, keeping index order per tile.
  void bin_triangles() {
    const std::size_t ntiles = static_cast<std::size_t>(tiles_x_) * tiles_y_;
    bin_start_.assign(ntiles + 1, 0);
    auto for_tiles = [&](const ScreenTri& s, auto&& f) {
      for (int ty = s.y0 / tile_s_; ty <= s.y1 / tile_s_; ++ty)
        for (int tx = s.x0 / tile_s_; tx <= s.x1 / tile_s_; ++tx) f(static_cast<std::size_t>(ty) * tiles_x_ + tx);
    };
    for (const ScreenTri& s : tris_) for_tiles(s, [&](std::size_t b) { ++bin_start_[b + 1]; });
    for (std::size_t b = 0; b < ntiles; ++b) bin_start_[b + 1] += bin_start_[b];
    bin_items_.resize(bin_start_[ntiles]);
    std::vector<std::size_t> fill(bin_start_.begin(), bin_start_.end() - 1);
    for (std::size_t i = 0; i < tris_.size(); ++i)
      for_tiles(tris_[i], [&](std::size_t b) { bin_items_[fill[b]++] = static_cast<int>(i); });
    ntiles_ = ntiles;
  }

  // Scans triangle `s` over the sample rectangle [sx0,sx1] x [sy0,sy1] of the tile.
  std::size_t scan(const ScreenTri& s, int id, int sx0, int sy0, int sx1, int sy1, int tile_x0,
                   int tile_y0, int stride, TileBuffer& buf) const {
    std::int64_t A[3], B[3], E[3];
    // Edge i is opposite vertex i: from vertex (i+1) to vertex (i+2).
    const std::int64_t px = static_cast<std::int64_t>(sx0) * kOne + kHalf;
    const std::int64_t py = static_cast<std::int64_t>(sy0) * kOne + kHalf;
    for (int i = 0; i < 3; ++i) {
      int a = (i + 1) % 3, b = (i + 2) % 3;
      std::int64_t dx = s.x[b] - s.x[a], dy = s.y[b] - s.y[a];
      A[i] = -dy * kOne;  // step per sample in x
      B[i] = dx * kOne;   // step per sample in y
      E[i] = dx * (py - s.y[a]) - dy * (px - s.x[a]);
      // Top-left fill rule: a sample exactly on an edge belongs to one side
      // only. In sample space (y down) with positive area, top edges run
      // dx > 0, dy == 0 and left edges dy < 0; each direction of an edge is
      // owned iff its reverse is not, so shared edges are drawn exactly once.
      bool owned = dy < 0 || (dy == 0 && dx > 0);
      if (!owned) E[i] -= 1;  // strict inequality on non-owned edges
    }
    const float k0 = s.key[0], dk1 = s.key[1] - s.key[0], dk2 = s.key[2] - s.key[0];
    std::size_t count = 0;
    for (int y = sy0; y <= sy1; ++y) {
      std::int64_t e0 = E[0], e1 = E[1], e2 = E[2];
      std::size_t row = static_cast<std::size_t>(y - tile_y0) * stride;
      for (int x = sx0; x <= sx1; ++x) {
        if ((e0 | e1 | e2) >= 0) {
          ++count;
          // (The fill-rule bias of one unit is far below float precision here.)
          float l1 = static_cast<float>(static_cast<double>(e1) * s.inv_area);
          float l2 = static_cast<float>(static_cast<double>(e2) * s.inv_area);
          float k = k0 + l1 * dk1 + l2 * dk2;
          std::size_t o = row + (x - tile_x0);
          if (k < buf.key[o]) {
            buf.key[o] = k;
            buf.id[o] = id;
            buf.l1[o] = l1;
            buf.l2[o] = l2;
          }
        }
        e0 += A[0];
        e1 += A[1];
        e2 += A[2];
      }
      E[0] += B[0];
      E[1] += B[1];
      E[2] += B[2];
    }
    return count;
  }

  Vec3f shade_sample(const ScreenTri& s, float l1, float l2) const {
    // Perspective-correct barycentrics in the screen triangle, then in the source triangle.
    float l[3] = {1.f - l1 - l2, l1, l2};
    float q[3], sum = 0.f;
    for (int i = 0; i < 3; ++i) {
      q[i] = std::max(0.f, l[i]) * s.inv_w[i];
      sum += q[i];
    }
    Vec3f b;
    if (sum > 0.f) {
      for (int i = 0; i < 3; ++i) q[i] /= sum;
    } else {
      q[0] = q[1] = q[2] = 1.f / 3.f;
    }
    for (int j = 0; j < 3; ++j) b[j] = q[0] * s.bary[0][j] + q[1] * s.bary[1][j] + q[2] * s.bary[2][j];
    const auto& tri = mesh_.triangles[s.tri];
    using CS = RenderOptions::ColorSource;
    Vec3f base;
    switch (opt_.color_source) {
      case CS::Constant: base = opt_.constant_color; break;
      case CS::VertexColors: {
        base = {0.f, 0.f, 0.f};
        for (int j = 0; j < 3; ++j)
          for (int c = 0; c < 3; ++c) base[c] += b[j] * mesh_.vertex_colors[tri[j]][c];
        break;
      }
      case CS::Texture: {
        float u = 0.f, v = 0.f;
        for (int j = 0; j < 3; ++j) {
          u += b[j] * mesh_.corner_uvs[3 * static_cast<std::size_t>(s.tri) + j][0];
          v += b[j] * mesh_.corner_uvs[3 * static_cast<std::size_t>(s.tri) + j][1];
        }
        base = sample_texture(*opt_.texture, u, v, opt_.wrap);
        break;
      }
      case CS::Callback: base = opt_.callback(s.tri, b); break;
    }
    if (!opt_.shade) return base;
    V3 n{s.normal[0], s.normal[1], s.normal[2]};
    if (!mesh_.vertex_normals.empty()) {
      V3 m{0, 0, 0};
      for (int j = 0; j < 3; ++j) m = add(m, mul(to_d(mesh_.vertex_normals[tri[j]]), b[j]));
      double ml = norm(m);
      if (ml > 0) {
        n = mul(m, (s.back ? -1.0 : 1.0) / ml);  // two-sided: flipped with the face
      }
    }
    double lambert = std::max(0.0, dot(n, view_.light_world));
    float f = static_cast<float>(opt_.ambient + (1.0 - opt_.ambient) * lambert);
    return {base[0] * f, base[1] * f, base[2] * f};
  }

  std::size_t render_tile(int t, TileBuffer& buf, RenderResult& res) const {
    const int tx = t % tiles_x_, ty = t / tiles_x_;
    const int px0 = tx * tile_px_, py0 = ty * tile_px_;
    const int px1 = std::min(opt_.width, px0 + tile_px_), py1 = std::min(opt_.height, py0 + tile_px_);
    const int sx0 = px0 * N_, sy0 = py0 * N_, sx1 = px1 * N_ - 1, sy1 = py1 * N_ - 1;
    const int stride = tile_s_;
    const std::size_t ns = static_cast<std::size_t>(tile_s_) * tile_s_;
    buf.key.assign(ns, std::numeric_limits<float>::infinity());
    buf.id.assign(ns, -1);
    buf.l1.resize(ns);
    buf.l2.resize(ns);
    std::size_t count = 0;
    for (std::size_t i = bin_start_[t]; i < bin_start_[t + 1]; ++i) {
      const int id = bin_items_[i];
      const ScreenTri& s = tris_[id];
      int ax0 = std::max(s.x0, sx0), ax1 = std::min(s.x1, sx1);
      int ay0 = std::max(s.y0, sy0), ay1 = std::min(s.y1, sy1);
      if (ax0 > ax1 || ay0 > ay1) continue;
      count += scan(s, id, ax0, ay0, ax1, ay1, sx0, sy0, stride, buf);
    }
    const float inv_n2 = 1.f / static_cast<float>(N_ * N_);
    for (int py = py0; py < py1; ++py)
      for (int px = px0; px < px1; ++px) {
        float acc[3] = {0.f, 0.f, 0.f};
        int covered = 0;
        float depth = std::numeric_limits<float>::infinity();
        for (int j = 0; j < N_; ++j)
          for (int i = 0; i < N_; ++i) {
            std::size_t o = static_cast<std::size_t>((py - py0) * N_ + j) * stride + (px - px0) * N_ + i;
            Vec3f c;
            if (buf.id[o] >= 0) {
              ++covered;
              c = shade_sample(tris_[buf.id[o]], buf.l1[o], buf.l2[o]);
              float d = view_.perspective ? -1.f / buf.key[o] : buf.key[o];
              depth = std::min(depth, d);
            } else {
              c = opt_.background;
            }
            for (int k = 0; k < 3; ++k) acc[k] += c[k];
          }
        for (int k = 0; k < 3; ++k) res.color.at(px, py, k) = acc[k] * inv_n2;
        res.coverage.at(px, py) = static_cast<float>(covered) * inv_n2;
        res.depth.at(px, py) = depth;
      }
    return count;
  }

  const RenderMesh& mesh_;
  const RenderOptions& opt_;
  View view_;
  int N_, ws_, hs_, tile_px_, tile_s_, tiles_x_, tiles_y_;
  std::vector<ClipVertex> clip_;
  std::vector<ScreenTri> tris_;
  std::size_t clipped_count_ = 0;
  std::size_t ntiles_ = 0;
  std::vector<std::size_t> bin_start_;  // tile t draws bin_items_[bin_start_[t] .. bin_start_[t+1])
  std::vector<int> bin_items_;          // indices into tris_, ascending per tile
};

}  // namespace

BBox3f bounding_box(const RenderMesh& mesh) {
  if (mesh.positions.empty()) throw InvalidInputError("bounding_box: mesh has no positions");
  BBox3f b{mesh.positions[0], mesh.positions[0]};
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3f& p = mesh.positions[i];
    if (!finite3(p)) throw InvalidInputError("bounding_box: position " + std::to_string(i) + " " + str3(p) + " is not finite");
    for (int k = 0; k < 3; ++k) {
      b.min[k] = std::min(b.min[k], p[k]);
      b.max[k] = std::max(b.max[k], p[k]);
    }
  }
  return b;
}

Camera fit_camera(const BBox3f& box, float azimuth_deg, float elevation_deg, Camera::Projection projection,
                  float aspect) {
  if (!std::isfinite(azimuth_deg)) throw InvalidInputError("fit_camera: azimuth " + std::to_string(azimuth_deg) + " is not finite");
  if (!(elevation_deg >= -90.f && elevation_deg <= 90.f))
    throw InvalidInputError("fit_camera: elevation " + std::to_string(elevation_deg) + " out of range [-90, 90]");
  if (!(aspect > 0.f) || !std::isfinite(aspect))
    throw InvalidInputError("fit_camera: aspect " + std::to_string(aspect) + " must be finite and > 0");
  if (!finite3(box.min) || !finite3(box.max))
    throw InvalidInputError("fit_camera: box " + str3(box.min) + " - " + str3(box.max) + " is not finite");
  V3 lo = to_d(box.min), hi = to_d(box.max);
  V3 c = mul(add(lo, hi), 0.5);
  double r = 0.5 * norm(sub(hi, lo));
  if (!(r > 0)) r = 1.0;
  const double az = azimuth_deg * kPi / 180.0, el = elevation_deg * kPi / 180.0;
  V3 d{std::sin(az) * std::cos(el), std::sin(el), std::cos(az) * std::cos(el)};   // centre -> eye
  V3 up{-std::sin(az) * std::sin(el), std::cos(el), -std::cos(az) * std::sin(el)};  // d/d(elevation)
  const double margin = 1.05;
  const V3 right = cross(mul(d, -1.0), up);  // forward x up
  // The eight box corners in the camera frame around the box centre (z towards the eye).
  double max_x = 0, max_y = 0, max_z = -r;
  V3 corner_xyz[8];
  for (int i = 0; i < 8; ++i) {
    V3 p{(i & 1) ? hi[0] : lo[0], (i & 2) ? hi[1] : lo[1], (i & 4) ? hi[2] : lo[2]};
    V3 q = sub(p, c);
    corner_xyz[i] = {dot(q, right), dot(q, up), dot(q, d)};
    max_x = std::max(max_x, std::abs(corner_xyz[i][0]));
    max_y = std::max(max_y, std::abs(corner_xyz[i][1]));
    max_z = std::max(max_z, corner_xyz[i][2]);
  }
  Camera cam;
  cam.projection = projection;
  double dist;
  if (projection == Camera::Projection::Perspective) {
    // Nearest eye distance that keeps every corner inside the frustum, with the margin.
    const double tan_v = std::tan(cam.fov_y_deg * kPi / 360.0), tan_h = tan_v * aspect;
    dist = 0;
    for (const V3& q : corner_xyz)
      dist = std::max({dist, q[2] + margin * std::abs(q[0]) / tan_h, q[2] + margin * std::abs(q[1]) / tan_v});
    dist = std::max(dist, max_z + 1e-3 * r);
    cam.near_plane = static_cast<float>(std::max(0.5 * (dist - max_z), 1e-4 * r));
  } else {
    cam.ortho_half_height = static_cast<float>(margin * std::max({max_y, max_x / aspect, 1e-6 * r}));
    dist = max_z + r;
    cam.near_plane = static_cast<float>(0.5 * r);
  }
  V3 eye = add(c, mul(d, dist));
  cam.eye = {static_cast<float>(eye[0]), static_cast<float>(eye[1]), static_cast<float>(eye[2])};
  cam.target = {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
  cam.up = {static_cast<float>(up[0]), static_cast<float>(up[1]), static_cast<float>(up[2])};
  return cam;
}

namespace {

// A texture coordinate (texel units after * size) brought into the range its
// wrap reads: one period for Repeat, two (there and back) for Mirror.
double wrap_coordinate(double t, RenderOptions::Wrap wrap) {
  switch (wrap) {
    case RenderOptions::Wrap::Repeat: return t - std::floor(t);
    case RenderOptions::Wrap::Mirror: return t - 2.0 * std::floor(t / 2.0);
    case RenderOptions::Wrap::Clamp: break;
  }
  return std::clamp(t, 0.0, 1.0);
}

// A texel index of the bilinear footprint, wrapped like its coordinate.
int wrap_index(int i, int n, RenderOptions::Wrap wrap) {
  switch (wrap) {
    case RenderOptions::Wrap::Repeat: return ((i % n) + n) % n;
    case RenderOptions::Wrap::Mirror: {
      const int k = ((i % (2 * n)) + 2 * n) % (2 * n);
      return k < n ? k : 2 * n - 1 - k;
    }
    case RenderOptions::Wrap::Clamp: break;
  }
  return std::clamp(i, 0, n - 1);
}

}  // namespace

Vec3f sample_texture(const Image& tex, float u, float v, RenderOptions::Wrap wrap) {
  return sample_texture(tex, u, v, wrap, wrap);
}

Vec3f sample_texture(const Image& tex, float u, float v, RenderOptions::Wrap wrap_u, RenderOptions::Wrap wrap_v) {
  const int w = tex.width, h = tex.height;
  // Rows run down from v = 1 (t = 1 - v, glTF's coordinate), so t is wrapped.
  const double uu = wrap_coordinate(u, wrap_u), vv = wrap_coordinate(1.0 - static_cast<double>(v), wrap_v);
  double x = uu * w - 0.5, y = vv * h - 0.5;
  double fx0 = std::floor(x), fy0 = std::floor(y);
  float ax = static_cast<float>(x - fx0), ay = static_cast<float>(y - fy0);
  int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0), x1 = x0 + 1, y1 = y0 + 1;
  x0 = wrap_index(x0, w, wrap_u);
  x1 = wrap_index(x1, w, wrap_u);
  y0 = wrap_index(y0, h, wrap_v);
  y1 = wrap_index(y1, h, wrap_v);
  Vec3f out;
  const int nc = tex.channels;
  for (int c = 0; c < 3; ++c) {
    int cc = nc >= 3 ? c : 0;
    float a = tex.at(x0, y0, cc) * (1 - ax) + tex.at(x1, y0, cc) * ax;
    float b = tex.at(x0, y1, cc) * (1 - ax) + tex.at(x1, y1, cc) * ax;
    out[c] = a * (1 - ay) + b * ay;
  }
  return out;
}

RenderResult render(const RenderMesh& mesh, const Camera& camera, const RenderOptions& options) {
  validate(mesh, options);
  Renderer r(mesh, camera, options);
  return r.run();
}

}  // namespace surftex
