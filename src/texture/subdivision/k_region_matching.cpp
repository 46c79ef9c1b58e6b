// SPDX-License-Identifier: AGPL-3.0-or-later
// k-region matching (Bangay & Morkel 2006, section 3.3). See k_region_matching.h.
#include "texture/subdivision/k_region_matching.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/polygon_util.h"
#include "geometry/properties.h"
#include "texture/gaussian_pyramid.h"
#include "texture/image_ops.h"

namespace surftex {
namespace {

using V3 = std::array<double, 3>;
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
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

RegionGraph make_region_graph(const Mesh& mesh, const SurfaceFrames& fr) {
  const std::size_t nv = mesh.number_of_vertices();
  if (fr.normal.size() != nv || fr.direction.size() != nv)
    throw InvalidInputError("make_region_graph: frames were computed for another mesh (" +
                            std::to_string(fr.normal.size()) + " vs " + std::to_string(nv) + " vertices)");
  RegionGraph g;
  g.offset.assign(nv + 1, 0);
  g.position.resize(nv);
  g.normal = fr.normal;
  g.u_axis = fr.direction;
  g.v_axis.resize(nv);
  for (VertexIndex v : mesh.vertices()) {
    const std::size_t i = v.idx();
    const Point3& p = mesh.point(v);
    g.position[i] = {p.x(), p.y(), p.z()};
    g.v_axis[i] = cross(fr.normal[i], fr.direction[i]);
    g.offset[i + 1] = mesh.is_isolated(v) ? 0 : static_cast<std::uint32_t>(mesh.degree(v));
  }
  for (std::size_t i = 0; i < nv; ++i) g.offset[i + 1] += g.offset[i];
  g.neighbor.resize(g.offset[nv]);
  g.step.resize(g.offset[nv]);
  for (VertexIndex v : mesh.vertices()) {
    if (mesh.is_isolated(v)) continue;
    const std::size_t i = v.idx();
    std::uint32_t s = g.offset[i];
    for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(v))) {
      const auto& pp = g.position[i];
      const Point3& pw = mesh.point(w);
      const V3 d{pw.x() - pp[0], pw.y() - pp[1], pw.z() - pp[2]};
      double u = dot(d, g.u_axis[i]), vv = dot(d, g.v_axis[i]);
      const double lt = std::sqrt(u * u + vv * vv), l3 = std::sqrt(dot(d, d));
      if (lt > 1e-300) u *= l3 / lt, vv *= l3 / lt;
      g.neighbor[s] = static_cast<std::uint32_t>(w.idx());
      g.step[s] = {u, vv};
      ++s;
    }
  }
  return g;
}

void k_region(const RegionGraph& g, std::size_t center, int k, LocalCoordinates mode, KRegion& out,
              RegionScratch& scr, bool with_edges) {
  const std::size_t nv = g.size();
  if (center >= nv)
    throw InvalidInputError("k_region: centre " + std::to_string(center) + " out of range (" + std::to_string(nv) +
                            " vertices)");
  if (k < 0) throw InvalidInputError("k_region: k must be >= 0 (got " + std::to_string(k) + ")");
  if (scr.index.size() != nv) scr.index.assign(nv, -1);
  int* index = scr.index.data();
  out.vertices.clear();
  out.hops.clear();
  out.uv.clear();
  out.edges.clear();
  scr.paths.clear();
  out.vertices.push_back(center);
  out.hops.push_back(0);
  out.uv.push_back({0, 0});
  scr.paths.push_back(1);
  index[center] = 0;
  const auto& pc = g.position[center];
  const auto& t0 = g.u_axis[center];
  const auto& b0 = g.v_axis[center];
  std::size_t ring_begin = 0;
  for (int hop = 1; hop <= k; ++hop) {
    const std::size_t ring_end = out.vertices.size();
    for (std::size_t i = ring_begin; i < ring_end; ++i) {
      const std::size_t p = out.vertices[i];
      for (std::uint32_t s = g.offset[p]; s < g.offset[p + 1]; ++s) {
        const std::uint32_t w = g.neighbor[s];
        if (index[w] < 0) {
          index[w] = static_cast<int>(out.vertices.size());
          out.vertices.push_back(w);
          out.hops.push_back(hop);
          if (mode == LocalCoordinates::kTangentProjection) {
            const auto& pw = g.position[w];
            const V3 d{pw[0] - pc[0], pw[1] - pc[1], pw[2] - pc[2]};
            out.uv.push_back({dot(d, t0), dot(d, b0)});
          } else {
            out.uv.push_back({0, 0});
          }
          scr.paths.push_back(0);
        }
        if (mode == LocalCoordinates::kUnfolding) {
          // w in the new ring: accumulate this predecessor's paths (p is one hop closer).
          const int j = index[w];
          if (out.hops[j] != hop) continue;
          const double m = scr.paths[i];
          out.uv[j][0] += m * (out.uv[i][0] + g.step[s][0]);
          out.uv[j][1] += m * (out.uv[i][1] + g.step[s][1]);
          scr.paths[j] += m;
        }
      }
    }
    if (mode == LocalCoordinates::kUnfolding)
      for (std::size_t j = ring_end; j < out.vertices.size(); ++j) {
        out.uv[j][0] /= scr.paths[j];
        out.uv[j][1] /= scr.paths[j];
      }
    ring_begin = ring_end;
    if (ring_begin == out.vertices.size()) break;
  }
  if (with_edges)
    for (std::size_t i = 0; i < out.vertices.size(); ++i) {
      const std::size_t v = out.vertices[i];
      for (std::uint32_t s = g.offset[v]; s < g.offset[v + 1]; ++s) {
        const int j = index[g.neighbor[s]];
        if (j > static_cast<int>(i)) out.edges.push_back({static_cast<int>(i), j});
      }
    }
  for (std::size_t v : out.vertices) index[v] = -1;
}

void k_region(const Mesh& mesh, const SurfaceFrames& fr, std::size_t center, int k, LocalCoordinates mode,
              KRegion& out) {
  const std::size_t nv = mesh.number_of_vertices();
  if (center >= nv)
    throw InvalidInputError("k_region: centre " + std::to_string(center) + " out of range (" + std::to_string(nv) +
                            " vertices)");
  if (fr.normal.size() != nv) throw InvalidInputError("k_region: frames were computed for another mesh");
  const RegionGraph g = make_region_graph(mesh, fr);
  RegionScratch scr;
  k_region(g, center, k, mode, out, scr, true);
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

ExemplarLevels make_exemplar_levels(const Image& exemplar, bool pyramid, int levels, int bounded_levels) {
  if (exemplar.empty()) throw InvalidInputError("make_exemplar_levels: the exemplar image is empty");
  if (bounded_levels < 0) throw InvalidInputError("make_exemplar_levels: bounded_levels must be >= 0");
  const Image rgb = as_rgb(exemplar);
  ExemplarLevels ex;
  ex.pyramid = pyramid;
  auto build = [&](bool toroidal) {
    if (pyramid) {
      PyramidOptions po;
      po.levels = levels;
      po.toroidal = toroidal;
      return gaussian_pyramid(rgb, po);
    }
    StackOptions so;
    so.levels = levels;
    so.toroidal = toroidal;
    return gaussian_stack(rgb, so);
  };
  ex.levels = build(true);
  ex.bounded_levels = std::min<int>(bounded_levels, static_cast<int>(ex.levels.size()));
  if (ex.bounded_levels > 0) {  // the bounded levels from the clamped stack
    std::vector<Image> clamped = build(false);
    for (int l = 0; l < ex.bounded_levels; ++l) ex.levels[l] = std::move(clamped[l]);
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
  std::vector<SampleGroup> g;
  GroupScratch scr;
  group_into(ex, samples, center_level, g, scr);
  return g;
}

std::array<float, 3> texel_bilinear(const ExemplarLevels& ex, int level, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
  const auto a = texel(ex, level, x0, y0), b = texel(ex, level, x0 + 1, y0), c = texel(ex, level, x0, y0 + 1),
             d = texel(ex, level, x0 + 1, y0 + 1);
  std::array<float, 3> o{};
  for (int k = 0; k < 3; ++k)
    o[k] = (1 - ay) * ((1 - ax) * a[k] + ax * b[k]) + ay * ((1 - ax) * c[k] + ax * d[k]);
  return o;
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

namespace {

// One group's SSD term; the single definition used by every search so that
// all of them compute bit-identical distances.
inline float group_term(const float* p, const SampleGroup& g) {
  const float e0 = p[0] - g.color[0], e1 = p[1] - g.color[1], e2 = p[2] - g.color[2];
  return g.weight * (e0 * e0 + e1 * e1 + e2 * e2);
}

struct GroupTable {
  std::vector<const float*> base;
  std::vector<int> gx, gy;
};

void group_table(const ExemplarLevels& ex, const std::vector<SampleGroup>& groups, int W, int H, GroupTable& t) {
  const std::size_t G = groups.size();
  t.base.resize(G);
  t.gx.resize(G);
  t.gy.resize(G);
  for (std::size_t g = 0; g < G; ++g) {
    t.base[g] = ex.levels[groups[g].level].data.data();
    t.gx[g] = wrap_coordinate(groups[g].dx, W);
    t.gy[g] = wrap_coordinate(groups[g].dy, H);
  }
}

// d(Q) for Q = (x, y), abandoned (returns a value > bound) once it exceeds bound.
inline float score(const std::vector<SampleGroup>& groups, const GroupTable& t, int W, int H, int x, int y,
                   float bound) {
  float d = 0;
  const std::size_t G = groups.size();
  for (std::size_t g = 0; g < G; ++g) {
    int xx = x + t.gx[g], yy = y + t.gy[g];
    if (xx >= W) xx -= W;
    if (yy >= H) yy -= H;
    d += group_term(t.base[g] + 3 * (static_cast<std::size_t>(yy) * W + xx), groups[g]);
    if (d > bound) return d;
  }
  return d;
}


}  // namespace

void prepare_groups(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level,
                    bool averaging, std::vector<SampleGroup>& out, GroupScratch& scr) {
  out.clear();
  if (!averaging) {
    for (const RegionSample& s : samples) {
      const auto o = sample_offset(ex, s, center_level);
      out.push_back(SampleGroup{o[0], o[1], ex.pyramid ? center_level : s.level, 1.f, s.color});
    }
  } else {
    group_into(ex, samples, center_level, out, scr);
  }
  // Heaviest groups first: partial sums grow fastest, so early termination bites sooner.
  std::stable_sort(out.begin(), out.end(),
                   [](const SampleGroup& a, const SampleGroup& b) { return a.weight > b.weight; });
}

void group_into(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level,
                std::vector<SampleGroup>& out, GroupScratch& scr) {
  out.clear();
  {
    // Open addressing on (level, dx, dy); groups in order of first occurrence,
    // colours summed in double in sample order (as group_samples).
    std::size_t cap = 16;
    while (cap < 2 * samples.size()) cap *= 2;
    scr.key.assign(cap, ~std::uint64_t(0));
    scr.slot.assign(cap, -1);
    scr.sum.clear();
    for (const RegionSample& s : samples) {
      const auto o = sample_offset(ex, s, center_level);
      const int level = ex.pyramid ? center_level : s.level;
      const std::uint64_t key = (std::uint64_t(std::uint32_t(level)) << 48) ^
                                (std::uint64_t(std::uint32_t(o[0]) & 0xFFFFFFu) << 24) ^
                                std::uint64_t(std::uint32_t(o[1]) & 0xFFFFFFu);
      std::size_t h = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 40) & (cap - 1);
      while (scr.key[h] != key && scr.slot[h] >= 0) h = (h + 1) & (cap - 1);
      if (scr.slot[h] < 0) {
        scr.key[h] = key;
        scr.slot[h] = static_cast<int>(out.size());
        out.push_back(SampleGroup{o[0], o[1], level, 0.f, {}});
        scr.sum.push_back({0, 0, 0});
      }
      const int gi = scr.slot[h];
      out[gi].weight += 1.f;
      for (int c = 0; c < 3; ++c) scr.sum[gi][c] += s.color[c];
    }
    for (std::size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < 3; ++c) out[i].color[c] = static_cast<float>(scr.sum[i][c] / out[i].weight);
  }
}

MatchBox candidate_box(int w, int h, int min_dx, int max_dx, int min_dy, int max_dy) {
  MatchBox b;
  b.restricted = true;
  b.x0 = -min_dx;
  b.x1 = w - 1 - max_dx;
  b.y0 = -min_dy;
  b.y1 = h - 1 - max_dy;
  return b;
}

namespace {

// The box a match searches: clipped `box` if restricted, else the whole
// level (wrapping) or the box keeping every group inside (bounded).
MatchBox search_box(const ExemplarLevels& ex, const std::vector<SampleGroup>& groups, int W, int H,
                    const MatchBox& box, int center_level) {
  const bool wraps = ex.wraps(center_level);
  MatchBox b = box;
  if (!b.restricted) {
    if (wraps) {
      b.x0 = b.y0 = 0, b.x1 = W - 1, b.y1 = H - 1;
    } else {
      int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
      for (const SampleGroup& g : groups)
        x0 = std::min(x0, g.dx), x1 = std::max(x1, g.dx), y0 = std::min(y0, g.dy), y1 = std::max(y1, g.dy);
      const MatchBox c = candidate_box(W, H, x0, x1, y0, y1);
      b.x0 = c.x0, b.x1 = c.x1, b.y0 = c.y0, b.y1 = c.y1;
    }
  }
  b.x0 = std::max(b.x0, 0), b.y0 = std::max(b.y0, 0), b.x1 = std::min(b.x1, W - 1), b.y1 = std::min(b.y1, H - 1);
  if (!wraps && b.x0 <= b.x1 && b.y0 <= b.y1)
    for (const SampleGroup& g : groups)
      if (b.x0 + g.dx < 0 || b.x1 + g.dx >= W || b.y0 + g.dy < 0 || b.y1 + g.dy >= H)
        throw InvalidInputError("ExemplarIndex::match: the candidate box lets group (" + std::to_string(g.dx) + "," +
                                std::to_string(g.dy) + ") leave a bounded level");
  return b;
}

}  // namespace

MatchResult match_region(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level,
                         const MatchOptions& opt) {
  if (center_level < 0 || center_level >= static_cast<int>(ex.levels.size()))
    throw InvalidInputError("match_region: centre level " + std::to_string(center_level) + " out of range");
  if (opt.rows_per_block < 1) throw InvalidInputError("match_region: rows_per_block must be >= 1");
  MatchResult res;
  if (samples.empty()) return res;
  std::vector<SampleGroup> groups;
  GroupScratch gs;
  prepare_groups(ex, samples, center_level, opt.averaging, groups, gs);
  const int W = ex.width(center_level), H = ex.height(center_level);
  GroupTable tab;
  group_table(ex, groups, W, H, tab);
  const MatchBox box = search_box(ex, groups, W, H, MatchBox{}, center_level);
  if (box.x1 < box.x0 || box.y1 < box.y0) return res;  // the region does not fit the exemplar
  const int blocks = (H + opt.rows_per_block - 1) / opt.rows_per_block;
  std::vector<float> best_d(blocks, std::numeric_limits<float>::infinity());
  std::vector<int> best_i(blocks, -1);
  tbb::parallel_for(0, blocks, [&](int b) {
    float bd = std::numeric_limits<float>::infinity();
    int bi = -1;
    const int y0 = std::max(box.y0, b * opt.rows_per_block), y1 = std::min(box.y1 + 1, (b + 1) * opt.rows_per_block);
    for (int y = y0; y < y1; ++y)
      for (int x = box.x0; x <= box.x1; ++x) {
        const float d = score(groups, tab, W, H, x, y, bd);
        if (d < bd) bd = d, bi = y * W + x;  // row-major: the first of equal minima is kept
      }
    best_d[b] = bd;
    best_i[b] = bi;
  });
  float bd = std::numeric_limits<float>::infinity();
  int bi = -1;
  for (int b = 0; b < blocks; ++b)
    if (best_i[b] >= 0 && best_d[b] < bd) bd = best_d[b], bi = best_i[b];
  if (bi < 0) bi = box.y0 * W + box.x0, bd = 0;  // only NaN colours: degenerate, take the first candidate
  res.found = true;
  res.qx = bi % W;
  res.qy = bi / W;
  res.distance = bd;
  res.comparisons = groups.size();
  return res;
}

ExemplarIndex::ExemplarIndex(const ExemplarLevels& ex) : ex_(&ex) {
  levels_.resize(ex.levels.size());
  for (std::size_t l = 0; l < ex.levels.size(); ++l) {
    const Image& im = ex.levels[l];
    const std::size_t n = static_cast<std::size_t>(im.width) * im.height;
    for (int c = 0; c < 3; ++c) {
      levels_[l].plane[c].resize(n);
      for (std::size_t i = 0; i < n; ++i) levels_[l].plane[c][i] = im.data[3 * i + c];
    }
  }
}

namespace {

// d[x] += m |I(x + sx) - c|^2 over x in [0, n): the same arithmetic, in the
// same order, as group_term (so sums are bit-identical to the scalar scan).
inline void accumulate(float* d, const float* r, const float* g, const float* b, int n, const SampleGroup& grp) {
  const float c0 = grp.color[0], c1 = grp.color[1], c2 = grp.color[2], m = grp.weight;
  for (int x = 0; x < n; ++x) {
    const float e0 = r[x] - c0, e1 = g[x] - c1, e2 = b[x] - c2;
    d[x] += m * (e0 * e0 + e1 * e1 + e2 * e2);
  }
}

// The region as a sparse stencil over one candidate row (ExemplarIndex::
// match): per group its offset (wrapped into [0, W) x [0, H) when the level
// wraps) and the R, G, B planes of its level; candidates x0 .. x0 + nx - 1.
struct RowStencil {
  const std::vector<SampleGroup>& groups;
  const float* const* planes;  // 3 per group
  const int* gx;
  const int* gy;
  int W, H, x0, nx;
  bool wraps;
  // The R, G, B rows of group g's level that candidate row y reads.
  std::array<const float*, 3> row(std::size_t g, int y) const {
    int yy = y + gy[g];
    if (yy >= H) yy -= H;
    const std::size_t r = static_cast<std::size_t>(yy) * W;
    return {planes[3 * g] + r, planes[3 * g + 1] + r, planes[3 * g + 2] + r};
  }
};

// The starting value of every candidate's sum of row y: its repetition
// penalty bin, or 0.
void start_row(const MatchBox& box, int y, int sc, int x0, int nx, std::vector<float>& d) {
  if (box.bin_penalty) {
    const float* prow = box.bin_penalty + static_cast<std::size_t>((y * sc) / box.bin) * box.bins_x;
    for (int x = 0; x < nx; ++x) d[x] = prow[((x0 + x) * sc) / box.bin];
  } else {
    std::fill(d.begin(), d.end(), 0.0f);
  }
}

// Phase 1 of a row (vectorised): the heaviest groups add their terms to all
// candidates of the row from one contiguous (periodic: wrapped in two
// pieces) run of their level's planes; after 1, 2, 4, ... groups the row is
// dropped if every partial sum reached bd, and phase 1 ends once few
// candidates (an eighth) survive. Returns the groups added, or none when
// the row is dropped.
std::optional<std::size_t> add_leading_groups(const RowStencil& s, int y, float bd, float* d) {
  const std::size_t G = s.groups.size();
  std::size_t g = 0, next_check = 1;
  while (g < G) {
    const auto [r, gg, b] = s.row(g, y);
    if (s.wraps) {
      int st = s.x0 + s.gx[g];  // candidate x0 + i reads texel x0 + i + dx (mod W)
      if (st >= s.W) st -= s.W;
      const int first = std::min(s.nx, s.W - st);
      accumulate(d, r + st, gg + st, b + st, first, s.groups[g]);
      accumulate(d + first, r, gg, b, s.nx - first, s.groups[g]);
    } else {
      const int st = s.x0 + s.gx[g];
      accumulate(d, r + st, gg + st, b + st, s.nx, s.groups[g]);
    }
    ++g;
    if (g == next_check && g < G) {
      next_check *= 2;
      int na = 0;
      for (int x = 0; x < s.nx; ++x) na += d[x] < bd ? 1 : 0;
      if (na == 0) return std::nullopt;
      if (8 * na <= s.nx) break;  // few survivors: phase 2
    }
  }
  return g;
}

// The best candidate so far (row-major: the first of equal minima is kept)
// and the candidates whose sum was completed.
struct RowBest {
  float bd = std::numeric_limits<float>::infinity();
  int bi = -1;
  std::size_t scored = 0;
};

// Phase 2 of a row: each candidate still below the best adds the groups
// from g on alone and is abandoned as soon as its partial sum reaches the
// best distance. alive and rowp are scratch (nx and 3 G entries).
void finish_survivors(const RowStencil& s, int y, std::size_t g, const float* d, int* alive,
                      const float** rowp, RowBest& best) {
  const std::size_t G = s.groups.size();
  int na = 0;
  for (int x = 0; x < s.nx; ++x)
    if (d[x] < best.bd) alive[na++] = x;
  for (std::size_t h = g; h < G; ++h) {
    const auto r = s.row(h, y);
    rowp[3 * h] = r[0];
    rowp[3 * h + 1] = r[1];
    rowp[3 * h + 2] = r[2];
  }
  for (int a = 0; a < na; ++a) {
    const int x = alive[a];
    float dx = d[x];
    std::size_t h = g;
    for (; h < G; ++h) {
      const SampleGroup& grp = s.groups[h];
      int xx = s.x0 + x + s.gx[h];
      if (s.wraps && xx >= s.W) xx -= s.W;
      const float e0 = rowp[3 * h][xx] - grp.color[0], e1 = rowp[3 * h + 1][xx] - grp.color[1],
                  e2 = rowp[3 * h + 2][xx] - grp.color[2];
      dx += grp.weight * (e0 * e0 + e1 * e1 + e2 * e2);
      if (dx >= best.bd) break;
    }
    if (h < G) continue;  // abandoned
    ++best.scored;
    if (dx < best.bd) best.bd = dx, best.bi = y * s.W + s.x0 + x;  // x increasing: the first of equal minima
  }
}

}  // namespace

MatchResult ExemplarIndex::match(const std::vector<SampleGroup>& groups, int center_level) const {
  return match(groups, center_level, MatchBox{});
}

MatchResult ExemplarIndex::match(const std::vector<SampleGroup>& groups, int center_level, const MatchBox& box_in) const {
  const ExemplarLevels& ex = *ex_;
  if (center_level < 0 || center_level >= static_cast<int>(ex.levels.size()))
    throw InvalidInputError("ExemplarIndex::match: centre level " + std::to_string(center_level) + " out of range");
  MatchResult res;
  if (groups.empty()) return res;
  for (const SampleGroup& g : groups)
    if (g.level < 0 || g.level >= static_cast<int>(ex.levels.size()))
      throw InvalidInputError("ExemplarIndex::match: group level " + std::to_string(g.level) + " out of range");
  const int W = ex.width(center_level), H = ex.height(center_level);
  const MatchBox box = search_box(ex, groups, W, H, box_in, center_level);
  if (box.x1 < box.x0 || box.y1 < box.y0) return res;  // no candidate keeps the region inside
  const int x0 = box.x0, nx = box.x1 - box.x0 + 1;
  const bool wraps = ex.wraps(center_level);
  const int sc = ex.scale(center_level);
  const std::size_t G = groups.size();
  thread_local std::vector<float> d;
  thread_local std::vector<int> gx, gy, alive;
  thread_local std::vector<const float*> planes, rowp;
  d.resize(nx);
  gx.resize(G);
  gy.resize(G);
  alive.resize(nx);
  planes.resize(3 * G);
  rowp.resize(3 * G);
  // Periodic: offsets wrapped into [0, W); non-periodic: as they are (the box keeps them inside).
  for (std::size_t g = 0; g < G; ++g) {
    gx[g] = wraps ? wrap_coordinate(groups[g].dx, W) : groups[g].dx,
    gy[g] = wraps ? wrap_coordinate(groups[g].dy, H) : groups[g].dy;
    for (int c = 0; c < 3; ++c) planes[3 * g + c] = levels_[groups[g].level].plane[c].data();
  }
  const RowStencil s{groups, planes.data(), gx.data(), gy.data(), W, H, x0, nx, wraps};
  RowBest best;
  // Row by row: phase 1 adds the heaviest groups to the whole row, phase 2
  // finishes the few survivors one by one. Both phases add the same terms
  // in the same order with the same arithmetic, so every finished sum
  // equals the full scan's, bit for bit, and so does the argmin (first of
  // equal minima). Terms are >= 0 and a later candidate must be strictly
  // better to win, so dropping a sum that reached the best is exact. A
  // repetition penalty is the starting value of each sum (>= 0).
  for (int y = box.y0; y <= box.y1; ++y) {
    start_row(box, y, sc, x0, nx, d);
    const std::optional<std::size_t> g = add_leading_groups(s, y, best.bd, d.data());
    if (!g) continue;  // dropped
    if (*g < G) {
      finish_survivors(s, y, *g, d.data(), alive.data(), rowp.data(), best);
      continue;
    }
    for (int x = 0; x < nx; ++x)  // every term added over the whole row
      if (d[x] < best.bd)
        best.bd = d[x], best.bi = y * W + x0 + x;  // row-major: the first of equal minima is kept
    best.scored += static_cast<std::size_t>(nx);
  }
  if (best.bi < 0)
    best.bi = box.y0 * W + x0, best.bd = 0;  // only NaN colours: degenerate, take the box's first texel
  res.found = true;
  res.qx = best.bi % W;
  res.qy = best.bi / W;
  res.distance = best.bd;
  res.comparisons = G;
  res.candidates = best.scored;
  return res;
}

}  // namespace surftex
