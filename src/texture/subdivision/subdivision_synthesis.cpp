// SPDX-License-Identifier: AGPL-3.0-or-later
// Subdivision graph-matching synthesis (Bangay & Morkel 2006, sections 3-4).
// See subdivision_synthesis.h.
#include "texture/subdivision/subdivision_synthesis.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <unordered_map>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <string>

#include "texture/subdivision/adaptive_sqrt2_subdivide.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"
#include "texture/subdivision/sqrt2_subdivide.h"
#include "geometry/polygon_util.h"
#include "geometry/timer.h"
#include "texture/gaussian_pyramid.h"
#include "texture/image_ops.h"
#include "texture/wrap_seam_ratio.h"
#include "texture/subdivision/graph_cut_transfer.h"

namespace surftex {
namespace {

void validate(const SubdivisionSynthesisOptions& o) {
  auto bad = [](const std::string& what, double v, const std::string& range) {
    throw InvalidInputError("subdivision synthesis: " + what + " must be " + range + " (got " + std::to_string(v) + ")");
  };
  if (!(o.r_scale >= 0) || !std::isfinite(o.r_scale)) bad("r_scale", o.r_scale, "> 0, or 0 for the repeats");
  if (!(o.texels_per_edge >= 0) || !std::isfinite(o.texels_per_edge))
    bad("texels_per_edge", o.texels_per_edge, "> 0, or 0 for the repeats");
  if (!(o.repeats > 0) || !std::isfinite(o.repeats)) bad("repeats", o.repeats, "> 0");
  if (!(o.min_relative_detail >= 0 && o.min_relative_detail <= 1))
    bad("min_relative_detail", o.min_relative_detail, "in [0, 1]");
  if (o.levels < -1 || o.levels > 12) bad("levels", o.levels, "in 0..12, or -1 to choose");
  if (o.max_vertices < 1000) bad("max_vertices", static_cast<double>(o.max_vertices), ">= 1000");
  if (!(o.adaptive_factor >= 0) || !std::isfinite(o.adaptive_factor)) bad("adaptive_factor", o.adaptive_factor, ">= 0");
  if (o.adaptive_steps < 0 || o.adaptive_steps > 32) bad("adaptive_steps", o.adaptive_steps, "in 0..32");
  if (o.passes < 1 || o.passes > 16) bad("passes", o.passes, "in 1..16");
  if (!(o.region_texels > 0) || !std::isfinite(o.region_texels)) bad("region_texels", o.region_texels, "> 0");
  if (!(o.sigma > 0) || !std::isfinite(o.sigma)) bad("sigma", o.sigma, "> 0");
  if (o.max_k < 1 || o.max_k > 64) bad("max_k", o.max_k, "in 1..64");
  if (!(o.wrap_threshold > 0) || !std::isfinite(o.wrap_threshold)) bad("wrap_threshold", o.wrap_threshold, "> 0");
  if (!(o.repetition_penalty >= 0) || !std::isfinite(o.repetition_penalty))
    bad("repetition_penalty", o.repetition_penalty, ">= 0");
  if (o.exhaustive_levels < 0 || o.exhaustive_levels > 13) bad("exhaustive_levels", o.exhaustive_levels, "in 0..13");
}

// Mesh figures the scale needs: bounding box, area, element counts.
struct MeshFigures {
  double longest = 0, area = 0, mean_edge = 0;
  std::size_t vertices = 0, faces = 0, edges = 0;
};

MeshFigures mesh_figures(const Mesh& mesh) {
  MeshFigures f;
  f.longest = longest_bbox_side(mesh);
  for (FaceIndex fc : mesh.faces()) f.area += polygon_area(mesh, fc);
  double s = 0;
  for (EdgeIndex e : mesh.edges())
    s += std::sqrt((mesh.point(mesh.vertex(e, 0)) - mesh.point(mesh.vertex(e, 1))).squared_length());
  f.vertices = mesh.number_of_vertices();
  f.faces = mesh.number_of_faces();
  f.edges = mesh.number_of_edges();
  f.mean_edge = f.edges ? s / f.edges : 0.0;
  return f;
}

// An exemplar reduced to w x h: halved with the binomial blur while more than
// twice the target, then bilinear (no aliasing for strong reductions). A
// periodic one is blurred and resampled around its borders, so that it still
// tiles (clamped borders put a step at the wrap: pebbles_256 reduced to 61 px
// measured a wrap-seam ratio of 1.53, from 0.76).
Image reduce_exemplar(const Image& img, int w, int h, bool periodic) {
  Image cur = img;
  while (cur.width >= 2 * w && cur.height >= 2 * h) {
    PyramidOptions po;
    po.levels = 2;
    po.toroidal = periodic;
    cur = gaussian_pyramid(cur, po)[1];
  }
  return resize_bilinear(cur, w, h, periodic);
}

// detail_kept of an image's luminance (one channel).
double luminance_detail_kept(const Image& lum, double scale) {
  const int w = lum.width, h = lum.height;
  const int rw = std::max(1, static_cast<int>(std::lround(w * scale / 2))),
            rh = std::max(1, static_cast<int>(std::lround(h * scale / 2)));
  const Image back = resize_bilinear(reduce_exemplar(lum, rw, rh, false), w, h, false);
  double mean = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) mean += lum.at(x, y, 0);
  mean /= static_cast<double>(w) * h;
  double total = 0, lost = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double v = lum.at(x, y, 0), d = v - back.at(x, y, 0);
      total += (v - mean) * (v - mean);
      lost += d * d;
    }
  return total > 0 ? std::max(0.0, 1.0 - lost / total) : 1.0;
}

}  // namespace

double detail_kept(const Image& img, double scale) {
  if (img.empty()) throw InvalidInputError("detail_kept: the image is empty");
  return luminance_detail_kept(luminance(img), scale);
}

Image resample_as_synthesised(const Image& img, const SubdivisionScale& scale, bool periodic) {
  if (img.empty()) throw InvalidInputError("resample_as_synthesised: the image is empty");
  if (scale.exemplar_scale < 1.0)
    return reduce_exemplar(img, scale.exemplar_width, scale.exemplar_height, periodic);
  return img;
}

namespace {

// The depth and exemplar reduction for r_mesh exemplar texels per mesh unit
// (step 1): the fewest levels whose vertex spacing is one texel, within
// max_vertices, else the exemplar reduced to the spacing reached.
void choose_depth(const MeshFigures& f, int w, int h, double r_mesh, const SubdivisionSynthesisOptions& opt,
                  SubdivisionScale& sc) {
  const double unit = opt.normalize_units ? f.longest : 1.0;
  sc.r_scale = r_mesh * unit;
  sc.repeats = r_mesh * f.longest / w;
  // Counts after L uniform steps: F_L = E_{L-1}, E_L = 2 E_{L-1}, V_L = V_{L-1} + F_{L-1}
  // (sqrt2_subdivide.h: one face per edge, two edges per old edge); the
  // vertex spacing of the final quads is sqrt(area / F_L).
  std::vector<double> V{double(f.vertices)}, F{double(f.faces)}, E{double(f.edges)};
  for (int l = 1; l <= 12; ++l) {
    V.push_back(V[l - 1] + F[l - 1]);
    F.push_back(E[l - 1]);
    E.push_back(2 * E[l - 1]);
  }
  auto spacing = [&](int l) { return l == 0 ? f.mean_edge : std::sqrt(f.area / F[l]); };
  const double texel0 = 1.0 / r_mesh;
  int L = opt.levels;
  sc.budget_limited = false;
  if (L < 0) {
    sc.levels_chosen = true;
    L = 0;
    while (L < 12 && spacing(L) > texel0) ++L;
    while (L > 0 && V[L] > static_cast<double>(opt.max_vertices)) {
      --L;
      sc.budget_limited = true;
    }
    if (L == 0 && V[0] > static_cast<double>(opt.max_vertices)) sc.budget_limited = true;
  }
  sc.levels = L;
  sc.predicted_vertices = static_cast<std::size_t>(V[L]);
  double texel = texel0;
  if (sc.budget_limited) texel = std::max(texel0, spacing(L));
  // The reduced exemplar keeps at least 16 pixels on its shorter side.
  const double min_scale = std::min(1.0, 16.0 / std::min(w, h));
  sc.exemplar_scale = std::clamp(texel0 / texel, min_scale, 1.0);
  texel = texel0 / sc.exemplar_scale;
  sc.exemplar_width = std::max(1, static_cast<int>(std::lround(w * sc.exemplar_scale)));
  sc.exemplar_height = std::max(1, static_cast<int>(std::lround(h * sc.exemplar_scale)));
  sc.texel_size = texel;
  sc.spacing_texels = spacing(L) / texel;
}

// The default scale's trade (SubdivisionSynthesisOptions::min_relative_detail):
// while the budget's reduction keeps less than that share of the detail the
// unreduced exemplar keeps, show fewer repeats (5% steps, down to one) so the
// exemplar is reduced less.
void keep_exemplar_detail(const MeshFigures& f, const Image& exemplar, const SubdivisionSynthesisOptions& opt,
                          SubdivisionScale& sc) {
  if (!(opt.min_relative_detail > 0) || sc.exemplar_scale >= 1.0 || !sc.budget_limited) return;
  const Image lum = luminance(exemplar);  // once: up to 22 evaluations below
  const double full = luminance_detail_kept(lum, 1.0);
  if (!(full > 0)) return;
  auto relative = [&](const SubdivisionScale& s) { return luminance_detail_kept(lum, s.exemplar_scale) / full; };
  sc.relative_detail = relative(sc);
  double repeats = opt.repeats;
  while (sc.relative_detail < opt.min_relative_detail && sc.exemplar_scale < 1.0 && repeats > 1.0) {
    repeats = std::max(1.0, repeats * 0.95);
    choose_depth(f, exemplar.width, exemplar.height, repeats * exemplar.width / f.longest, opt, sc);
    sc.relative_detail = sc.exemplar_scale < 1.0 ? relative(sc) : 1.0;
  }
}

}  // namespace

SubdivisionScale choose_subdivision_scale(const Mesh& mesh, int w, int h, double input_mean_edge,
                                          const SubdivisionSynthesisOptions& opt, const Image* exemplar) {
  validate(opt);
  if (w < 1 || h < 1) throw InvalidInputError("subdivision synthesis: the exemplar is empty");
  if (exemplar && (exemplar->width != w || exemplar->height != h))
    throw InvalidInputError("subdivision synthesis: the exemplar is not w x h");
  const MeshFigures f = mesh_figures(mesh);
  if (!(f.longest > 0) || !std::isfinite(f.longest) || !(f.area > 0))
    throw InvalidInputError("subdivision synthesis: the mesh has no extent (or non-finite coordinates)");
  SubdivisionScale sc;
  const double unit = opt.normalize_units ? f.longest : 1.0;
  double r_mesh = 0;  // exemplar texels per mesh unit
  if (opt.r_scale > 0) {
    sc.scale_from = "rscale";
    r_mesh = opt.r_scale / unit;
  } else if (opt.texels_per_edge > 0) {
    if (!(input_mean_edge > 0) || !std::isfinite(input_mean_edge))
      throw InvalidInputError("subdivision synthesis: texels_per_edge needs a mesh with edges of positive length");
    sc.scale_from = "texels_per_edge";
    r_mesh = opt.texels_per_edge / input_mean_edge;
  } else {
    sc.scale_from = "repeats";
    r_mesh = opt.repeats * w / f.longest;
  }
  choose_depth(f, w, h, r_mesh, opt, sc);
  sc.repeats_requested = sc.repeats;
  if (exemplar && sc.scale_from == std::string("repeats") && !opt.repeats_fixed)
    keep_exemplar_detail(f, *exemplar, opt, sc);
  sc.texels_per_edge = sc.repeats * w / f.longest * input_mean_edge;
  return sc;
}

namespace {

// One vertex's speculative work (region, samples, match, cut): a pure
// function of the geometry and of the colour state it reads.
struct VertexJob {
  std::size_t p = 0;
  int k = 0;
  bool has_samples = false;
  KRegion reg;
  MatchResult m;
  std::size_t groups = 0;
  struct Write {
    std::size_t vertex;
    std::array<float, 3> color;
    int level;                  ///< stack level the colour was read from
    std::array<int, 2> source;  ///< level-0 exemplar texel
    ExemplarLookup lookup;      ///< where the colour was read
  };
  std::vector<Write> writes;  ///< centre first
  bool searched_all = false;  ///< the index searched the candidate box (no coherent candidate, or an exhaustive level)
  double t_region = 0, t_match = 0, t_transfer = 0;
};

// Where on the surface each exemplar area is shown: the surface is cut into
// cubic cells one exemplar width wide; each cell counts, per exemplar bin
// (16 x 16 bins over level 0), the vertices in it whose colour came from that
// bin. A match's repetition term reads the 27 cells around its centre.
class RepetitionGrid {
 public:
  RepetitionGrid(double cell, int ex_w, int ex_h)
      : cell_(cell), bin_(std::max(1, (std::max(ex_w, ex_h) + 15) / 16)),
        bx_((ex_w + bin_ - 1) / bin_), by_((ex_h + bin_ - 1) / bin_) {}
  int bin() const { return bin_; }
  int bins_x() const { return bx_; }
  std::size_t bins() const { return static_cast<std::size_t>(bx_) * by_; }
  void add(const std::array<double, 3>& p, const std::array<int, 2>& src, int delta) {
    if (src[0] < 0) return;
    auto& c = cells_[key(cell_of(p))];
    if (c.empty()) c.assign(bins() + 1, 0);
    c[slot(src)] += delta;
    c.back() += delta;  // total
  }
  /// counts[b] = vertices near p whose source is in bin b (the 27 cells),
  /// minus `exclude` (the region's own); returns their total.
  double near_counts(const std::array<double, 3>& p, const std::vector<std::array<int, 2>>& exclude,
                     std::vector<float>& counts) const {
    counts.assign(bins(), 0.f);
    double total = 0;
    const auto c = cell_of(p);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          const auto& v = it->second;
          for (std::size_t b = 0; b < counts.size(); ++b) counts[b] += static_cast<float>(v[b]);
          total += v.back();
        }
    for (const auto& src : exclude)
      if (src[0] >= 0 && counts[slot(src)] > 0) counts[slot(src)] -= 1.f, total -= 1;
    return total;
  }

 private:
  std::array<std::int64_t, 3> cell_of(const std::array<double, 3>& p) const {
    return {static_cast<std::int64_t>(std::floor(p[0] / cell_)), static_cast<std::int64_t>(std::floor(p[1] / cell_)),
            static_cast<std::int64_t>(std::floor(p[2] / cell_))};
  }
  static std::uint64_t key(const std::array<std::int64_t, 3>& c) {
    return (std::uint64_t(c[0] & 0x1FFFFF) << 42) | (std::uint64_t(c[1] & 0x1FFFFF) << 21) | std::uint64_t(c[2] & 0x1FFFFF);
  }
  std::size_t slot(const std::array<int, 2>& s) const {
    return static_cast<std::size_t>(std::min(s[1] / bin_, by_ - 1)) * bx_ + std::min(s[0] / bin_, bx_ - 1);
  }
  double cell_;
  int bin_, bx_, by_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

// Direct texel addresses of a job's groups (group_footprint).
struct GroupFootprint {
  bool direct = false;
  int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  std::vector<const float*> data;
  std::vector<std::ptrdiff_t> offset;
};

struct JobScratch {
  GroupFootprint footprint;
  RegionScratch region;
  GroupScratch group;
  std::vector<RegionSample> samples;
  std::vector<SampleGroup> groups;
  std::vector<TransferNode> nodes;
  std::vector<std::array<int, 2>> offsets, own_sources;
  std::vector<ExemplarLookup> lookups;
  std::vector<char> inside;
  std::vector<float> penalty;
};

struct PassContext {
  const RegionGraph& graph;
  const SurfaceFrames& fr;
  const ExemplarLevels& ex;
  const ExemplarIndex& index;
  const std::vector<int>& level;
  const std::vector<char>& colored;
  const std::vector<Color3f>& color;
  const std::vector<int>& color_level;  ///< stack level each vertex's colour was read from
  const std::vector<std::array<int, 2>>& source;  ///< level-0 source texel per vertex
  const std::vector<ExemplarLookup>& lookup;      ///< where each vertex's colour was read
  const RepetitionGrid* grid;           ///< null = no repetition term
  double sigma2;                        ///< summed channel variance of level 0
  double r_scale;
  const SubdivisionSynthesisOptions& opt;
  bool coherent;                        ///< coherence search (SubdivisionSynthesisOptions::exhaustive_levels)
};

// The groups' offsets as addresses: when every group's level has the size of
// the centre's level, a candidate whose footprint [x0, x1] x [y0, y1] lies
// inside it reads group k's texel at data[k] + offset[k] + 3 (qy W + qx).
void group_footprint(const ExemplarLevels& ex, int lp, const std::vector<SampleGroup>& groups, GroupFootprint& fp) {
  const int W = ex.width(lp), H = ex.height(lp);
  fp.direct = true;
  fp.x0 = fp.y0 = 0, fp.x1 = fp.y1 = 0;
  fp.data.resize(groups.size());
  fp.offset.resize(groups.size());
  for (std::size_t k = 0; k < groups.size(); ++k) {
    const SampleGroup& g = groups[k];
    const Image& im = ex.levels[g.level];
    if (im.width != W || im.height != H || im.channels != 3) fp.direct = false;
    fp.x0 = std::min(fp.x0, g.dx), fp.x1 = std::max(fp.x1, g.dx);
    fp.y0 = std::min(fp.y0, g.dy), fp.y1 = std::max(fp.y1, g.dy);
    fp.data[k] = im.data.data();
    fp.offset[k] = (static_cast<std::ptrdiff_t>(g.dy) * W + g.dx) * 3;
  }
}

// Coherence search (SubdivisionSynthesisOptions::exhaustive_levels): the best
// of the centres implied by the region's sources. found = false when no
// region vertex has a source implying a centre inside the box.
// The coherent candidate of region vertex i at the sub-texel position its
// lookup gives (that lookup carried back to the centre), so that the new copy
// continues its neighbour's without the rounding of the integer match: half a
// texel of phase between neighbouring copies breaks a fine periodic pattern.
// Stacks only (a pyramid's levels have their own texel grids).
void continue_subtexel(const PassContext& c, const KRegion& reg, std::size_t i, const std::array<int, 2>& offset,
                       int sc, MatchResult& best) {
  const ExemplarLookup& l = c.lookup[reg.vertices[i]];
  const auto& src = c.source[reg.vertices[i]];
  best.subtexel = false;
  if (c.ex.pyramid || l.level < 0) return;
  const double rx = (l.x - c.r_scale * reg.uv[i][0]) - (src[0] / sc - offset[0]);
  const double ry = (l.y + c.r_scale * reg.uv[i][1]) - (src[1] / sc - offset[1]);
  if (!(std::abs(rx) <= 1.0 && std::abs(ry) <= 1.0)) return;
  best.subtexel = true;
  best.x = best.qx + rx, best.y = best.qy + ry;
}

MatchResult coherent_match(const PassContext& c, const KRegion& reg, int lp, const MatchBox& box, JobScratch& s) {
  MatchResult best;
  const int W = c.ex.width(lp), H = c.ex.height(lp), sc = c.ex.scale(lp);
  const bool bounded = !c.ex.wraps(lp);
  std::array<std::array<int, 2>, 32> seen;
  int nseen = 0;
  double bd = std::numeric_limits<double>::infinity();
  GroupFootprint& fp = s.footprint;
  group_footprint(c.ex, lp, s.groups, fp);
  for (std::size_t i = 0; i < reg.vertices.size() && nseen < 32; ++i) {
    const std::size_t v = reg.vertices[i];
    const auto& src = c.source[v];
    if (src[0] < 0 || (i > 0 && !c.colored[v])) continue;
    int qx = src[0] / sc - s.offsets[i][0], qy = src[1] / sc - s.offsets[i][1];
    if (bounded) {
      if (qx < box.x0 || qx > box.x1 || qy < box.y0 || qy > box.y1) continue;
    } else {
      qx = wrap_coordinate(qx, W), qy = wrap_coordinate(qy, H);
    }
    bool dup = false;
    for (int k = 0; k < nseen && !dup; ++k) dup = seen[k][0] == qx && seen[k][1] == qy;
    if (dup) continue;
    seen[nseen++] = {qx, qy};
    double d = box.bin_penalty ? box.bin_penalty[((qy * sc) / box.bin) * box.bins_x + (qx * sc) / box.bin] : 0.0;
    const bool inside = fp.direct && qx + fp.x0 >= 0 && qx + fp.x1 < W && qy + fp.y0 >= 0 && qy + fp.y1 < H;
    const std::ptrdiff_t at = (static_cast<std::ptrdiff_t>(qy) * W + qx) * 3;
    for (std::size_t k = 0; k < s.groups.size(); ++k) {
      const SampleGroup& g = s.groups[k];
      // The footprint inside the level: the texel by address (as texel() reads it).
      const float* t = inside ? fp.data[k] + at + fp.offset[k] : texel_pointer(c.ex, g.level, qx + g.dx, qy + g.dy);
      for (int j = 0; j < 3; ++j) d += g.weight * (double(t[j]) - g.color[j]) * (double(t[j]) - g.color[j]);
      if (d >= bd) break;
    }
    if (d < bd || (d == bd && qy * W + qx < best.qy * W + best.qx)) {
      bd = d;
      best.found = true;
      best.qx = qx, best.qy = qy, best.distance = d;
      continue_subtexel(c, reg, i, s.offsets[i], sc, best);
    }
  }
  best.comparisons = s.groups.size();
  best.candidates = static_cast<std::size_t>(nseen);
  return best;
}

// Non-periodic exemplar: the region vertices whose offset lies within a
// quarter of the level's size of the centre keep a texture (inside); the box
// of candidates keeps all of them inside the level, so it is at least half
// the level wide (a region clipped to half the exemplar would leave a single
// candidate, the same for every vertex of a coarse level).
MatchBox bounded_region(const PassContext& c, const KRegion& reg, int lp, JobScratch& s) {
  const int W = c.ex.width(lp), H = c.ex.height(lp);
  const int hx = std::max(1, (W - 1) / 4), hy = std::max(1, (H - 1) / 4);
  int x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  s.inside.assign(reg.vertices.size(), 1);
  for (std::size_t i = 0; i < reg.vertices.size(); ++i) {
    const auto& o = s.offsets[i];
    if (std::abs(o[0]) > hx || std::abs(o[1]) > hy) {
      s.inside[i] = 0;
      continue;
    }
    x0 = std::min(x0, o[0]), x1 = std::max(x1, o[0]), y0 = std::min(y0, o[1]), y1 = std::max(y1, o[1]);
  }
  return candidate_box(W, H, x0, x1, y0, y1);
}

// The repetition term per exemplar bin (see SubdivisionSynthesisOptions::
// repetition_penalty), scaled by the samples' total weight.
void repetition_term(const PassContext& c, std::size_t p, const KRegion& reg, double weight, JobScratch& s) {
  s.own_sources.clear();
  for (std::size_t v : reg.vertices) s.own_sources.push_back(c.source[v]);
  const double total = c.grid->near_counts(c.graph.position[p], s.own_sources, s.penalty);
  const double mean = total / static_cast<double>(s.penalty.size());
  const double coef = c.opt.repetition_penalty * c.sigma2 * weight;
  for (float& x : s.penalty) x = mean > 0 ? static_cast<float>(coef * std::max(0.0, x / mean - 1.0)) : 0.f;
}

void run_job(const PassContext& c, std::size_t p, VertexJob& job, JobScratch& s) {
  const SubdivisionSynthesisOptions& opt = c.opt;
  auto t0 = std::chrono::steady_clock::now();
  job.p = p;
  job.writes.clear();
  job.has_samples = false;
  const int lp = c.level[p];
  const double e = c.fr.mean_edge[p] > 0 ? c.fr.mean_edge[p] : c.fr.mean_edge_length;
  // n counted in texels of the centre's level (a = 2), or in level-0 texels
  // for a stack with level_relative_region off (a = 1, the paper's choice).
  const bool per_level = c.ex.pyramid || opt.level_relative_region;
  job.k = region_k(opt.region_texels, lp, per_level, c.r_scale, e, opt.max_k);
  k_region(c.graph, p, job.k, opt.coordinates, job.reg, s.region, opt.graph_cut);
  const KRegion& reg = job.reg;
  // Offsets of every region vertex at the centre's level (the same for all
  // levels of a stack).
  s.offsets.resize(reg.vertices.size());
  for (std::size_t i = 0; i < reg.vertices.size(); ++i)
    s.offsets[i] = sample_offset(c.ex, RegionSample{c.r_scale * reg.uv[i][0], c.r_scale * reg.uv[i][1], 0, {}}, lp);
  MatchBox box;
  const bool bounded = !c.ex.wraps(lp);
  if (bounded) box = bounded_region(c, reg, lp, s);
  s.samples.clear();
  double weight = 0;
  for (std::size_t i = 1; i < reg.vertices.size(); ++i) {
    const std::size_t v = reg.vertices[i];
    if (!c.colored[v] || (bounded && !s.inside[i])) continue;
    const Color3f& col = c.color[v];
    // Compared at the level its colour represents (a colour carried from a
    // coarser mesh level is a blurred one: matching it against sharper texels
    // turns blurred dark seams into solid dark blobs).
    s.samples.push_back(
        RegionSample{c.r_scale * reg.uv[i][0], c.r_scale * reg.uv[i][1], c.color_level[v], {col[0], col[1], col[2]}});
    weight += 1;
  }
  auto t1 = std::chrono::steady_clock::now();
  job.t_region = std::chrono::duration<double>(t1 - t0).count();
  if (s.samples.empty()) return;
  job.has_samples = true;
  prepare_groups(c.ex, s.samples, lp, opt.averaging, s.groups, s.group);
  job.groups = s.groups.size();
  if (c.grid) {
    repetition_term(c, p, reg, weight, s);
    box.bin_penalty = s.penalty.data();
    box.bin = c.grid->bin();
    box.bins_x = c.grid->bins_x();
  }
  job.m = c.coherent ? coherent_match(c, reg, lp, box, s) : MatchResult{};
  job.searched_all = !job.m.found;
  if (!job.m.found) job.m = c.index.match(s.groups, lp, box);
  auto t2 = std::chrono::steady_clock::now();
  job.t_match = std::chrono::duration<double>(t2 - t1).count();
  if (!job.m.found) {  // nothing fits (cannot happen with the box above): leave the vertex
    job.has_samples = false;
    return;
  }
  const int sc = c.ex.scale(lp);
  if (!opt.graph_cut) {
    job.writes.push_back({p, texel(c.ex, lp, job.m.qx, job.m.qy), lp, {job.m.qx * sc, job.m.qy * sc},
                          {lp, double(job.m.qx), double(job.m.qy)}});
  } else {
    s.nodes.resize(reg.vertices.size());
    s.lookups.resize(reg.vertices.size());
    const double mx = job.m.subtexel ? job.m.x : job.m.qx, my = job.m.subtexel ? job.m.y : job.m.qy;
    for (std::size_t i = 0; i < reg.vertices.size(); ++i) {
      const std::size_t v = reg.vertices[i];
      RegionSample smp{c.r_scale * reg.uv[i][0], c.r_scale * reg.uv[i][1], c.level[v], {}};
      const int lv = c.ex.pyramid ? lp : c.level[v];
      TransferNode& n = s.nodes[i];
      n.colored = c.colored[v] != 0;
      const Color3f& col = c.color[v];
      n.surface = {col[0], col[1], col[2]};
      n.pinned = bounded && !s.inside[i];
      // The texture at the vertex's exact offset (bilinear; the match compared
      // rounded offsets): vertices about a texel apart then carry a resampled
      // exemplar, not a nearest-texel one whose duplicated and skipped texels
      // break its fine structure. Pinned vertices keep their colour.
      const double lsc = c.ex.pyramid ? static_cast<double>(sc) : 1.0;  // as sample_offset
      s.lookups[i] = n.pinned ? c.lookup[v] : ExemplarLookup{lv, mx + smp.du / lsc, my - smp.dv / lsc};
      n.texture = n.pinned ? n.surface : texel_bilinear(c.ex, lv, s.lookups[i].x, s.lookups[i].y);
      n.distance = std::sqrt(smp.du * smp.du + smp.dv * smp.dv);
      n.hops = reg.hops[i];
    }
    const double r = (per_level ? std::ldexp(1.0, lp) : 1.0) * opt.region_texels;
    GraphCutTransferOptions go;
    go.sigma = opt.sigma;
    const auto cut = graph_cut_transfer(s.nodes, reg.edges, 0, job.k, r, go);
    for (std::size_t i = 0; i < reg.vertices.size(); ++i)
      if (cut.take_texture[i]) {
        const auto& o = s.offsets[i];
        int sx = job.m.qx + o[0], sy = job.m.qy + o[1];
        if (!bounded) {
          const int W = c.ex.width(lp), H = c.ex.height(lp);
          sx = wrap_coordinate(sx, W), sy = wrap_coordinate(sy, H);
        }
        job.writes.push_back({reg.vertices[i], s.nodes[i].texture, c.ex.pyramid ? lp : c.level[reg.vertices[i]],
                              {sx * sc, sy * sc}, s.lookups[i]});
      }
  }
  job.t_transfer = std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count();
}

// Throws unless the order and the caller's per-vertex records fit the
// mesh's nv vertices.
void check_pass_inputs(std::size_t nv, const std::vector<std::size_t>& order,
                       const std::vector<char>& colored, const std::vector<int>* color_level_io,
                       const std::vector<std::array<int, 2>>* source_io,
                       const std::vector<ExemplarLookup>* lookup_io) {
  if (source_io && source_io->size() != nv)
    throw InvalidInputError("synthesis_pass: source has " + std::to_string(source_io->size()) + " entries for " +
                            std::to_string(nv) + " vertices");
  if (colored.size() != nv) throw InvalidInputError("synthesis_pass: colored has the wrong size");
  if (lookup_io && lookup_io->size() != nv)
    throw InvalidInputError("synthesis_pass: lookup has " + std::to_string(lookup_io->size()) + " entries for " +
                            std::to_string(nv) + " vertices");
  if (color_level_io && color_level_io->size() != nv)
    throw InvalidInputError("synthesis_pass: color_level has " + std::to_string(color_level_io->size()) +
                            " entries for " + std::to_string(nv) + " vertices");
  for (std::size_t p : order)
    if (p >= nv) throw InvalidInputError("synthesis_pass: order names vertex " + std::to_string(p));
}

// The summed channel variance of the exemplar's level 0 (the scale of the
// repetition term).
double level0_variance(const Image& l0) {
  double sigma2 = 0;
  for (int c = 0; c < 3; ++c) {
    double m = 0, m2 = 0;
    const std::size_t n = static_cast<std::size_t>(l0.width) * l0.height;
    for (std::size_t i = 0; i < n; ++i)
      m += l0.data[3 * i + c], m2 += double(l0.data[3 * i + c]) * l0.data[3 * i + c];
    sigma2 += std::max(0.0, m2 / n - (m / n) * (m / n));
  }
  return sigma2;
}

// One synthesis pass over a vertex order (sections 3.1.2 and 3.3.1): each
// vertex's k-region is matched against the exemplar and its colours taken
// through the graph cut (3.4); the very first vertex gets a random texel.
//
// Speculative parallel matching, sequential commit (exactly the sequential
// pass): the order is cut into chunks of consecutive vertices; every vertex
// of a chunk is matched (and its cut solved) in parallel against the colours
// at the start of the chunk; the results are then committed one by one in
// the pass order. A vertex whose region received a colour from an earlier
// commit of the same chunk read stale colours: its job is recomputed at
// commit time against the current colours. Every committed result is thus
// the one the sequential pass would compute, whatever the thread count. The
// chunk size adapts to the conflict rate, deterministically (it depends only
// on the data).
class SynthesisPass {
 public:
  SynthesisPass(Mesh& mesh, const ExemplarLevels& ex, const ExemplarIndex& index, const PassGeometry& geo,
                std::vector<char>& colored, double r_scale, int hierarchy_level,
                const SubdivisionSynthesisOptions& opt, std::vector<int>* color_level_io,
                std::vector<std::array<int, 2>>* source_io, std::vector<ExemplarLookup>* lookup_io)
      : mesh_(mesh),
        ex_(ex),
        graph_(geo.graph),
        opt_(opt),
        colored_(colored),
        col_(get_or_add(mesh, kVertexColor, Color3f{0.5f, 0.5f, 0.5f})) {
    const std::size_t nv = mesh.number_of_vertices();
    color_.resize(nv);
    for (VertexIndex v : mesh.vertices()) color_[v.idx()] = col_[v];
    const int nlev = static_cast<int>(ex.levels.size());
    const int fixed_level = std::clamp(hierarchy_level, 0, nlev - 1);
    level_.resize(nv);
    for (std::size_t i = 0; i < nv; ++i)
      level_[i] = opt.antialias ? antialias_level(ex, r_scale, geo.frames.mean_edge[i]) : fixed_level;
    // Without a caller's record, every colour is taken to represent its vertex's level.
    if (!color_level_io) own_level_ = level_;
    color_level_ = color_level_io ? color_level_io : &own_level_;
    for (int& l : *color_level_) l = std::clamp(l, 0, nlev - 1);
    if (!source_io) own_source_.assign(nv, {-1, -1});
    source_ = source_io ? source_io : &own_source_;
    if (!lookup_io) own_lookup_.assign(nv, {});
    lookup_ = lookup_io ? lookup_io : &own_lookup_;
    // The repetition counts (see SubdivisionSynthesisOptions::repetition_penalty);
    // they are updated after every chunk's commits, so every job of a chunk
    // reads the counts as they were at the chunk's start (whatever the threads).
    if (source_io && opt.repetition_penalty > 0) {
      const Image& l0 = ex.levels[0];
      sigma2_ = level0_variance(l0);
      grid_ = std::make_unique<RepetitionGrid>(std::max(l0.width, l0.height) / r_scale, l0.width, l0.height);
      for (std::size_t v = 0; v < nv; ++v)
        if (colored[v]) grid_->add(graph_.position[v], (*source_)[v], 1);
    }
    patched_.assign(nv, 0);
    written_.assign(nv, 0);
    any_colored_ = std::any_of(colored.begin(), colored.end(), [](char c) { return c != 0; });
    const bool coherent = source_io && geo.mesh_level >= opt.exhaustive_levels;
    ctx_.emplace(PassContext{graph_, geo.frames, ex, index, level_, colored, color_, *color_level_, *source_,
                             *lookup_, grid_.get(), sigma2_, r_scale, opt, coherent});
  }

  // The pass over `order` (setup_seconds: the time spent before it); the
  // colours are written back to the mesh.
  SynthesisPassStats run(const std::vector<std::size_t>& order, std::mt19937_64& rng, double setup_seconds) {
    st_.seconds_setup = setup_seconds;
    std::size_t chunk = 16;
    for (std::size_t begin = 0; begin < order.size();) {
      const std::size_t end = std::min(order.size(), begin + chunk);
      std::size_t wasted = 0;
      const std::size_t conflicts = run_chunk(order, begin, end, rng, wasted);
      st_.recomputed += conflicts;
      st_.wasted += wasted;
      const std::size_t n = end - begin;
      // A job whose vertex an earlier commit of its chunk patched is thrown
      // away like a recomputed one: on the base level's sweep each match
      // patches its whole region, so large chunks there were mostly waste.
      const std::size_t lost = conflicts + wasted;
      if (16 * lost > n)
        chunk = std::max<std::size_t>(1, chunk / 2);
      else if (64 * lost < n)
        chunk = std::min<std::size_t>(1024, chunk * 2);
      begin = end;
    }
    for (VertexIndex v : mesh_.vertices()) col_[v] = color_[v.idx()];
    if (st_.matched) {
      st_.mean_k = sum_k_ / st_.matched;
      st_.mean_region = sum_region_ / st_.matched;
      st_.mean_groups = sum_groups_ / st_.matched;
    }
    return st_;
  }

 private:
  struct SourceChange {
    std::size_t vertex;
    std::array<int, 2> before, after;
  };

  bool needs_job(std::size_t p) const {
    return !(opt_.skip_patched && patched_[p]) && graph_.offset[p] != graph_.offset[p + 1] && any_colored_;
  }

  // One chunk order[begin, end): matched in parallel, committed in order;
  // returns the jobs recomputed at commit time; `wasted`: jobs computed for
  // vertices that an earlier commit of the chunk patched (not committed).
  std::size_t run_chunk(const std::vector<std::size_t>& order, std::size_t begin, std::size_t end,
                        std::mt19937_64& rng, std::size_t& wasted) {
    ++stamp_;
    if (jobs_.size() < end - begin) jobs_.resize(end - begin);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        JobScratch& s = scratch_.local();
                        for (std::size_t i = r.begin(); i != r.end(); ++i) {
                          const std::size_t p = order[i];
                          jobs_[i - begin].p = static_cast<std::size_t>(-1);
                          if (needs_job(p)) run_job(*ctx_, p, jobs_[i - begin], s);
                        }
                      });
    std::size_t conflicts = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t p = order[i];
      if (opt_.skip_patched && patched_[p]) {
        wasted += jobs_[i - begin].p == p ? 1 : 0;
        continue;
      }
      if (graph_.offset[p] == graph_.offset[p + 1]) continue;  // isolated
      if (!any_colored_) {                                     // the very first vertex: a random texel
        seed_vertex(p, rng);
        continue;
      }
      VertexJob& job = jobs_[i - begin];
      if (is_stale(p, job)) {
        ++conflicts;
        run_job(*ctx_, p, job, serial_);
      }
      commit(p, job);
    }
    if (grid_) {
      for (const SourceChange& ch : changed_) {
        grid_->add(graph_.position[ch.vertex], ch.before, -1);
        grid_->add(graph_.position[ch.vertex], ch.after, 1);
      }
    }
    changed_.clear();
    return conflicts;
  }

  // A random texel of the vertex's level for the pass's first vertex.
  void seed_vertex(std::size_t p, std::mt19937_64& rng) {
    const int lp = level_[p];
    std::uniform_int_distribution<int> ux(0, ex_.width(lp) - 1), uy(0, ex_.height(lp) - 1);
    const int x = ux(rng), y = uy(rng);
    const auto t = texel(ex_, lp, x, y);
    color_[p] = {t[0], t[1], t[2]};
    (*color_level_)[p] = lp;
    (*source_)[p] = {x * ex_.scale(lp), y * ex_.scale(lp)};
    (*lookup_)[p] = {lp, double(x), double(y)};
    if (grid_) changed_.push_back({p, {-1, -1}, (*source_)[p]});
    colored_[p] = 1;
    written_[p] = stamp_;
    any_colored_ = true;
    ++st_.seeded;
  }

  // Whether the job of p is missing or read a colour an earlier commit of
  // this chunk wrote.
  bool is_stale(std::size_t p, const VertexJob& job) const {
    if (job.p != p) return true;
    for (std::size_t v : job.reg.vertices)
      if (written_[v] == stamp_) return true;
    return false;
  }

  // The job's colours written (centre first), with its figures.
  void commit(std::size_t p, const VertexJob& job) {
    st_.seconds_region += job.t_region;
    st_.seconds_match += job.t_match;
    st_.seconds_transfer += job.t_transfer;
    if (!job.has_samples) {
      ++st_.skipped;
      return;
    }
    ++st_.matched;
    sum_k_ += job.k;
    sum_region_ += job.reg.vertices.size();
    sum_groups_ += job.groups;
    st_.candidates += job.m.candidates;
    st_.searched_all += job.searched_all ? 1 : 0;
    std::vector<std::array<int, 2>>& source = *source_;
    for (const auto& w : job.writes) {
      color_[w.vertex] = {w.color[0], w.color[1], w.color[2]};
      (*color_level_)[w.vertex] = w.level;
      if (grid_)
        changed_.push_back(
            {w.vertex, colored_[w.vertex] ? source[w.vertex] : std::array<int, 2>{-1, -1}, w.source});
      source[w.vertex] = w.source;
      (*lookup_)[w.vertex] = w.lookup;
      colored_[w.vertex] = 1;
      written_[w.vertex] = stamp_;
      if (w.vertex != p) {
        patched_[w.vertex] = 1;
        ++st_.patched;
      }
    }
  }

  Mesh& mesh_;
  const ExemplarLevels& ex_;
  const RegionGraph& graph_;
  const SubdivisionSynthesisOptions& opt_;
  std::vector<char>& colored_;
  PropertyMap<VertexIndex, Color3f> col_;
  std::vector<Color3f> color_;
  std::vector<int> level_;
  // The caller's records, or the pass's own when the caller keeps none.
  std::vector<int> own_level_;
  std::vector<int>* color_level_ = nullptr;
  std::vector<std::array<int, 2>> own_source_;
  std::vector<std::array<int, 2>>* source_ = nullptr;
  std::vector<ExemplarLookup> own_lookup_;
  std::vector<ExemplarLookup>* lookup_ = nullptr;
  std::unique_ptr<RepetitionGrid> grid_;
  double sigma2_ = 0;
  std::vector<char> patched_;
  std::vector<std::uint32_t> written_;  // chunk stamp of the last write
  bool any_colored_ = false;
  std::optional<PassContext> ctx_;
  std::vector<SourceChange> changed_;  // this chunk's, applied to the grid after its commits
  std::vector<VertexJob> jobs_;
  tbb::enumerable_thread_specific<JobScratch> scratch_;
  JobScratch serial_;
  std::uint32_t stamp_ = 0;
  SynthesisPassStats st_;
  double sum_k_ = 0, sum_region_ = 0, sum_groups_ = 0;
};

}  // namespace

PassGeometry make_pass_geometry(const Mesh& mesh) {
  PassGeometry g;
  g.frames = compute_surface_frames(mesh);
  g.graph = make_region_graph(mesh, g.frames);
  return g;
}

SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const std::vector<std::size_t>& order,
                                  std::vector<char>& colored, double r_scale, int hierarchy_level,
                                  const SubdivisionSynthesisOptions& opt, std::mt19937_64& rng) {
  const ExemplarIndex index(ex);
  return synthesis_pass(mesh, ex, index, order, colored, r_scale, hierarchy_level, opt, rng, nullptr);
}

SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const ExemplarIndex& index,
                                  const std::vector<std::size_t>& order, std::vector<char>& colored,
                                  double r_scale, int hierarchy_level, const SubdivisionSynthesisOptions& opt,
                                  std::mt19937_64& rng, std::vector<int>* color_level_io,
                                  std::vector<std::array<int, 2>>* source_io, const PassGeometry* geometry,
                                  std::vector<ExemplarLookup>* lookup_io) {
  const std::size_t nv = mesh.number_of_vertices();
  check_pass_inputs(nv, order, colored, color_level_io, source_io, lookup_io);
  auto t_setup = std::chrono::steady_clock::now();
  PassGeometry own_geometry;
  if (!geometry) own_geometry = make_pass_geometry(mesh);
  const PassGeometry& geo = geometry ? *geometry : own_geometry;
  if (geo.graph.size() != nv)
    throw InvalidInputError("synthesis_pass: the pass geometry belongs to another mesh (" +
                            std::to_string(geo.graph.size()) + " vs " + std::to_string(nv) + " vertices)");
  SynthesisPass pass(mesh, ex, index, geo, colored, r_scale, hierarchy_level, opt, color_level_io, source_io,
                     lookup_io);
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_setup).count();
  return pass.run(order, rng, setup);
}

namespace {

// The exemplar as synthesised (RGB, reduced to the chosen synthesis texel)
// and whether it wraps (issue 18 item 2): decided on the input exemplar, at
// its own resolution (decision 207), and a periodic one is reduced wrapping.
void prepare_exemplar(const Image& exemplar, const SubdivisionSynthesisOptions& opt, SubdivisionSynthesisResult& res) {
  const Image rgb = as_rgb(exemplar);
  if (rgb.width >= 2 && rgb.height >= 2) {
    // Windows of the matching neighbourhood's side (region_texels, odd).
    const int window = 2 * static_cast<int>(opt.region_texels / 2) + 1;
    const WrapVerdict v = wrap_verdict(rgb, opt.wrap_threshold, window);
    res.wrap_seam_ratio = v.seam_ratio;
    res.wrap_lines_within_interior = v.lines_within_interior;
    res.wrap_window_ratio = v.window_ratio;
    res.wrap_seamless = v.seamless;
  }
  res.periodic = opt.wrap == ExemplarWrap::Periodic || (opt.wrap == ExemplarWrap::Auto && res.wrap_seamless);
  res.exemplar = resample_as_synthesised(rgb, res.scale, res.periodic);
  res.scale.exemplar_width = res.exemplar.width;
  res.scale.exemplar_height = res.exemplar.height;
}

// Stack levels matched bounded (issue 18 item 2): none for a periodic
// exemplar; else every level whose regions (region_texels texels of the
// level) fit in half the exemplar, and at least level 0. Coarser levels are
// blurred enough for their toroidal blur to hide the wrap, and their regions
// need the room: clipped to a quarter of a small exemplar they shrink to
// 1-rings that lay down cells too large (the deep-hierarchy regression).
int bounded_levels(const SubdivisionSynthesisResult& res, const SubdivisionSynthesisOptions& opt) {
  if (res.periodic) return 0;
  const double half = 0.5 * (std::min(res.exemplar.width, res.exemplar.height) - 1);
  int l = 0;
  while (l < 30) {
    const double scale = opt.pyramid ? 1.0 / double(1 << l) : 1.0;  // level size relative to level 0
    const double extent = (opt.pyramid || !opt.level_relative_region) ? opt.region_texels
                                                                      : opt.region_texels * double(1 << l);
    if (extent > half * scale) break;
    ++l;
  }
  return std::max(1, l);
}

// Level > 0: one sqrt(2) step; old vertices keep index, colour, colour level
// and source; a face point's averaged colour is at least as coarse as its
// face's corners (its neighbours) and has no source yet.
void subdivide_level(Mesh& mesh, std::vector<int>& color_level, std::vector<std::array<int, 2>>& source,
                     std::vector<ExemplarLookup>& lookup) {
  const std::size_t old_nv = mesh.number_of_vertices();
  sqrt2_subdivide(mesh);
  color_level.resize(mesh.number_of_vertices(), 0);
  source.resize(mesh.number_of_vertices(), {-1, -1});
  lookup.resize(mesh.number_of_vertices(), ExemplarLookup{});
  for (std::size_t v = old_nv; v < color_level.size(); ++v) {
    const VertexIndex fv(static_cast<Mesh::size_type>(v));
    int l = 0;
    if (!mesh.is_isolated(fv))
      for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(fv)))
        if (w.idx() < old_nv) l = std::max(l, color_level[w.idx()]);
    color_level[v] = l;
  }
}

// Visiting order (3.1.2): sweep order on the base level, random later.
std::vector<std::size_t> level_order(const Mesh& mesh, int level, std::mt19937_64& rng) {
  std::vector<std::size_t> order(mesh.number_of_vertices());
  std::iota(order.begin(), order.end(), std::size_t(0));
  if (level == 0) {
    auto sweep = find(mesh, kVertexSweep).first;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return sweep[VertexIndex(static_cast<Mesh::size_type>(a))] < sweep[VertexIndex(static_cast<Mesh::size_type>(b))];
    });
  } else {
    std::shuffle(order.begin(), order.end(), rng);
  }
  return order;
}

struct LevelContext {
  const ExemplarLevels& ex;
  const ExemplarIndex& index;
  double r_mesh;
  int levels;
  std::mt19937_64& rng;
  std::vector<char>& colored;
  std::vector<int>& color_level;
  std::vector<std::array<int, 2>>& source;
  std::vector<ExemplarLookup>& lookup;
};

// The passes of one level: pass 1, fill passes for the vertices it skipped
// (section 4's two-pass process), then passes 2..P.
void synthesize_level(Mesh& mesh, int level, const SubdivisionSynthesisOptions& opt, LevelContext& c,
                      SynthesisLevelStats& ls) {
  const std::vector<std::size_t> order = level_order(mesh, level, c.rng);
  const int hierarchy_level = c.levels - level;
  PassGeometry geo = make_pass_geometry(mesh);  // shared by every pass of the level
  geo.mesh_level = level;
  for (int pass = 0; pass < opt.passes; ++pass) {
    report_progress(opt.progress, "synthesis level " + std::to_string(level),
                    double(level * opt.passes + pass) / double((c.levels + 1) * opt.passes));
    ls.pass_stats.push_back(synthesis_pass(mesh, c.ex, c.index, order, c.colored, c.r_mesh, hierarchy_level, opt, c.rng,
                                           &c.color_level, &c.source, &geo, &c.lookup));
    ++ls.passes;
    if (pass > 0) continue;
    for (int guard = 0; guard < 10000; ++guard) {
      std::vector<std::size_t> missing;
      for (std::size_t v : order)
        if (!c.colored[v] && !mesh.is_isolated(VertexIndex(static_cast<Mesh::size_type>(v)))) missing.push_back(v);
      if (missing.empty()) break;
      const SynthesisPassStats fs = synthesis_pass(mesh, c.ex, c.index, missing, c.colored, c.r_mesh, hierarchy_level,
                                                   opt, c.rng, &c.color_level, &c.source, &geo, &c.lookup);
      ls.pass_stats.push_back(fs);
      ++ls.passes;
      ++ls.fill_passes;
      if (fs.matched == 0 && fs.seeded == 0) {  // a component with nothing coloured: seed it
        std::uniform_int_distribution<int> ux(0, c.ex.width(0) - 1), uy(0, c.ex.height(0) - 1);
        const int x = ux(c.rng), y = uy(c.rng);
        const auto tx = texel(c.ex, 0, x, y);
        get_or_add(mesh, kVertexColor)[VertexIndex(static_cast<Mesh::size_type>(missing.front()))] = {tx[0], tx[1], tx[2]};
        c.colored[missing.front()] = 1;
        c.color_level[missing.front()] = 0;
        c.source[missing.front()] = {x, y};
        c.lookup[missing.front()] = {0, double(x), double(y)};
      }
    }
  }
}

}  // namespace

SubdivisionSynthesisResult synthesize_on_subdivision(Mesh& mesh, const Image& exemplar,
                                                     const SubdivisionSynthesisOptions& opt) {
  validate(opt);
  if (exemplar.empty()) throw InvalidInputError("subdivision synthesis: the exemplar image is empty");
  if (mesh.has_garbage()) mesh.collect_garbage();
  if (mesh.number_of_faces() == 0) throw InvalidInputError("subdivision synthesis: the mesh has no faces");
  Timer total;
  SubdivisionSynthesisResult res;
  std::mt19937_64 rng(opt.seed);
  const MeshFigures input = mesh_figures(mesh);
  if (!(input.longest > 0) || !std::isfinite(input.longest))
    throw InvalidInputError("subdivision synthesis: the mesh has no extent (or non-finite coordinates)");
  res.object_unit = opt.normalize_units ? input.longest : 1.0;
  {  // drop stale colours
    auto stale = find(mesh, kVertexColor);
    if (stale.second) mesh.remove_property_map(stale.first);
  }
  // 2. adaptive subdivision (3.2.2), then 1. scale and depth on its result
  if (opt.adaptive_factor > 0 && opt.adaptive_steps > 0) {
    report_progress(opt.progress, "adaptive subdivision", 0);
    AdaptiveSubdivideOptions ao;
    ao.factor = opt.adaptive_factor;
    ao.steps = opt.adaptive_steps;
    res.adaptive_area_std_percent = adaptive_sqrt2_subdivide(mesh, ao).area_std_percent;
  }
  res.scale = choose_subdivision_scale(mesh, exemplar.width, exemplar.height, input.mean_edge, opt, &exemplar);
  prepare_exemplar(exemplar, opt, res);
  const double r_mesh = 1.0 / res.scale.texel_size;  // synthesis texels per mesh unit
  const int levels = res.scale.levels;
  res.bounded_levels = bounded_levels(res, opt);
  const ExemplarLevels ex = make_exemplar_levels(res.exemplar, opt.pyramid, 0, res.bounded_levels);
  const ExemplarIndex index(ex);
  res.stack_levels = static_cast<int>(ex.levels.size());
  std::vector<OrientationKey> keys = opt.keys;
  if (keys.empty()) keys.push_back(OrientationKey{0, {1, 0, 0}});
  std::vector<char> colored;
  std::vector<int> color_level(mesh.number_of_vertices(), 0);  // stack level each vertex's colour was read from
  res.source.assign(mesh.number_of_vertices(), {-1, -1});
  res.lookup.assign(mesh.number_of_vertices(), ExemplarLookup{});
  res.pyramid = opt.pyramid;
  LevelContext lc{ex, index, r_mesh, levels, rng, colored, color_level, res.source, res.lookup};
  for (int level = 0; level <= levels; ++level) {
    SynthesisLevelStats ls;
    ls.level = level;
    Timer t;
    if (level > 0) {
      subdivide_level(mesh, color_level, res.source, res.lookup);
      ls.seconds_subdivide = t.seconds();
    }
    t.reset();
    TurkFieldOptions to;
    to.from_existing = level > 0;
    to.smoothing_passes = level > 0 ? 3 : 10;
    turk_orientation_field(mesh, keys, to);
    SweepFieldOptions so;
    so.from_existing = level > 0;
    so.passes = level > 0 ? 3 : 30;
    turk_sweep_field(mesh, keys.front().vertex, so);
    ls.seconds_fields = t.seconds();
    t.reset();
    ls.vertices = mesh.number_of_vertices();
    ls.faces = mesh.number_of_faces();
    colored.assign(ls.vertices, level > 0 ? 1 : 0);  // face points carry the averaged colour
    synthesize_level(mesh, level, opt, lc, ls);
    ls.seconds_synthesis = t.seconds();
    res.levels.push_back(std::move(ls));
  }
  report_progress(opt.progress, "synthesis", 1.0);
  res.seconds_total = total.seconds();
  return res;
}

nlohmann::json to_json(const SubdivisionSynthesisResult& r, const SubdivisionSynthesisOptions& o) {
  nlohmann::json j;
  const SubdivisionScale& sc = r.scale;
  j["scale"] = {{"from", sc.scale_from}, {"repeats", sc.repeats}, {"repeats_requested", sc.repeats_requested},
                {"relative_detail", sc.relative_detail}, {"min_relative_detail", o.min_relative_detail},
                {"texels_per_edge", sc.texels_per_edge},
                {"r_scale", sc.r_scale}, {"texel_size", sc.texel_size}, {"exemplar_scale", sc.exemplar_scale},
                {"exemplar_size", {sc.exemplar_width, sc.exemplar_height}}, {"levels", sc.levels},
                {"levels_chosen", sc.levels_chosen}, {"budget_limited", sc.budget_limited},
                {"max_vertices", o.max_vertices}, {"spacing_texels", sc.spacing_texels},
                {"predicted_vertices", sc.predicted_vertices}};
  j["wrap"] = {{"periodic", r.periodic},
               {"wrap_seam_ratio", r.wrap_seam_ratio},
               {"threshold", o.wrap_threshold},
               {"lines_within_interior", r.wrap_lines_within_interior},
               {"window_ratio", r.wrap_window_ratio},
               {"seamless", r.wrap_seamless},
               {"bounded_levels", r.bounded_levels}};
  j["repetition_penalty"] = o.repetition_penalty;
  j["exhaustive_levels"] = o.exhaustive_levels;
  j["r_scale"] = sc.r_scale;
  j["object_unit"] = r.object_unit;
  j["stack_levels"] = r.stack_levels;
  j["pyramid"] = o.pyramid;
  j["passes_per_level"] = o.passes;
  j["adaptive_factor"] = o.adaptive_factor;
  j["adaptive_area_std_percent"] = r.adaptive_area_std_percent;
  j["seconds_synthesis_total"] = r.seconds_total;
  for (const auto& l : r.levels) {
    nlohmann::json lj{{"level", l.level}, {"vertices", l.vertices}, {"faces", l.faces}, {"passes", l.passes},
                      {"fill_passes", l.fill_passes}, {"seconds_subdivide", l.seconds_subdivide},
                      {"seconds_fields", l.seconds_fields}, {"seconds_synthesis", l.seconds_synthesis}};
    for (const auto& p : l.pass_stats)
      lj["pass_stats"].push_back({{"matched", p.matched}, {"patched", p.patched}, {"skipped", p.skipped},
                                  {"mean_k", p.mean_k}, {"mean_region", p.mean_region}, {"mean_groups", p.mean_groups},
                                  {"searched_all", p.searched_all}, {"candidates", p.candidates},
                                  {"recomputed", p.recomputed}, {"wasted", p.wasted},
                                  {"seconds_region", p.seconds_region}, {"seconds_match", p.seconds_match},
                                  {"seconds_transfer", p.seconds_transfer}});
    j["levels"].push_back(lj);
  }
  return j;
}

}  // namespace surftex
