// SPDX-License-Identifier: AGPL-3.0-or-later
// Subdivision graph-matching synthesis (Bangay & Morkel 2006, sections 3-4).
// See subdivision_synthesis.h.
#include "texture/subdivision_synthesis.h"

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

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const std::vector<std::size_t>& order,
                                  std::vector<char>& colored, double r_scale, int hierarchy_level,
                                  const SubdivisionSynthesisOptions& opt, std::mt19937_64& rng) {
  const std::size_t nv = mesh.number_of_vertices();
  if (colored.size() != nv) throw InvalidInputError("synthesis_pass: colored has the wrong size");
  const SurfaceFrames fr = compute_surface_frames(mesh);
  auto col = get_or_add(mesh, kVertexColor, Color3f{0.5f, 0.5f, 0.5f});
  const int nlev = static_cast<int>(ex.levels.size());
  const int fixed_level = std::clamp(hierarchy_level, 0, nlev - 1);
  std::vector<int> level(nv);
  for (std::size_t i = 0; i < nv; ++i)
    level[i] = opt.antialias ? antialias_level(ex, r_scale, fr.mean_edge[i]) : fixed_level;
  std::vector<char> patched(nv, 0);
  bool any_colored = std::any_of(colored.begin(), colored.end(), [](char c) { return c != 0; });
  SynthesisPassStats st;
  KRegion reg;
  std::vector<RegionSample> samples;
  std::vector<TransferNode> nodes;
  MatchOptions mo;
  mo.averaging = opt.averaging;
  double sum_k = 0, sum_region = 0, sum_groups = 0;
  for (std::size_t p : order) {
    if (p >= nv) throw InvalidInputError("synthesis_pass: order names vertex " + std::to_string(p));
    if (opt.skip_patched && patched[p]) continue;
    const VertexIndex vp(static_cast<Mesh::size_type>(p));
    if (mesh.is_isolated(vp)) continue;
    const int lp = level[p];
    const double e = fr.mean_edge[p] > 0 ? fr.mean_edge[p] : fr.mean_edge_length;
    if (!any_colored) {  // the very first vertex: a random texel
      std::uniform_int_distribution<int> ux(0, ex.width(lp) - 1), uy(0, ex.height(lp) - 1);
      const int x = ux(rng), y = uy(rng);
      const auto t = texel(ex, lp, x, y);
      col[vp] = {t[0], t[1], t[2]};
      colored[p] = 1;
      any_colored = true;
      ++st.seeded;
      continue;
    }
    auto t0 = std::chrono::steady_clock::now();
    const int k = region_k(opt.region_texels, lp, ex.pyramid, r_scale, e, opt.max_k);
    k_region(mesh, fr, p, k, opt.coordinates, reg);
    samples.clear();
    for (std::size_t i = 1; i < reg.vertices.size(); ++i) {
      const std::size_t v = reg.vertices[i];
      if (!colored[v]) continue;
      const Color3f& c = col[VertexIndex(static_cast<Mesh::size_type>(v))];
      samples.push_back(RegionSample{r_scale * reg.uv[i][0], r_scale * reg.uv[i][1], level[v], {c[0], c[1], c[2]}});
    }
    st.seconds_region += seconds_since(t0);
    if (samples.empty()) {
      ++st.skipped;
      continue;
    }
    t0 = std::chrono::steady_clock::now();
    const MatchResult m = match_region(ex, samples, lp, mo);
    st.seconds_match += seconds_since(t0);
    ++st.matched;
    sum_k += k;
    sum_region += reg.vertices.size();
    sum_groups += m.comparisons;
    t0 = std::chrono::steady_clock::now();
    if (!opt.graph_cut) {
      const auto t = texel(ex, lp, m.qx, m.qy);
      col[vp] = {t[0], t[1], t[2]};
      colored[p] = 1;
    } else {
      nodes.resize(reg.vertices.size());
      for (std::size_t i = 0; i < reg.vertices.size(); ++i) {
        const std::size_t v = reg.vertices[i];
        RegionSample s{r_scale * reg.uv[i][0], r_scale * reg.uv[i][1], level[v], {}};
        const auto o = sample_offset(ex, s, lp);
        const int lv = ex.pyramid ? lp : level[v];
        TransferNode& n = nodes[i];
        n.colored = colored[v] != 0;
        const Color3f& c = col[VertexIndex(static_cast<Mesh::size_type>(v))];
        n.surface = {c[0], c[1], c[2]};
        n.texture = texel(ex, lv, m.qx + o[0], m.qy + o[1]);
        n.distance = std::sqrt(s.du * s.du + s.dv * s.dv);
        n.hops = reg.hops[i];
      }
      const double r = ex.scale(lp) * opt.region_texels;
      GraphCutTransferOptions go;
      go.sigma = opt.sigma;
      const auto cut = graph_cut_transfer(nodes, reg.edges, 0, k, r, go);
      for (std::size_t i = 0; i < reg.vertices.size(); ++i) {
        if (!cut.take_texture[i]) continue;
        const std::size_t v = reg.vertices[i];
        col[VertexIndex(static_cast<Mesh::size_type>(v))] = {nodes[i].texture[0], nodes[i].texture[1],
                                                              nodes[i].texture[2]};
        colored[v] = 1;
        if (i > 0) {
          patched[v] = 1;
          ++st.patched;
        }
      }
    }
    st.seconds_transfer += seconds_since(t0);
  }
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
  res.stack_levels = static_cast<int>(ex.levels.size());
  std::vector<OrientationKey> keys = opt.keys;
  if (keys.empty()) keys.push_back(OrientationKey{0, {1, 0, 0}});
  std::vector<char> colored;
  for (int level = 0; level <= opt.levels; ++level) {
    SynthesisLevelStats ls;
    ls.level = level;
    Timer t;
    if (level > 0) {
      sqrt2_subdivide(mesh);
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
      ls.pass_stats.push_back(synthesis_pass(mesh, ex, order, colored, r_mesh, hierarchy_level, opt, rng));
      ++ls.passes;
      if (pass == 0) {
        // Fill passes: vertices left without coloured neighbours (section 4).
        for (int guard = 0; guard < 10000; ++guard) {
          std::vector<std::size_t> missing;
          for (std::size_t v : order)
            if (!colored[v] && !mesh.is_isolated(VertexIndex(static_cast<Mesh::size_type>(v)))) missing.push_back(v);
          if (missing.empty()) break;
          const SynthesisPassStats fs = synthesis_pass(mesh, ex, missing, colored, r_mesh, hierarchy_level, opt, rng);
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
