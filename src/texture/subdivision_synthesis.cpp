// SPDX-License-Identifier: AGPL-3.0-or-later
// Subdivision graph-matching synthesis (Bangay & Morkel 2006, sections 3-4).
// See subdivision_synthesis.h.
#include "texture/subdivision_synthesis.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include "geometry/adaptive_sqrt2_subdivide.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/sqrt2_subdivide.h"
#include "geometry/timer.h"
#include "texture/graph_cut_transfer.h"

namespace surftex {
namespace {

void validate(const SubdivisionSynthesisOptions& o) {
  auto bad = [](const std::string& what, double v, const std::string& range) {
    throw InvalidInputError("subdivision synthesis: " + what + " must be " + range + " (got " + std::to_string(v) + ")");
  };
  if (!(o.r_scale > 0) || !std::isfinite(o.r_scale)) bad("r_scale", o.r_scale, "> 0");
  if (o.levels < 0 || o.levels > 12) bad("levels", o.levels, "in 0..12");
  if (!(o.adaptive_factor >= 0) || !std::isfinite(o.adaptive_factor)) bad("adaptive_factor", o.adaptive_factor, ">= 0");
  if (o.adaptive_steps < 0 || o.adaptive_steps > 32) bad("adaptive_steps", o.adaptive_steps, "in 0..32");
  if (o.passes < 1 || o.passes > 16) bad("passes", o.passes, "in 1..16");
  if (!(o.region_texels > 0) || !std::isfinite(o.region_texels)) bad("region_texels", o.region_texels, "> 0");
  if (!(o.sigma > 0) || !std::isfinite(o.sigma)) bad("sigma", o.sigma, "> 0");
  if (o.max_k < 1 || o.max_k > 64) bad("max_k", o.max_k, "in 1..64");
}


}  // namespace

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
    int level;  ///< stack level the colour was read from
  };
  std::vector<Write> writes;  ///< centre first
  double t_region = 0, t_match = 0, t_transfer = 0;
};

struct JobScratch {
  RegionScratch region;
  GroupScratch group;
  std::vector<RegionSample> samples;
  std::vector<SampleGroup> groups;
  std::vector<TransferNode> nodes;
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
  double r_scale;
  const SubdivisionSynthesisOptions& opt;
};

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
  s.samples.clear();
  for (std::size_t i = 1; i < reg.vertices.size(); ++i) {
    const std::size_t v = reg.vertices[i];
    if (!c.colored[v]) continue;
    const Color3f& col = c.color[v];
    // Compared at the level its colour represents (a colour carried from a
    // coarser mesh level is a blurred one: matching it against sharper texels
    // turns blurred dark seams into solid dark blobs).
    s.samples.push_back(
        RegionSample{c.r_scale * reg.uv[i][0], c.r_scale * reg.uv[i][1], c.color_level[v], {col[0], col[1], col[2]}});
  }
  auto t1 = std::chrono::steady_clock::now();
  job.t_region = std::chrono::duration<double>(t1 - t0).count();
  if (s.samples.empty()) return;
  job.has_samples = true;
  prepare_groups(c.ex, s.samples, lp, opt.averaging, s.groups, s.group);
  job.groups = s.groups.size();
  job.m = c.index.match(s.groups, lp);
  auto t2 = std::chrono::steady_clock::now();
  job.t_match = std::chrono::duration<double>(t2 - t1).count();
  if (!opt.graph_cut) {
    job.writes.push_back({p, texel(c.ex, lp, job.m.qx, job.m.qy), lp});
  } else {
    s.nodes.resize(reg.vertices.size());
    for (std::size_t i = 0; i < reg.vertices.size(); ++i) {
      const std::size_t v = reg.vertices[i];
      RegionSample smp{c.r_scale * reg.uv[i][0], c.r_scale * reg.uv[i][1], c.level[v], {}};
      const auto o = sample_offset(c.ex, smp, lp);
      const int lv = c.ex.pyramid ? lp : c.level[v];
      TransferNode& n = s.nodes[i];
      n.colored = c.colored[v] != 0;
      const Color3f& col = c.color[v];
      n.surface = {col[0], col[1], col[2]};
      n.texture = texel(c.ex, lv, job.m.qx + o[0], job.m.qy + o[1]);
      n.distance = std::sqrt(smp.du * smp.du + smp.dv * smp.dv);
      n.hops = reg.hops[i];
    }
    const double r = (per_level ? std::ldexp(1.0, lp) : 1.0) * opt.region_texels;
    GraphCutTransferOptions go;
    go.sigma = opt.sigma;
    const auto cut = graph_cut_transfer(s.nodes, reg.edges, 0, job.k, r, go);
    for (std::size_t i = 0; i < reg.vertices.size(); ++i)
      if (cut.take_texture[i])
        job.writes.push_back({reg.vertices[i], s.nodes[i].texture, c.ex.pyramid ? lp : c.level[reg.vertices[i]]});
  }
  job.t_transfer = std::chrono::duration<double>(std::chrono::steady_clock::now() - t2).count();
}

}  // namespace

SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const std::vector<std::size_t>& order,
                                  std::vector<char>& colored, double r_scale, int hierarchy_level,
                                  const SubdivisionSynthesisOptions& opt, std::mt19937_64& rng) {
  const ExemplarIndex index(ex);
  return synthesis_pass(mesh, ex, index, order, colored, r_scale, hierarchy_level, opt, rng, nullptr);
}

SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const ExemplarIndex& index,
                                  const std::vector<std::size_t>& order, std::vector<char>& colored, double r_scale,
                                  int hierarchy_level, const SubdivisionSynthesisOptions& opt,
                                  std::mt19937_64& rng, std::vector<int>* color_level_io) {
  const std::size_t nv = mesh.number_of_vertices();
  if (colored.size() != nv) throw InvalidInputError("synthesis_pass: colored has the wrong size");
  if (color_level_io && color_level_io->size() != nv)
    throw InvalidInputError("synthesis_pass: color_level has " + std::to_string(color_level_io->size()) +
                            " entries for " + std::to_string(nv) + " vertices");
  for (std::size_t p : order)
    if (p >= nv) throw InvalidInputError("synthesis_pass: order names vertex " + std::to_string(p));
  auto t_setup = std::chrono::steady_clock::now();
  const SurfaceFrames fr = compute_surface_frames(mesh);
  const RegionGraph graph = make_region_graph(mesh, fr);
  auto col = get_or_add(mesh, kVertexColor, Color3f{0.5f, 0.5f, 0.5f});
  std::vector<Color3f> color(nv);
  for (VertexIndex v : mesh.vertices()) color[v.idx()] = col[v];
  const int nlev = static_cast<int>(ex.levels.size());
  const int fixed_level = std::clamp(hierarchy_level, 0, nlev - 1);
  std::vector<int> level(nv);
  for (std::size_t i = 0; i < nv; ++i)
    level[i] = opt.antialias ? antialias_level(ex, r_scale, fr.mean_edge[i]) : fixed_level;
  // Without a caller's record, every colour is taken to represent its vertex's level.
  std::vector<int> own_level;
  if (!color_level_io) own_level = level;
  std::vector<int>& color_level = color_level_io ? *color_level_io : own_level;
  for (int& l : color_level) l = std::clamp(l, 0, nlev - 1);
  std::vector<char> patched(nv, 0);
  std::vector<std::uint32_t> written(nv, 0);  // chunk stamp of the last write
  bool any_colored = std::any_of(colored.begin(), colored.end(), [](char c) { return c != 0; });
  SynthesisPassStats st;
  st.seconds_setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_setup).count();
  const PassContext ctx{graph, fr, ex, index, level, colored, color, color_level, r_scale, opt};
  double sum_k = 0, sum_region = 0, sum_groups = 0;

  // Speculative parallel matching, sequential commit (exactly the sequential
  // pass of sections 3.1.2 and 3.3.1): the order is cut into chunks of
  // consecutive vertices; every vertex of a chunk is matched (and its cut
  // solved) in parallel against the colours at the start of the chunk; the
  // results are then committed one by one in the pass order. A vertex whose
  // region received a colour from an earlier commit of the same chunk read
  // stale colours: its job is recomputed at commit time against the current
  // colours. Every committed result is thus the one the sequential pass would
  // compute, whatever the thread count. The chunk size adapts to the conflict
  // rate, deterministically (it depends only on the data).
  std::vector<VertexJob> jobs;
  tbb::enumerable_thread_specific<JobScratch> scratch;
  JobScratch serial;
  std::size_t chunk = 16;
  std::uint32_t stamp = 0;
  for (std::size_t begin = 0; begin < order.size();) {
    const std::size_t end = std::min(order.size(), begin + chunk);
    ++stamp;
    if (jobs.size() < end - begin) jobs.resize(end - begin);
    auto needs_job = [&](std::size_t p) {
      return !(opt.skip_patched && patched[p]) && graph.offset[p] != graph.offset[p + 1] && any_colored;
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      JobScratch& s = scratch.local();
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        const std::size_t p = order[i];
        jobs[i - begin].p = static_cast<std::size_t>(-1);
        if (needs_job(p)) run_job(ctx, p, jobs[i - begin], s);
      }
    });
    std::size_t conflicts = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const std::size_t p = order[i];
      if (opt.skip_patched && patched[p]) continue;
      if (graph.offset[p] == graph.offset[p + 1]) continue;  // isolated
      if (!any_colored) {  // the very first vertex: a random texel
        const int lp = level[p];
        std::uniform_int_distribution<int> ux(0, ex.width(lp) - 1), uy(0, ex.height(lp) - 1);
        const int x = ux(rng), y = uy(rng);
        const auto t = texel(ex, lp, x, y);
        color[p] = {t[0], t[1], t[2]};
        color_level[p] = lp;
        colored[p] = 1;
        written[p] = stamp;
        any_colored = true;
        ++st.seeded;
        continue;
      }
      VertexJob& job = jobs[i - begin];
      bool stale = job.p != p;
      if (!stale)
        for (std::size_t v : job.reg.vertices)
          if (written[v] == stamp) {
            stale = true;
            break;
          }
      if (stale) {
        ++conflicts;
        run_job(ctx, p, job, serial);
      }
      st.seconds_region += job.t_region;
      st.seconds_match += job.t_match;
      st.seconds_transfer += job.t_transfer;
      if (!job.has_samples) {
        ++st.skipped;
        continue;
      }
      ++st.matched;
      sum_k += job.k;
      sum_region += job.reg.vertices.size();
      sum_groups += job.groups;
      st.candidates += job.m.candidates;
      for (const auto& w : job.writes) {
        color[w.vertex] = {w.color[0], w.color[1], w.color[2]};
        color_level[w.vertex] = w.level;
        colored[w.vertex] = 1;
        written[w.vertex] = stamp;
        if (w.vertex != p) {
          patched[w.vertex] = 1;
          ++st.patched;
        }
      }
    }
    st.recomputed += conflicts;
    const std::size_t n = end - begin;
    if (16 * conflicts > n)
      chunk = std::max<std::size_t>(1, chunk / 2);
    else if (64 * conflicts < n)
      chunk = std::min<std::size_t>(1024, chunk * 2);
    begin = end;
  }
  for (VertexIndex v : mesh.vertices()) col[v] = color[v.idx()];
  if (st.matched) {
    st.mean_k = sum_k / st.matched;
    st.mean_region = sum_region / st.matched;
    st.mean_groups = sum_groups / st.matched;
  }
  return st;
}

SubdivisionSynthesisResult synthesize_on_subdivision(Mesh& mesh, const Image& exemplar,
                                                     const SubdivisionSynthesisOptions& opt) {
  validate(opt);
  if (exemplar.empty()) throw InvalidInputError("subdivision synthesis: the exemplar image is empty");
  if (mesh.has_garbage()) mesh.collect_garbage();
  if (mesh.number_of_faces() == 0) throw InvalidInputError("subdivision synthesis: the mesh has no faces");
  Timer total;
  SubdivisionSynthesisResult res;
  std::mt19937_64 rng(opt.seed);

  // 1. units
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  }
  const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  if (!(longest > 0) || !std::isfinite(longest))
    throw InvalidInputError("subdivision synthesis: the mesh has no extent (or non-finite coordinates)");
  res.object_unit = opt.normalize_units ? longest : 1.0;
  const double r_mesh = opt.r_scale / res.object_unit;  // texels per mesh unit

  // Properties carried through the hierarchy; drop stale colours.
  {
    auto stale = find(mesh, kVertexColor);
    if (stale.second) mesh.remove_property_map(stale.first);
  }

  // 2. adaptive subdivision
  if (opt.adaptive_factor > 0 && opt.adaptive_steps > 0) {
    report_progress(opt.progress, "adaptive subdivision", 0);
    AdaptiveSubdivideOptions ao;
    ao.factor = opt.adaptive_factor;
    ao.steps = opt.adaptive_steps;
    res.adaptive_area_std_percent = adaptive_sqrt2_subdivide(mesh, ao).area_std_percent;
  }

  const ExemplarLevels ex = make_exemplar_levels(exemplar, opt.pyramid);
  const ExemplarIndex index(ex);
  res.stack_levels = static_cast<int>(ex.levels.size());
  std::vector<OrientationKey> keys = opt.keys;
  if (keys.empty()) keys.push_back(OrientationKey{0, {1, 0, 0}});
  std::vector<char> colored;
  std::vector<int> color_level;  // stack level each vertex's colour was read from
  for (int level = 0; level <= opt.levels; ++level) {
    SynthesisLevelStats ls;
    ls.level = level;
    Timer t;
    if (level > 0) {
      const std::size_t old_nv = mesh.number_of_vertices();
      sqrt2_subdivide(mesh);
      ls.seconds_subdivide = t.seconds();
      // Old vertices keep their index and colour, so the level that colour was
      // read from; a face point's averaged colour is at least as coarse as its
      // face's corners (its neighbours).
      color_level.resize(mesh.number_of_vertices(), 0);
      for (std::size_t v = old_nv; v < color_level.size(); ++v) {
        const VertexIndex fv(static_cast<Mesh::size_type>(v));
        int l = 0;
        if (!mesh.is_isolated(fv))
          for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(fv)))
            if (w.idx() < old_nv) l = std::max(l, color_level[w.idx()]);
        color_level[v] = l;
      }
    } else {
      color_level.assign(mesh.number_of_vertices(), 0);
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
    const std::size_t nv = mesh.number_of_vertices();
    ls.vertices = nv;
    ls.faces = mesh.number_of_faces();
    colored.assign(nv, level > 0 ? 1 : 0);  // face points carry the averaged colour
    std::vector<std::size_t> order(nv);
    std::iota(order.begin(), order.end(), std::size_t(0));
    if (level == 0) {
      auto sweep = find(mesh, kVertexSweep).first;
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return sweep[VertexIndex(static_cast<Mesh::size_type>(a))] < sweep[VertexIndex(static_cast<Mesh::size_type>(b))];
      });
    } else {
      std::shuffle(order.begin(), order.end(), rng);
    }
    const int hierarchy_level = opt.levels - level;
    for (int pass = 0; pass < opt.passes; ++pass) {
      report_progress(opt.progress, "synthesis level " + std::to_string(level),
                      double(level * opt.passes + pass) / double((opt.levels + 1) * opt.passes));
      ls.pass_stats.push_back(synthesis_pass(mesh, ex, index, order, colored, r_mesh, hierarchy_level, opt, rng, &color_level));
      ++ls.passes;
      if (pass == 0) {
        // Fill passes: vertices left without coloured neighbours (section 4).
        for (int guard = 0; guard < 10000; ++guard) {
          std::vector<std::size_t> missing;
          for (std::size_t v : order)
            if (!colored[v] && !mesh.is_isolated(VertexIndex(static_cast<Mesh::size_type>(v)))) missing.push_back(v);
          if (missing.empty()) break;
          const SynthesisPassStats fs = synthesis_pass(mesh, ex, index, missing, colored, r_mesh, hierarchy_level, opt, rng, &color_level);
          ls.pass_stats.push_back(fs);
          ++ls.passes;
          ++ls.fill_passes;
          if (fs.matched == 0 && fs.seeded == 0) {  // a component with nothing coloured: seed it
            // Seed the first missing vertex of the component with a random texel.
            std::uniform_int_distribution<int> ux(0, ex.width(0) - 1), uy(0, ex.height(0) - 1);
            const auto tx = texel(ex, 0, ux(rng), uy(rng));
            get_or_add(mesh, kVertexColor)[VertexIndex(static_cast<Mesh::size_type>(missing.front()))] = {
                tx[0], tx[1], tx[2]};
            colored[missing.front()] = 1;
            color_level[missing.front()] = 0;
          }
        }
      }
    }
    ls.seconds_synthesis = t.seconds();
    res.levels.push_back(std::move(ls));
  }
  report_progress(opt.progress, "synthesis", 1.0);
  res.seconds_total = total.seconds();
  return res;
}

}  // namespace surftex
