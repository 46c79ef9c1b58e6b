// SPDX-License-Identifier: AGPL-3.0-or-later
// Surface fidelity (issue 18 item 3). See surface_fidelity.h.
#include "texture/surface_fidelity.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numeric>
#include <random>
#include <string>
#include <unordered_map>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/polygon_util.h"
#include "geometry/properties.h"
#include "geometry/timer.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"
#include "texture/graphcut_synthesis.h"
#include "texture/image_ops.h"
#include "texture/material_space/material_tile_io.h"

namespace surftex {
namespace {

using V3 = std::array<double, 3>;
using vec3::add;
using vec3::cross;
using vec3::dot;
using vec3::mul;
using vec3::norm;
using vec3::sub;
inline V3 point(const Mesh& m, VertexIndex v) { return {m.point(v).x(), m.point(v).y(), m.point(v).z()}; }

void fail(const std::string& m) { throw InvalidInputError("surface_fidelity: " + m); }

// The fan triangles of every face (corner 0 = target(halfedge(f)), then i, i+1).
struct FanTriangle {
  std::size_t face = 0;
  std::array<std::size_t, 3> corner{}, vertex{};
  std::array<V3, 3> p{};
  V3 n{};          // unit normal (0 for a degenerate triangle)
  double area = 0;
};

std::vector<FanTriangle> fan_triangles(const Mesh& mesh) {
  // Triangles before each face (its degree - 2 each), then every face's fan in parallel.
  std::vector<std::size_t> first(mesh.number_of_faces() + 1, 0);
  for (FaceIndex f : mesh.faces()) first[f.idx() + 1] = std::max<std::size_t>(mesh.degree(f), 2) - 2;
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<FanTriangle> tris(first.back());
  tbb::parallel_for(std::size_t(0), std::size_t(mesh.number_of_faces()), [&](std::size_t fi) {
    const FaceIndex f(static_cast<std::uint32_t>(fi));
    if (first[fi + 1] == first[fi]) return;
    const HalfedgeIndex h0 = mesh.halfedge(f);
    HalfedgeIndex hi = mesh.next(h0);
    for (std::size_t k = first[fi]; k < first[fi + 1]; ++k, hi = mesh.next(hi)) {
      FanTriangle& t = tris[k];
      t.face = fi;
      const HalfedgeIndex c[3] = {h0, hi, mesh.next(hi)};
      for (int j = 0; j < 3; ++j) {
        t.corner[j] = c[j].idx();
        t.vertex[j] = mesh.target(c[j]).idx();
        t.p[j] = point(mesh, mesh.target(c[j]));
      }
      const V3 nn = cross(sub(t.p[1], t.p[0]), sub(t.p[2], t.p[0]));
      const double l = norm(nn);
      t.area = 0.5 * l;
      if (l > 0 && std::isfinite(l)) t.n = mul(nn, 1.0 / l);
    }
  });
  return tris;
}

// Triangles sharing an edge (by vertex pair), CSR.
struct Adjacency {
  std::vector<std::uint32_t> offset, next;
};

Adjacency triangle_adjacency(const std::vector<FanTriangle>& tris) {
  // (edge key, triangle) for every side, sorted: the triangles of an edge are one run.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> sides(3 * tris.size());
  tbb::parallel_for(std::size_t(0), tris.size(), [&](std::size_t t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = tris[t].vertex[k], b = tris[t].vertex[(k + 1) % 3];
      sides[3 * t + k] = {(std::min(a, b) << 32) | std::max(a, b), static_cast<std::uint32_t>(t)};
    }
  });
  tbb::parallel_sort(sides.begin(), sides.end());
  // Every ordered pair of distinct triangles of a run, sorted by (from, to).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  pairs.reserve(sides.size());
  for (std::size_t i = 0; i < sides.size();) {
    std::size_t j = i;
    while (j < sides.size() && sides[j].first == sides[i].first) ++j;
    for (std::size_t a = i; a < j; ++a)
      for (std::size_t b = i; b < j; ++b)
        if (sides[a].second != sides[b].second) pairs.push_back({sides[a].second, sides[b].second});
    i = j;
  }
  tbb::parallel_sort(pairs.begin(), pairs.end());
  Adjacency adj;
  adj.offset.assign(tris.size() + 1, 0);
  adj.next.resize(pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    ++adj.offset[pairs[k].first + 1];
    adj.next[k] = pairs[k].second;
  }
  std::partial_sum(adj.offset.begin(), adj.offset.end(), adj.offset.begin());
  return adj;
}

// One chart: its frame and the per-pixel surface point (or none).
struct Chart {
  V3 origin{}, ex{}, ey{}, n{};
  std::vector<int> tri;                  // fan triangle per pixel, -1 = invalid
  std::vector<std::array<float, 3>> bary;
  std::size_t valid = 0;
};

// Chart frame at triangle t: the seed normal, the frame's x projected onto
// the tangent plane, y the frame's y made orthogonal to x (its sign kept).
bool chart_frame(const FanTriangle& t, const TextureFrames& fr, Chart& c) {
  if (norm(t.n) == 0) return false;
  c.n = t.n;
  V3 x = fr.x_axis[t.face], y = fr.y_axis[t.face];
  x = sub(x, mul(c.n, dot(x, c.n)));
  const double lx = norm(x);
  if (!(lx > 1e-12) || !std::isfinite(lx)) return false;
  c.ex = mul(x, 1.0 / lx);
  y = sub(y, mul(c.n, dot(y, c.n)));
  y = sub(y, mul(c.ex, dot(y, c.ex)));
  const double ly = norm(y);
  if (!(ly > 1e-12) || !std::isfinite(ly)) {
    c.ey = cross(c.ex, c.n);  // no y given: the subdivision/patch convention
  } else {
    c.ey = mul(y, 1.0 / ly);
  }
  return true;
}

// Grows the chart's triangles from `seed` (edge-connected, normal cone, the
// projection meets the window) and rasterises them at texel size h.
void rasterize_chart(const std::vector<FanTriangle>& tris, const Adjacency& adj, std::size_t seed, double h, int C,
                     double cos_max, Chart& c, std::vector<int>& mark, int stamp) {
  const std::size_t N = static_cast<std::size_t>(C) * C;
  c.tri.assign(N, -1);
  c.bary.assign(N, {0, 0, 0});
  std::vector<char> strict(N, 0);  // a pixel strictly inside its triangle
  std::vector<char> fold(N, 0);
  std::vector<std::size_t> queue{seed};
  mark[seed] = stamp;
  auto to_px = [&](const V3& p) {
    const V3 d = sub(p, c.origin);
    return std::array<double, 2>{dot(d, c.ex) / h + 0.5 * C, dot(d, c.ey) / h + 0.5 * C};
  };
  for (std::size_t qi = 0; qi < queue.size(); ++qi) {
    const std::size_t t = queue[qi];
    const FanTriangle& tr = tris[t];
    std::array<std::array<double, 2>, 3> q;
    for (int k = 0; k < 3; ++k) q[k] = to_px(tr.p[k]);
    const double x0 = std::min({q[0][0], q[1][0], q[2][0]}), x1 = std::max({q[0][0], q[1][0], q[2][0]});
    const double y0 = std::min({q[0][1], q[1][1], q[2][1]}), y1 = std::max({q[0][1], q[1][1], q[2][1]});
    if (x1 < 0 || y1 < 0 || x0 > C || y0 > C) continue;  // off the window: not grown further
    const double area2 = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
    if (std::abs(area2) > 1e-14) {
      const int ix0 = std::max(0, static_cast<int>(std::floor(x0 - 0.5))), ix1 = std::min(C - 1, static_cast<int>(std::ceil(x1)));
      const int iy0 = std::max(0, static_cast<int>(std::floor(y0 - 0.5))), iy1 = std::min(C - 1, static_cast<int>(std::ceil(y1)));
      for (int y = iy0; y <= iy1; ++y)
        for (int x = ix0; x <= ix1; ++x) {
          const double px = x + 0.5, py = y + 0.5;
          const double b1 = ((px - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (py - q[0][1])) / area2;
          const double b2 = ((q[1][0] - q[0][0]) * (py - q[0][1]) - (px - q[0][0]) * (q[1][1] - q[0][1])) / area2;
          const double b0 = 1.0 - b1 - b2;
          const double mn = std::min({b0, b1, b2});
          if (mn < -1e-9) continue;
          const std::size_t i = static_cast<std::size_t>(y) * C + x;
          const bool inside = mn > 1e-6;
          if (c.tri[i] >= 0) {
            if (inside && strict[i]) fold[i] = 1;  // two triangles overlap here
            if (!inside || strict[i]) continue;
          }
          c.tri[i] = static_cast<int>(t);
          c.bary[i] = {static_cast<float>(b0), static_cast<float>(b1), static_cast<float>(b2)};
          strict[i] = inside;
        }
    }
    for (std::uint32_t k = adj.offset[t]; k < adj.offset[t + 1]; ++k) {
      const std::uint32_t u = adj.next[k];
      if (mark[u] == stamp || dot(tris[u].n, c.n) < cos_max) continue;
      mark[u] = stamp;
      queue.push_back(u);
    }
  }
  c.valid = 0;
  for (std::size_t i = 0; i < N; ++i) {
    if (fold[i]) c.tri[i] = -1;
    if (c.tri[i] >= 0) ++c.valid;
  }
}

// Seeded chart placement: area-weighted random points at least one chart
// side apart (3D), each rasterised; charts with too few valid pixels dropped.
std::vector<Chart> place_charts(const std::vector<FanTriangle>& tris, const Adjacency& adj, const TextureFrames& fr,
                                const SurfaceFidelityOptions& o) {
  std::vector<double> cum(tris.size());
  double total = 0;
  for (std::size_t t = 0; t < tris.size(); ++t) cum[t] = total += tris[t].area;
  if (!(total > 0)) fail("the mesh has no area");
  const double side = o.chart_texels * o.texel_size;
  const double cos_max = std::cos(o.max_normal_angle_deg * M_PI / 180.0);
  std::mt19937_64 rng(o.seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Chart> charts;
  std::vector<V3> seeds;
  std::vector<int> mark(tris.size(), 0);
  int stamp = 0;
  const int attempts = 40 * o.max_charts;
  for (int a = 0; a < attempts && static_cast<int>(charts.size()) < o.max_charts; ++a) {
    const double r = u01(rng) * total;
    const std::size_t t = std::min<std::size_t>(tris.size() - 1, std::lower_bound(cum.begin(), cum.end(), r) - cum.begin());
    double s1 = u01(rng), s2 = u01(rng);
    if (s1 + s2 > 1) s1 = 1 - s1, s2 = 1 - s2;
    const FanTriangle& tr = tris[t];
    const V3 p = add(tr.p[0], add(mul(sub(tr.p[1], tr.p[0]), s1), mul(sub(tr.p[2], tr.p[0]), s2)));
    bool near = false;
    for (const V3& s : seeds) near = near || norm(sub(s, p)) < side;
    if (near) continue;
    Chart c;
    c.origin = p;
    if (!chart_frame(tr, fr, c)) continue;
    rasterize_chart(tris, adj, t, o.texel_size, o.chart_texels, cos_max, c, mark, ++stamp);
    seeds.push_back(p);  // a spot tried once is not tried again, kept or not
    if (static_cast<double>(c.valid) < o.min_valid_share * o.chart_texels * o.chart_texels) continue;
    charts.push_back(std::move(c));
  }
  return charts;
}

// An object only a few dozen texels across holds no chart of the asked side:
// halve it down to 16 (SurfaceFidelityOptions::chart_texels); o.chart_texels
// is left at the side used.
std::vector<Chart> place_fitting_charts(const std::vector<FanTriangle>& tris, const TextureFrames& fr,
                                        SurfaceFidelityOptions& o) {
  const Adjacency adj = triangle_adjacency(tris);
  std::vector<Chart> charts = place_charts(tris, adj, fr, o);
  while (charts.empty() && o.chart_texels / 2 >= std::max(16, o.patch)) {
    o.chart_texels /= 2;
    charts = place_charts(tris, adj, fr, o);
  }
  return charts;
}

SurfacePoint surface_point(const FanTriangle& t, const std::array<float, 3>& b) {
  SurfacePoint s;
  s.face = t.face;
  s.corner = t.corner;
  s.vertex = t.vertex;
  s.bary = {b[0], b[1], b[2]};
  return s;
}

}  // namespace

SurfaceColorFn vertex_color_source(const Mesh& mesh) {
  auto col = find(mesh, kVertexColor);
  if (!col.second) fail("the mesh has no vertex colours (kVertexColor)");
  auto colors = std::make_shared<std::vector<Color3f>>(mesh.number_of_vertices());
  for (VertexIndex v : mesh.vertices()) (*colors)[v.idx()] = col.first[v];
  return [colors](const SurfacePoint& p) {
    std::array<float, 3> c{0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 3; ++j) c[j] += static_cast<float>(p.bary[k]) * (*colors)[p.vertex[k]][j];
    return c;
  };
}

SurfaceColorFn vertex_source_coordinates(const std::vector<std::array<int, 2>>& per_vertex) {
  auto src = std::make_shared<std::vector<std::array<int, 2>>>(per_vertex);
  return [src](const SurfacePoint& p) {
    std::array<float, 3> c{0, 0, 1};
    for (int k = 0; k < 3; ++k) {
      if (p.vertex[k] >= src->size() || (*src)[p.vertex[k]][0] < 0) return std::array<float, 3>{0, 0, 0};
      c[0] += static_cast<float>(p.bary[k]) * (*src)[p.vertex[k]][0];
      c[1] += static_cast<float>(p.bary[k]) * (*src)[p.vertex[k]][1];
    }
    return c;
  };
}

SurfaceColorFn material_tile_source(const std::vector<std::array<std::array<double, 3>, 3>>& corners,
                                    const MaterialTile& tile) {
  validate_material_tile(tile);
  auto c = std::make_shared<std::vector<std::array<std::array<double, 3>, 3>>>(corners);
  auto t = std::make_shared<MaterialTile>(tile);
  return [c, t](const SurfacePoint& p) {
    if (p.face >= c->size()) return std::array<float, 3>{0, 0, 0};
    const auto& k = (*c)[p.face];
    std::array<double, 3> stm{0, 0, 0};
    for (int i = 0; i < 3; ++i)
      for (int d = 0; d < 3; ++d) stm[d] += p.bary[i] * k[i][d];
    const Vec3f v = sample_material_tile(*t, stm[0], stm[1], stm[2]);
    return std::array<float, 3>{v[0], v[1], v[2]};
  };
}

SurfaceColorFn atlas_color_source(const Mesh& mesh, const Image& atlas) {
  auto uv = find(mesh, kCornerUV);
  if (!uv.second) fail("the mesh has no corner UVs (kCornerUV)");
  if (atlas.empty()) fail("the atlas image is empty");
  auto uvs = std::make_shared<std::vector<UV>>(mesh.number_of_halfedges());
  for (HalfedgeIndex h : mesh.halfedges())
    if (!mesh.is_border(h)) (*uvs)[h.idx()] = uv.first[h];
  auto img = std::make_shared<Image>(as_rgb(atlas));
  return [uvs, img](const SurfacePoint& p) {
    double u = 0, v = 0;
    for (int k = 0; k < 3; ++k) {
      u += p.bary[k] * (*uvs)[p.corner[k]][0];
      v += p.bary[k] * (*uvs)[p.corner[k]][1];
    }
    float out[3];
    sample_bilinear(*img, u * img->width - 0.5, (1.0 - v) * img->height - 0.5, true, out);
    return std::array<float, 3>{out[0], out[1], out[2]};
  };
}

TextureFrames frames_from_vertex_directions(const Mesh& mesh) {
  auto dir = find(mesh, kVertexDirection);
  if (!dir.second) fail("the mesh has no vertex directions (kVertexDirection)");
  TextureFrames fr;
  fr.x_axis.assign(mesh.number_of_faces(), {0, 0, 0});
  fr.y_axis = fr.x_axis;
  for (FaceIndex f : mesh.faces()) {
    V3 x{0, 0, 0};
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
      const Vector3 d = dir.first[v];
      x = add(x, {d.x(), d.y(), d.z()});
    }
    const Vector3 a = polygon_vector_area(mesh, f);
    fr.x_axis[f.idx()] = x;
    fr.y_axis[f.idx()] = cross(x, {a.x(), a.y(), a.z()});
  }
  return fr;
}

TextureFrames frames_from_face_directions(const Mesh& mesh) {
  auto dir = find(mesh, kFaceDirection);
  if (!dir.second) fail("the mesh has no face directions (kFaceDirection)");
  TextureFrames fr;
  fr.x_axis.assign(mesh.number_of_faces(), {0, 0, 0});
  fr.y_axis = fr.x_axis;
  for (FaceIndex f : mesh.faces()) {
    const Vector3 d = dir.first[f], a = polygon_vector_area(mesh, f);
    fr.x_axis[f.idx()] = {d.x(), d.y(), d.z()};
    fr.y_axis[f.idx()] = cross(fr.x_axis[f.idx()], {a.x(), a.y(), a.z()});
  }
  return fr;
}

TextureFrames frames_from_corner_coordinates(const Mesh& mesh,
                                             const std::function<std::array<double, 2>(std::size_t)>& xy) {
  TextureFrames fr;
  fr.x_axis.assign(mesh.number_of_faces(), {0, 0, 0});
  fr.y_axis = fr.x_axis;
  std::vector<char> done(mesh.number_of_faces(), 0);
  for (const FanTriangle& t : fan_triangles(mesh)) {
    if (done[t.face]) continue;
    done[t.face] = 1;
    // p(x, y) = p0 + A (x - x0, y - y0): the columns of A are dp/dx, dp/dy.
    const auto a = xy(t.corner[0]), b = xy(t.corner[1]), c = xy(t.corner[2]);
    const double m00 = b[0] - a[0], m01 = c[0] - a[0], m10 = b[1] - a[1], m11 = c[1] - a[1];
    const double det = m00 * m11 - m01 * m10;
    if (!(std::abs(det) > 1e-300) || !std::isfinite(det)) continue;
    const V3 e1 = sub(t.p[1], t.p[0]), e2 = sub(t.p[2], t.p[0]);
    // A = [e1 e2] M^-1, M^-1 = [m11 -m01; -m10 m00] / det
    fr.x_axis[t.face] = mul(sub(mul(e1, m11), mul(e2, m10)), 1.0 / det);
    fr.y_axis[t.face] = mul(sub(mul(e2, m00), mul(e1, m01)), 1.0 / det);
  }
  return fr;
}

std::vector<char> seam_edges_from_corners(const Mesh& mesh,
                                          const std::function<std::array<double, 2>(std::size_t)>& uv,
                                          double tol) {
  std::vector<char> seam(mesh.number_of_edges(), 0);
  for (EdgeIndex e : mesh.edges()) {
    const HalfedgeIndex h = mesh.halfedge(e), o = mesh.opposite(h);
    if (mesh.is_border(h) || mesh.is_border(o)) continue;
    // face(h) has corner target(h) = b at h, source(h) = a at prev(h); face(o)
    // has a at o and b at prev(o).
    const auto fb = uv(h.idx()), fa = uv(mesh.prev(h).idx()), ga = uv(o.idx()), gb = uv(mesh.prev(o).idx());
    auto differ = [tol](const std::array<double, 2>& p, const std::array<double, 2>& q) {
      return std::abs(p[0] - q[0]) > tol || std::abs(p[1] - q[1]) > tol;
    };
    seam[e.idx()] = differ(fa, ga) || differ(fb, gb);
  }
  return seam;
}

double texel_size_of_frames(const Mesh& mesh, const TextureFrames& fr) {
  std::vector<std::pair<double, double>> v;  // (texel, area)
  for (FaceIndex f : mesh.faces()) {
    if (f.idx() >= fr.x_axis.size()) break;
    const double t = std::sqrt(norm(fr.x_axis[f.idx()]) * norm(fr.y_axis[f.idx()]));
    const double a = polygon_area(mesh, f);
    if (t > 0 && std::isfinite(t) && a > 0) v.push_back({t, a});
  }
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  double total = 0, acc = 0;
  for (const auto& x : v) total += x.second;
  for (const auto& x : v)
    if ((acc += x.second) >= 0.5 * total) return x.first;
  return v.back().first;
}

std::vector<char> seam_edges_from_corner_uv(const Mesh& mesh) {
  auto uv = find(mesh, kCornerUV);
  if (!uv.second) fail("the mesh has no corner UVs (kCornerUV)");
  return seam_edges_from_corners(mesh, [&](std::size_t h) {
    const UV t = uv.first[HalfedgeIndex(static_cast<Mesh::size_type>(h))];
    return std::array<double, 2>{t[0], t[1]};
  });
}

std::vector<char> seam_edges_from_face_ids(const Mesh& mesh, const std::vector<int>& id) {
  if (id.size() != mesh.number_of_faces()) fail("face ids have the wrong size");
  std::vector<char> seam(mesh.number_of_edges(), 0);
  for (EdgeIndex e : mesh.edges()) {
    const HalfedgeIndex h = mesh.halfedge(e), o = mesh.opposite(h);
    if (mesh.is_border(h) || mesh.is_border(o)) continue;
    seam[e.idx()] = id[mesh.face(h).idx()] != id[mesh.face(o).idx()];
  }
  return seam;
}

namespace {

// Step 5: the share of valid pixels on a long straight run of sources.
double long_run_share(const std::vector<std::array<float, 3>>& src, const std::vector<char>& valid, int W, int H,
                      double max_run_x, double max_run_y) {
  std::vector<char> mark(valid.size(), 0);
  auto coherent = [&](std::size_t a, std::size_t b, double ex, double ey) {
    if (!valid[a] || !valid[b] || src[a][2] < 0.5f || src[b][2] < 0.5f) return false;
    return std::abs(src[b][0] - src[a][0] - ex) < 0.5 && std::abs(src[b][1] - src[a][1] - ey) < 0.5;
  };
  auto scan = [&](int lines, int len, bool rows, double max_run) {
    for (int l = 0; l < lines; ++l) {
      auto at = [&](int i) { return rows ? static_cast<std::size_t>(l) * W + i : static_cast<std::size_t>(i) * W + l; };
      int start = 0;
      for (int i = 1; i <= len; ++i) {
        if (i < len && coherent(at(i - 1), at(i), rows ? 1.0 : 0.0, rows ? 0.0 : 1.0)) continue;
        if (i - start > max_run)
          for (int j = start; j < i; ++j) mark[at(j)] = 1;
        start = i;
      }
    }
  };
  scan(H, W, true, max_run_x);
  scan(W, H, false, max_run_y);
  std::size_t n = 0, m = 0;
  for (std::size_t i = 0; i < valid.size(); ++i) n += valid[i], m += valid[i] && mark[i];
  return n ? double(m) / double(n) : 0.0;
}

}  // namespace

SurfaceSeamRatio surface_seam_ratio(const Mesh& mesh, const SurfaceColorFn& color, const std::vector<char>& seam_edges,
                                    double texel_size, const SeamRatioSurfaceOptions& o) {
  if (!(texel_size > 0) || !std::isfinite(texel_size)) fail("texel size must be > 0 (got " + std::to_string(texel_size) + ")");
  if (o.chart_texels < 16 || o.chart_texels > 1024) fail("seam chart_texels must be in 16..1024");
  if (o.max_charts < 1 || o.max_charts > 256) fail("seam max_charts must be in 1..256");
  if (seam_edges.size() != mesh.number_of_edges())
    fail("seam flags have " + std::to_string(seam_edges.size()) + " entries for " +
         std::to_string(mesh.number_of_edges()) + " edges");
  if (!color) fail("no colour source");
  SurfaceSeamRatio r;
  // Islands: faces joined across unflagged edges (union-find); flagged face pairs.
  UnionFind<std::size_t> islands(mesh.number_of_faces());
  auto root = [&](std::size_t x) { return islands.find(x); };
  std::unordered_map<std::uint64_t, char> flagged;
  for (EdgeIndex e : mesh.edges()) {
    if (mesh.is_border(e)) continue;
    const std::uint64_t f = mesh.face(mesh.halfedge(e)).idx(), g = mesh.face(mesh.opposite(mesh.halfedge(e))).idx();
    if (seam_edges[e.idx()]) {
      ++r.seam_edges;
      flagged[(std::min(f, g) << 32) | std::max(f, g)] = 1;
    } else {
      islands.unite(f, g);
    }
  }
  // Charts in an arbitrary tangent frame (the ratio is orientation-matched).
  TextureFrames fr;
  fr.x_axis.assign(mesh.number_of_faces(), {0, 0, 0});
  fr.y_axis = fr.x_axis;
  for (FaceIndex f : mesh.faces()) {
    const HalfedgeIndex h = mesh.halfedge(f);
    fr.x_axis[f.idx()] = sub(point(mesh, mesh.target(h)), point(mesh, mesh.source(h)));
  }
  const std::vector<FanTriangle> tris = fan_triangles(mesh);
  SurfaceFidelityOptions co;
  co.texel_size = texel_size;
  co.chart_texels = o.chart_texels;
  co.max_charts = o.max_charts;
  co.seed = o.seed;
  const std::vector<Chart> charts = place_fitting_charts(tris, fr, co);
  const int C = co.chart_texels;
  double across[2] = {0, 0}, within[2] = {0, 0};
  std::size_t n_across[2] = {0, 0}, n_within[2] = {0, 0};
  std::vector<std::array<float, 3>> col(static_cast<std::size_t>(C) * C);
  for (const Chart& c : charts) {
    tbb::parallel_for(0, C, [&](int y) {
      for (int x = 0; x < C; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * C + x;
        if (c.tri[i] >= 0) col[i] = color(surface_point(tris[c.tri[i]], c.bary[i]));
      }
    });
    for (int y = 0; y < C; ++y)
      for (int x = 0; x < C; ++x)
        for (int d = 0; d < 2; ++d) {  // 0: horizontal pair, 1: vertical pair
          const int x2 = x + (d == 0), y2 = y + (d == 1);
          if (x2 >= C || y2 >= C) continue;
          const std::size_t i = static_cast<std::size_t>(y) * C + x, j = static_cast<std::size_t>(y2) * C + x2;
          if (c.tri[i] < 0 || c.tri[j] < 0) continue;
          const std::uint64_t f = tris[c.tri[i]].face, g = tris[c.tri[j]].face;
          double jump = 0;
          for (int k = 0; k < 3; ++k) jump += (double(col[i][k]) - col[j][k]) * (double(col[i][k]) - col[j][k]);
          jump = std::sqrt(jump);
          const bool is_across =
              f != g && (root(f) != root(g) || flagged.count((std::min(f, g) << 32) | std::max(f, g)));
          if (is_across) across[d] += jump, ++n_across[d];
          else within[d] += jump, ++n_within[d];
        }
  }
  r.pairs_across = n_across[0] + n_across[1];
  r.pairs_within = n_within[0] + n_within[1];
  if (r.pairs_across) r.mean_across = (across[0] + across[1]) / r.pairs_across;
  if (r.pairs_within) r.mean_within = (within[0] + within[1]) / r.pairs_within;
  double expected = 0;
  for (int d = 0; d < 2; ++d)
    if (n_within[d]) expected += n_across[d] * (within[d] / n_within[d]);
  r.ratio = (r.pairs_across && expected > 0) ? (across[0] + across[1]) / expected : 0.0;
  return r;
}

SurfaceFidelityResult surface_fidelity(const Mesh& mesh, const Image& exemplar, const SurfaceColorFn& color,
                                       const TextureFrames& frames, const SurfaceFidelityOptions& o) {
  Timer timer;
  if (mesh.number_of_faces() == 0) fail("the mesh has no faces");
  if (mesh.has_garbage()) fail("the mesh has removed elements (collect garbage first)");
  if (exemplar.empty()) fail("the exemplar is empty");
  if (!color) fail("no colour source");
  if (!(o.texel_size > 0) || !std::isfinite(o.texel_size))
    fail("texel size must be > 0 mesh units (got " + std::to_string(o.texel_size) + ")");
  if (o.chart_texels < 16 || o.chart_texels > 1024) fail("chart_texels must be in 16..1024 (got " + std::to_string(o.chart_texels) + ")");
  if (o.max_charts < 1 || o.max_charts > 256) fail("max_charts must be in 1..256 (got " + std::to_string(o.max_charts) + ")");
  if (static_cast<double>(o.max_charts) * o.chart_texels * o.chart_texels > double(1 << 22))
    fail("max_charts x chart_texels^2 must be at most 4M texels");
  if (!(o.max_normal_angle_deg > 0 && o.max_normal_angle_deg <= 89)) fail("max_normal_angle_deg must be in (0, 89]");
  if (!(o.min_valid_share >= 0 && o.min_valid_share < 1)) fail("min_valid_share must be in [0, 1)");
  if (o.patch < 1 || o.patch > o.chart_texels) fail("patch must be in 1..chart_texels");
  if (o.stride < 1) fail("stride must be >= 1");
  if (o.max_candidates < 0) fail("max_candidates must be >= 0");
  if (!(o.search_eps >= 0.f)) fail("search_eps must be >= 0");
  if (o.exemplar_stride < 0) fail("exemplar_stride must be >= 0");
  if (frames.x_axis.size() != mesh.number_of_faces() || frames.y_axis.size() != mesh.number_of_faces())
    fail("texture frames have " + std::to_string(frames.x_axis.size()) + " entries for " +
         std::to_string(mesh.number_of_faces()) + " faces");
  const Image ex = as_rgb(exemplar);
  const std::vector<FanTriangle> tris = fan_triangles(mesh);
  SurfaceFidelityOptions oc = o;
  std::vector<Chart> charts = place_fitting_charts(tris, frames, oc);
  if (charts.empty())
    fail("no chart of " + std::to_string(oc.chart_texels) + " texels at texel size " + std::to_string(o.texel_size) +
         " fits the surface with at least " + std::to_string(o.min_valid_share) + " of its pixels valid");
  SurfaceFidelityResult r;
  r.texel_size = o.texel_size;
  r.chart_texels = oc.chart_texels;
  r.charts = static_cast<int>(charts.size());
  const int C = oc.chart_texels, n = r.charts;
  const int cols = static_cast<int>(std::ceil(std::sqrt(double(n)))), rows = (n + cols - 1) / cols;
  const int W = cols * (C + 1) - 1, H = rows * (C + 1) - 1;
  r.mosaic = Image(W, H, 3, 0.f);
  r.mosaic_valid.assign(static_cast<std::size_t>(W) * H, 0);
  tbb::parallel_for(0, n, [&](int k) {
    const Chart& c = charts[k];
    const int ox = (k % cols) * (C + 1), oy = (k / cols) * (C + 1);
    for (int y = 0; y < C; ++y)
      for (int x = 0; x < C; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * C + x;
        if (c.tri[i] < 0) continue;
        const auto col = color(surface_point(tris[c.tri[i]], c.bary[i]));
        float* px = r.mosaic.pixel(ox + x, oy + y);
        for (int j = 0; j < 3; ++j) px[j] = col[j];
        r.mosaic_valid[static_cast<std::size_t>(oy + y) * W + ox + x] = 1;
      }
  });
  for (const Chart& c : charts) r.valid_texels += c.valid;
  if (o.source) {
    std::vector<std::array<float, 3>> src(r.mosaic_valid.size(), {0, 0, 0});
    tbb::parallel_for(0, n, [&](int k) {
      const Chart& c = charts[k];
      const int ox = (k % cols) * (C + 1), oy = (k / cols) * (C + 1);
      for (int y = 0; y < C; ++y)
        for (int x = 0; x < C; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * C + x;
          if (c.tri[i] >= 0) src[static_cast<std::size_t>(oy + y) * W + ox + x] = o.source(surface_point(tris[c.tri[i]], c.bary[i]));
        }
    });
    r.long_run_fraction = long_run_share(src, r.mosaic_valid, W, H, 0.5 * ex.width, 0.5 * ex.height);
  }
  r.seconds_charts = timer.seconds();
  timer.reset();
  BidirectionalOptions bo = fidelity_similarity_options(o, ex);
  bo.output_valid = r.mosaic_valid;
  r.surface = bidirectional_similarity(r.mosaic, ex, bo);
  r.bds = r.surface.total;
  r.seconds_bds = timer.seconds();
  if (o.reference_2d) {
    timer.reset();
    GraphcutOptions go;
    go.seed = o.seed;
    const Image gc = graphcut_synthesize(ex, W + 1, H + 1, go);
    // Each chart reads the 2D texture at a seeded sub-texel offset (bilinear).
    std::mt19937_64 rng(o.seed ^ 0x5eedULL);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    std::vector<std::array<double, 2>> shift(n);
    for (auto& sh : shift) sh = {u01(rng), u01(rng)};
    r.reference_image = Image(W, H, 3, 0.f);
    tbb::parallel_for(0, n, [&](int k) {
      const int ox = (k % cols) * (C + 1), oy = (k / cols) * (C + 1);
      for (int y = 0; y < C; ++y)
        for (int x = 0; x < C; ++x) {
          const std::size_t i = static_cast<std::size_t>(oy + y) * W + ox + x;
          if (!r.mosaic_valid[i]) continue;
          sample_bilinear(gc, ox + x + shift[k][0], oy + y + shift[k][1], false, r.reference_image.pixel(ox + x, oy + y));
        }
    });
    r.reference = bidirectional_similarity(r.reference_image, ex, bo);
    r.bds_2d = r.reference.total;
    r.ratio = r.bds_2d > 0 ? r.bds / r.bds_2d : 0.0;
    r.seconds_reference = timer.seconds();
  }
  return r;
}

BidirectionalOptions fidelity_similarity_options(const SurfaceFidelityOptions& o, const Image& exemplar) {
  BidirectionalOptions bo;
  bo.patch = o.patch;
  bo.stride = o.stride;
  bo.periodic_exemplar = o.periodic_exemplar;
  bo.max_candidates = o.max_candidates;
  bo.search_eps = o.search_eps;
  bo.exemplar_stride = o.exemplar_stride;
  if (bo.exemplar_stride == 0) {
    const double patches =
        double(std::max(1, exemplar.width - o.patch + 1)) * std::max(1, exemplar.height - o.patch + 1);
    bo.exemplar_stride = std::max(2, static_cast<int>(std::ceil(std::sqrt(patches / 20000.0))));
  }
  return bo;
}

TextureFrames frames_from_atlas_uv(const Mesh& mesh, int width, int height) {
  auto uv = find(mesh, kCornerUV);
  if (!uv.second) fail("the mesh has no corner UVs (kCornerUV)");
  return frames_from_corner_coordinates(mesh, [&](std::size_t he) {
    const UV t = uv.first[HalfedgeIndex(static_cast<Mesh::size_type>(he))];
    return std::array<double, 2>{t[0] * width, (1.0 - t[1]) * height};
  });
}

nlohmann::json fidelity_report(const Mesh& mesh, const Image& exemplar, const SurfaceColorFn& color,
                               const TextureFrames& frames, const std::vector<char>& seam_edges,
                               const SurfaceFidelityOptions& o) {
  nlohmann::json j;
  try {
    j = to_json(surface_fidelity(mesh, exemplar, color, frames, o));
  } catch (const InvalidInputError& e) {
    j = {{"error", e.what()}};
  }
  if (!seam_edges.empty()) {
    SeamRatioSurfaceOptions so;
    so.chart_texels = o.chart_texels;
    so.seed = o.seed;
    try {
      j["seam"] = to_json(surface_seam_ratio(mesh, color, seam_edges, o.texel_size, so));
    } catch (const InvalidInputError& e) {
      j["seam"] = {{"error", e.what()}};
    }
  }
  return j;
}

nlohmann::json atlas_fidelity_report(const Mesh& mesh, const Image& exemplar, const Image& atlas, double texel_size,
                                     bool face_directions, std::uint64_t seed) {
  if (!find(mesh, kCornerUV).second) fail("the mesh has no corner UVs (kCornerUV)");
  const TextureFrames frames =
      face_directions ? frames_from_face_directions(mesh) : frames_from_atlas_uv(mesh, atlas.width, atlas.height);
  auto patch = find(mesh, kFacePatch);
  std::vector<char> seams;
  if (patch.second) {
    std::vector<int> id(mesh.number_of_faces());
    for (FaceIndex f : mesh.faces()) id[f.idx()] = patch.first[f];
    seams = seam_edges_from_face_ids(mesh, id);
  } else {
    seams = seam_edges_from_corner_uv(mesh);
  }
  SurfaceFidelityOptions o;
  o.texel_size = texel_size;
  o.seed = seed;
  return fidelity_report(mesh, exemplar, atlas_color_source(mesh, atlas), frames, seams, o);
}

nlohmann::json material_map_fidelity_report(const Mesh& mesh,
                                            const std::vector<std::array<std::array<double, 3>, 3>>& corners,
                                            const MaterialTile& tile, std::uint64_t seed) {
  validate_material_tile(tile);
  if (corners.size() != mesh.number_of_faces()) fail("corner (s,t,m) given for the wrong number of faces");
  // Corner k of face f is the k-th halfedge from halfedge(f): map halfedges to (face, k).
  std::vector<std::array<double, 2>> st(mesh.number_of_halfedges(), {0, 0});
  double msum = 0, n = 0;
  for (FaceIndex f : mesh.faces()) {
    int k = 0;
    for (HalfedgeIndex hh : mesh.halfedges_around_face(mesh.halfedge(f))) {
      if (k < 3) {
        st[hh.idx()] = {corners[f.idx()][k][0] * tile.size, corners[f.idx()][k][1] * tile.size};
        msum += corners[f.idx()][k][2], n += 1;
      }
      ++k;
    }
  }
  const auto coords = [&](std::size_t he) { return st[he]; };
  const TextureFrames frames = frames_from_corner_coordinates(mesh, coords);
  SurfaceFidelityOptions o;
  o.texel_size = texel_size_of_frames(mesh, frames);
  o.periodic_exemplar = true;
  o.seed = seed;
  const double m = n > 0 ? std::clamp(msum / n, 0.0, 1.0) : 0.0;
  const std::size_t layer =
      tile.layers.size() > 1 ? static_cast<std::size_t>(std::lround(m * (tile.layers.size() - 1))) : 0;
  if (!(o.texel_size > 0)) return {{"error", "the (s,t) mapping has no face with a usable gradient"}};
  return fidelity_report(mesh, tile.layers[layer], material_tile_source(corners, tile), frames,
                         seam_edges_from_corners(mesh, coords, 1e-9), o);
}

nlohmann::json to_json(const SurfaceFidelityResult& r) {
  nlohmann::json j = {{"bds", r.bds},
          {"bds_2d", r.bds_2d},
          {"ratio", r.ratio},
          {"coherence", r.surface.coherence},
          {"completeness", r.surface.completeness},
          {"coherence_2d", r.reference.coherence},
          {"completeness_2d", r.reference.completeness},
          {"charts", r.charts},
          {"valid_texels", r.valid_texels},
          {"texel_size", r.texel_size},
          {"chart_texels", r.chart_texels},
          {"seconds", {{"charts", r.seconds_charts}, {"bds", r.seconds_bds}, {"bds_2d", r.seconds_reference}}}};
  if (r.long_run_fraction >= 0) j["long_run_fraction"] = r.long_run_fraction;
  return j;
}

nlohmann::json to_json(const SurfaceSeamRatio& r) {
  return {{"ratio", r.ratio},
          {"mean_jump_across", r.mean_across},
          {"mean_jump_within", r.mean_within},
          {"pairs_across", r.pairs_across},
          {"pairs_within", r.pairs_within},
          {"seam_edges", r.seam_edges}};
}

}  // namespace surftex
