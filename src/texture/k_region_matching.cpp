// SPDX-License-Identifier: AGPL-3.0-or-later
// k-region matching (Bangay & Morkel 2006, section 3.3). See k_region_matching.h.
#include "texture/k_region_matching.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/polygon_util.h"
#include "geometry/properties.h"
#include "texture/gaussian_pyramid.h"

namespace surftex {
namespace {

using V3 = std::array<double, 3>;
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline int wrap(int x, int n) {
  x %= n;
  return x < 0 ? x + n : x;
}

}  // namespace

SurfaceFrames compute_surface_frames(const Mesh& mesh) {
  auto dir = find(mesh, kVertexDirection);
  if (!dir.second) throw InvalidInputError("compute_surface_frames: the mesh has no kVertexDirection (v:dir) map");
  const std::size_t nv = mesh.number_of_vertices();
  if (nv == 0 || mesh.has_garbage())
    throw InvalidInputError("compute_surface_frames: the mesh is empty or has removed elements (collect garbage)");
  SurfaceFrames fr;
  const auto n = polygon_vertex_normals(mesh);
  fr.normal.resize(nv);
  fr.direction.resize(nv);
  fr.mean_edge.resize(nv);
  for (VertexIndex v : mesh.vertices()) {
    const std::size_t i = v.idx();
    fr.normal[i] = {n[i].x(), n[i].y(), n[i].z()};
    V3 d{dir.first[v].x(), dir.first[v].y(), dir.first[v].z()};
    const double dn = dot(d, fr.normal[i]);
    for (int k = 0; k < 3; ++k) d[k] -= dn * fr.normal[i][k];
    double l = std::sqrt(dot(d, d));
    if (!(l > 1e-12)) {  // fall back to any tangent
      d = cross(fr.normal[i], std::abs(fr.normal[i][0]) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0});
      l = std::sqrt(dot(d, d));
    }
    for (int k = 0; k < 3; ++k) d[k] /= l;
    fr.direction[i] = d;
    fr.mean_edge[i] = mean_incident_edge_length(mesh, v);
  }
  double s = 0;
  for (EdgeIndex e : mesh.edges())
    s += std::sqrt((mesh.point(mesh.vertex(e, 0)) - mesh.point(mesh.vertex(e, 1))).squared_length());
  fr.mean_edge_length = mesh.number_of_edges() ? s / mesh.number_of_edges() : 0.0;
  return fr;
}

void k_region(const Mesh& mesh, const SurfaceFrames& fr, std::size_t center, int k, LocalCoordinates mode,
              KRegion& out) {
  const std::size_t nv = mesh.number_of_vertices();
  if (center >= nv)
    throw InvalidInputError("k_region: centre " + std::to_string(center) + " out of range (" + std::to_string(nv) +
                            " vertices)");
  if (k < 0) throw InvalidInputError("k_region: k must be >= 0 (got " + std::to_string(k) + ")");
  if (fr.normal.size() != nv) throw InvalidInputError("k_region: frames were computed for another mesh");
  thread_local std::vector<int> index;
  if (index.size() != nv) index.assign(nv, -1);
  out.vertices.clear();
  out.hops.clear();
  out.uv.clear();
  out.edges.clear();
  std::vector<double> paths;
  out.vertices.push_back(center);
  out.hops.push_back(0);
  out.uv.push_back({0, 0});
  paths.push_back(1);
  index[center] = 0;
  const Point3 pc = mesh.point(VertexIndex(static_cast<Mesh::size_type>(center)));
  const V3& n0 = fr.normal[center];
  const V3& t0 = fr.direction[center];
  const V3 b0 = cross(n0, t0);
  std::size_t ring_begin = 0;
  for (int hop = 1; hop <= k; ++hop) {
    const std::size_t ring_end = out.vertices.size();
    for (std::size_t i = ring_begin; i < ring_end; ++i) {
      const VertexIndex p(static_cast<Mesh::size_type>(out.vertices[i]));
      if (mesh.is_isolated(p)) continue;
      for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(p))) {
        if (index[w.idx()] >= 0) continue;
        index[w.idx()] = static_cast<int>(out.vertices.size());
        out.vertices.push_back(w.idx());
        out.hops.push_back(hop);
        out.uv.push_back({0, 0});
        paths.push_back(0);
      }
    }
    // Coordinates of the new ring.
    for (std::size_t j = ring_end; j < out.vertices.size(); ++j) {
      const VertexIndex w(static_cast<Mesh::size_type>(out.vertices[j]));
      const Point3 pw = mesh.point(w);
      if (mode == LocalCoordinates::kTangentProjection) {
        const V3 d{pw.x() - pc.x(), pw.y() - pc.y(), pw.z() - pc.z()};
        out.uv[j] = {dot(d, t0), dot(d, b0)};
        continue;
      }
      double su = 0, sv = 0, np = 0;
      for (VertexIndex p : mesh.vertices_around_target(mesh.halfedge(w))) {
        const int ip = index[p.idx()];
        if (ip < 0 || out.hops[ip] != hop - 1) continue;
        const Point3 pp = mesh.point(p);
        const V3 d{pw.x() - pp.x(), pw.y() - pp.y(), pw.z() - pp.z()};
        const V3& t = hop == 1 ? t0 : fr.direction[p.idx()];
        const V3& nn = hop == 1 ? n0 : fr.normal[p.idx()];
        const V3 b = cross(nn, t);
        double u = dot(d, t), v = dot(d, b);
        const double lt = std::sqrt(u * u + v * v), l3 = std::sqrt(dot(d, d));
        if (lt > 1e-300) u *= l3 / lt, v *= l3 / lt;
        const double m = paths[ip];
        su += m * (out.uv[ip][0] + u);
        sv += m * (out.uv[ip][1] + v);
        np += m;
      }
      paths[j] = np;
      out.uv[j] = {su / np, sv / np};
    }
    ring_begin = ring_end;
    if (ring_begin == out.vertices.size()) break;
  }
  for (std::size_t i = 0; i < out.vertices.size(); ++i) {
    const VertexIndex v(static_cast<Mesh::size_type>(out.vertices[i]));
    if (mesh.is_isolated(v)) continue;
    for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(v))) {
      const int j = index[w.idx()];
      if (j > static_cast<int>(i)) out.edges.push_back({static_cast<int>(i), j});
    }
  }
  for (std::size_t v : out.vertices) index[v] = -1;
}

int region_k(double region_texels, int level, bool pyramid, double r_scale, double mean_edge, int max_k) {
  if (!(region_texels > 0) || !(r_scale > 0) || !(mean_edge > 0) || max_k < 1)
    throw InvalidInputError("region_k: region size, r_scale and edge length must be > 0 (got n=" +
                            std::to_string(region_texels) + ", r_scale=" + std::to_string(r_scale) +
                            ", e=" + std::to_string(mean_edge) + ")");
  const double side = std::pow(pyramid ? 2.0 : 1.0, level) * region_texels / (r_scale * mean_edge);
  const double N = side * side;
  // 2k^2 + 2k + 1 = N  ->  k = (-1 + sqrt(2N - 1)) / 2
  const double k = N <= 1 ? 0.0 : (-1.0 + std::sqrt(2.0 * N - 1.0)) / 2.0;
  return std::clamp(static_cast<int>(std::ceil(k - 1e-9)), 1, max_k);
}

ExemplarLevels make_exemplar_levels(const Image& exemplar, bool pyramid, int levels) {
  if (exemplar.empty()) throw InvalidInputError("make_exemplar_levels: the exemplar image is empty");
  Image rgb(exemplar.width, exemplar.height, 3);
  for (int y = 0; y < exemplar.height; ++y)
    for (int x = 0; x < exemplar.width; ++x)
      for (int c = 0; c < 3; ++c)
        rgb.at(x, y, c) = exemplar.at(x, y, exemplar.channels >= 3 ? c : 0);
  ExemplarLevels ex;
  ex.pyramid = pyramid;
  if (pyramid) {
    PyramidOptions po;
    po.levels = levels;
    po.toroidal = true;
    ex.levels = gaussian_pyramid(rgb, po);
  } else {
    StackOptions so;
    so.levels = levels;
    so.toroidal = true;
    ex.levels = gaussian_stack(rgb, so);
  }
  return ex;
}

int antialias_level(const ExemplarLevels& ex, double r_scale, double mean_edge) {
  const double t = r_scale * mean_edge;
  if (!(t > 1.0)) return 0;
  const int l = static_cast<int>(std::lround(std::log2(t)));
  return std::clamp(l, 0, static_cast<int>(ex.levels.size()) - 1);
}

std::array<int, 2> sample_offset(const ExemplarLevels& ex, const RegionSample& s, int center_level) {
  const double sc = ex.pyramid ? static_cast<double>(ex.scale(center_level)) : 1.0;
  return {static_cast<int>(std::lround(s.du / sc)), static_cast<int>(std::lround(-s.dv / sc))};
}

std::vector<SampleGroup> group_samples(const ExemplarLevels& ex, const std::vector<RegionSample>& samples,
                                       int center_level) {
  std::map<std::array<int, 3>, std::size_t> where;
  std::vector<SampleGroup> g;
  std::vector<std::array<double, 3>> sum;
  for (const RegionSample& s : samples) {
    const auto o = sample_offset(ex, s, center_level);
    const int level = ex.pyramid ? center_level : s.level;
    const std::array<int, 3> key{level, o[0], o[1]};
    auto it = where.find(key);
    if (it == where.end()) {
      it = where.emplace(key, g.size()).first;
      g.push_back(SampleGroup{o[0], o[1], level, 0.f, {}});
      sum.push_back({0, 0, 0});
    }
    g[it->second].weight += 1.f;
    for (int c = 0; c < 3; ++c) sum[it->second][c] += s.color[c];
  }
  for (std::size_t i = 0; i < g.size(); ++i)
    for (int c = 0; c < 3; ++c) g[i].color[c] = static_cast<float>(sum[i][c] / g[i].weight);
  return g;
}

std::array<float, 3> texel(const ExemplarLevels& ex, int level, int x, int y) {
  const Image& im = ex.levels[level];
  const float* p = im.pixel(wrap(x, im.width), wrap(y, im.height));
  return {p[0], p[1], p[2]};
}

double naive_distance(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level, int qx,
                      int qy) {
  double d = 0;
  for (const RegionSample& smp : samples) {
    const auto o = sample_offset(ex, smp, center_level);
    const int level = ex.pyramid ? center_level : smp.level;
    const auto w = texel(ex, level, qx + o[0], qy + o[1]);
    for (int c = 0; c < 3; ++c) d += (double(smp.color[c]) - w[c]) * (double(smp.color[c]) - w[c]);
  }
  return d;
}

double grouped_distance(const ExemplarLevels& ex, const std::vector<SampleGroup>& groups, int, int qx, int qy) {
  double d = 0;
  for (const SampleGroup& g : groups) {
    const auto w = texel(ex, g.level, qx + g.dx, qy + g.dy);
    for (int c = 0; c < 3; ++c) d += g.weight * (double(g.color[c]) - w[c]) * (double(g.color[c]) - w[c]);
  }
  return d;
}

MatchResult match_region(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level,
                         const MatchOptions& opt) {
  if (center_level < 0 || center_level >= static_cast<int>(ex.levels.size()))
    throw InvalidInputError("match_region: centre level " + std::to_string(center_level) + " out of range");
  if (opt.rows_per_block < 1) throw InvalidInputError("match_region: rows_per_block must be >= 1");
  MatchResult res;
  if (samples.empty()) return res;
  std::vector<SampleGroup> groups;
  if (opt.averaging) {
    groups = group_samples(ex, samples, center_level);
  } else {
    for (const RegionSample& s : samples) {
      const auto o = sample_offset(ex, s, center_level);
      groups.push_back(SampleGroup{o[0], o[1], ex.pyramid ? center_level : s.level, 1.f, s.color});
    }
  }
  // Heaviest groups first: partial sums grow fastest, so early termination bites sooner.
  std::stable_sort(groups.begin(), groups.end(),
                   [](const SampleGroup& a, const SampleGroup& b) { return a.weight > b.weight; });
  const int W = ex.width(center_level), H = ex.height(center_level);
  const int G = static_cast<int>(groups.size());
  std::vector<const float*> base(G);
  std::vector<int> gx(G), gy(G);
  for (int g = 0; g < G; ++g) {
    const Image& im = ex.levels[groups[g].level];
    base[g] = im.data.data();
    gx[g] = wrap(groups[g].dx, W);
    gy[g] = wrap(groups[g].dy, H);
  }
  const int blocks = (H + opt.rows_per_block - 1) / opt.rows_per_block;
  std::vector<float> best_d(blocks, std::numeric_limits<float>::infinity());
  std::vector<int> best_i(blocks, -1);
  tbb::parallel_for(0, blocks, [&](int b) {
    float bd = std::numeric_limits<float>::infinity();
    int bi = -1;
    std::vector<const float*> row(G);
    const int y0 = b * opt.rows_per_block, y1 = std::min(H, y0 + opt.rows_per_block);
    for (int y = y0; y < y1; ++y) {
      for (int g = 0; g < G; ++g) {
        int yy = y + gy[g];
        if (yy >= H) yy -= H;
        row[g] = base[g] + static_cast<std::size_t>(yy) * W * 3;
      }
      for (int x = 0; x < W; ++x) {
        float d = 0;
        int g = 0;
        for (; g < G; ++g) {
          int xx = x + gx[g];
          if (xx >= W) xx -= W;
          const float* p = row[g] + 3 * xx;
          const float* c = groups[g].color.data();
          const float e0 = p[0] - c[0], e1 = p[1] - c[1], e2 = p[2] - c[2];
          d += groups[g].weight * (e0 * e0 + e1 * e1 + e2 * e2);
          if (d > bd) break;
        }
        if (g == G && d < bd) bd = d, bi = y * W + x;
      }
    }
    best_d[b] = bd;
    best_i[b] = bi;
  });
  float bd = std::numeric_limits<float>::infinity();
  int bi = -1;
  for (int b = 0; b < blocks; ++b)
    if (best_i[b] >= 0 && best_d[b] < bd) bd = best_d[b], bi = best_i[b];
  if (bi < 0) bi = 0, bd = 0;  // only NaN colours: degenerate, take texel 0
  res.found = true;
  res.qx = bi % W;
  res.qy = bi / W;
  res.distance = bd;
  res.comparisons = groups.size();
  return res;
}

}  // namespace surftex
