// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch-based oriented surface synthesis (Gorla et al. 2003, 3-5).
#include "texture/patch_synthesis.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <memory>
#include <mutex>
#include <random>
#include <string>

#include "geometry/direction_field.h"
#include "geometry/mesh_util.h"
#include "geometry/principal_curvatures.h"
#include "geometry/properties.h"
#include "geometry/surface_normals.h"
#include "geometry/timer.h"

namespace surftex {
namespace {

Vector3 vec(const std::array<double, 3>& a) { return Vector3(a[0], a[1], a[2]); }

std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (a + 1) + 0xBF58476D1CE4E5B9ull * (b + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

void validate(const Mesh& mesh, const std::vector<Image>& ex, const PatchSynthesisOptions& o) {
  auto bad = [](const std::string& m) { throw InvalidInputError("synthesize_patches: " + m); };
  if (ex.empty()) bad("no exemplar given");
  for (std::size_t i = 0; i < ex.size(); ++i) {
    if (ex[i].empty()) bad("exemplar " + std::to_string(i) + " is empty");
    if (ex[i].channels != ex[0].channels)
      bad("exemplar " + std::to_string(i) + " has " + std::to_string(ex[i].channels) +
          " channels, exemplar 0 has " + std::to_string(ex[0].channels));
  }
  if (o.field == PatchField::Constant && vec(o.constant_vector).squared_length() == 0)
    bad("constant_vector is zero");
  if (!(o.constraint_fraction > 0 && o.constraint_fraction <= 1))
    bad("constraint_fraction " + std::to_string(o.constraint_fraction) + " outside (0, 1]");
  if (o.multi != MultiTexture::None && ex.size() < 2)
    bad("multi-texturing needs at least 2 exemplars, got " + std::to_string(ex.size()));
  if (o.multi == MultiTexture::VertexScalar && o.vertex_scalar.size() != mesh.num_vertices())
    bad("vertex_scalar has " + std::to_string(o.vertex_scalar.size()) + " values, the mesh " +
        std::to_string(mesh.num_vertices()) + " vertices");
  if (o.multi == MultiTexture::Illumination && vec(o.light).squared_length() == 0) bad("light is zero");
  if (o.multi == MultiTexture::Height && vec(o.height_axis).squared_length() == 0)
    bad("height_axis is zero");
  if (mesh.number_of_faces() == 0) bad("the mesh has no faces");
}

// Constraints from (possibly swapped) principal directions for a line field.
std::vector<DirectionConstraint> principal_constraints(const Mesh& mesh, PatchField field,
                                                       double fraction) {
  auto kmax = find(mesh, kVertexKmax).first;
  auto kmin = find(mesh, kVertexKmin).first;
  auto dmax = find(mesh, kVertexDmax).first;
  auto dmin = find(mesh, kVertexDmin).first;
  const bool abs_choice = field == PatchField::KmaxAbs || field == PatchField::KminAbs;
  const bool want_max = field == PatchField::Kmax || field == PatchField::KmaxAbs;
  std::vector<std::pair<double, int>> score;
  std::vector<Vector3> dir(mesh.num_faces(), Vector3(0, 0, 0));
  for (FaceIndex f : mesh.faces()) {
    const auto v = face_vertices(mesh, f);
    const Vector3 n = robust_face_normal(mesh, f);
    double s = 0;
    Vector3 sum(0, 0, 0), ref(0, 0, 0);
    for (VertexIndex w : v) {
      const double a = kmax[w], b = kmin[w];
      bool use_max = want_max;
      if (abs_choice && std::abs(b) > std::abs(a)) use_max = !use_max;  // |kmin| is the greater
      s += abs_choice ? std::abs(std::abs(a) - std::abs(b)) : a - b;
      Vector3 d = use_max ? dmax[w] : dmin[w];
      d = d - (d * n) * n;
      if (ref.squared_length() == 0) ref = d;
      if (d * ref < 0) d = -d;  // line field: align signs before averaging
      sum = sum + d;
    }
    if (sum.squared_length() == 0) continue;
    dir[f.idx()] = sum;
    score.emplace_back(-s / 3.0, static_cast<int>(f.idx()));
  }
  std::sort(score.begin(), score.end());
  const std::size_t keep = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(fraction * mesh.number_of_faces())));
  std::vector<DirectionConstraint> out;
  for (std::size_t i = 0; i < score.size() && i < keep; ++i) {
    const Vector3& d = dir[score[i].second];
    out.push_back({static_cast<std::uint32_t>(score[i].second), {d.x(), d.y(), d.z()}});
  }
  return out;
}

// Bilinear lookup in a patch image restricted to its Inside pixels (weights
// renormalised); false if none of the four texels is Inside.
bool sample_inside(const FlatPatch& fp, const Image& img, double px, double py, float* out) {
  const int C = img.channels;
  const double fx = px - 0.5, fy = py - 0.5;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const double ax = fx - x0, ay = fy - y0;
  double acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  double wsum = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int x = x0 + i, y = y0 + j;
      if (x < 0 || y < 0 || x >= fp.res || y >= fp.res) continue;
      if (fp.pixel[static_cast<std::size_t>(y) * fp.res + x] != PatchPixel::Inside) continue;
      const double w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay) + 1e-6;
      for (int c = 0; c < C && c < 8; ++c) acc[c] += w * img.at(x, y, c);
      wsum += w;
    }
  if (wsum <= 0) return false;
  for (int c = 0; c < C && c < 8; ++c) out[c] = static_cast<float>(acc[c] / wsum);
  return true;
}

}  // namespace

PatchSynthesisResult synthesize_patches(Mesh& mesh, const std::vector<Image>& exemplars,
                                        const PatchSynthesisOptions& opt) {
  validate(mesh, exemplars, opt);
  require_triangle_mesh(mesh, "synthesize_patches");
  if (exemplars[0].channels > 8)
    throw InvalidInputError("synthesize_patches: exemplars have " +
                            std::to_string(exemplars[0].channels) + " channels, at most 8 supported");
  Timer total;
  PatchSynthesisResult res;
  // 1. Partition (3.1) and overlap splitting (3.2).
  Timer t;
  report_progress(opt.progress, "partition", 0.0);
  res.partition = partition_near_planar(mesh, opt.partition);
  std::vector<int> seeds = res.partition.seed_face;
  res.split_patches = split_overlapping_patches(mesh, seeds, std::min(89.0, opt.partition.max_angle_deg));
  const int P = static_cast<int>(seeds.size());
  res.seconds_partition = t.seconds();

  // 2. Direction field (4) and the per-vertex quantities the pixels need.
  t.reset();
  report_progress(opt.progress, "field", 0.0);
  compute_vertex_normals(mesh);
  auto vnormal = find(mesh, kVertexNormal).first;
  const bool principal = opt.field == PatchField::Kmax || opt.field == PatchField::Kmin ||
                         opt.field == PatchField::KmaxAbs || opt.field == PatchField::KminAbs;
  const bool need_curv = principal || opt.order == PatchOrder::Curvature ||
                         opt.multi == MultiTexture::Curvature;
  if (need_curv) compute_principal_curvatures(mesh);
  const std::size_t NV = mesh.num_vertices(), NF = mesh.num_faces();
  std::vector<Vector3> fdir(NF, Vector3(0, 0, 0)), vdir(NV, Vector3(0, 0, 0));
  const bool oriented = opt.field != PatchField::None;
  const bool line_field = principal;
  if (oriented) {
    DirectionFieldOptions dfo;
    std::vector<DirectionConstraint> cons;
    if (opt.field == PatchField::Constant) {
      dfo.symmetry = 1;
      cons = constraints_from_constant_vector(mesh, opt.constant_vector);
      if (cons.empty())  // every face nearly orthogonal to the vector: take them all
        cons = constraints_from_constant_vector(mesh, opt.constant_vector, 1e-9);
    } else {
      dfo.symmetry = 2;
      cons = principal_constraints(mesh, opt.field, opt.constraint_fraction);
    }
    if (!cons.empty()) {
      interpolate_direction_field(mesh, cons, dfo);
      auto fd = find(mesh, kFaceDirection).first;
      for (FaceIndex f : mesh.faces()) fdir[f.idx()] = fd[f];
    }
    for (VertexIndex v : mesh.vertices()) {
      Vector3 sum(0, 0, 0), ref(0, 0, 0);
      const Vector3 n = vnormal[v];
      for (FaceIndex f : CGAL::faces_around_target(mesh.halfedge(v), mesh)) {
        if (f == Mesh::null_face()) continue;
        Vector3 d = fdir[f.idx()];
        d = d - (d * n) * n;
        if (ref.squared_length() == 0) ref = d;
        if (line_field && d * ref < 0) d = -d;
        sum = sum + d;
      }
      vdir[v.idx()] = normalized_or(sum, Vector3(0, 0, 0));
    }
  }
  // Multi-texturing scalar per vertex (t in [0,1]), except Illumination (per pixel).
  std::vector<double> vt(NV, 0.0);
  if (opt.multi == MultiTexture::Curvature || opt.multi == MultiTexture::Height ||
      opt.multi == MultiTexture::VertexScalar) {
    std::vector<double> raw(NV, 0.0);
    auto kmax = find(mesh, kVertexKmax).first;
    auto kmin = find(mesh, kVertexKmin).first;
    const Vector3 ax = vec(opt.height_axis);
    for (VertexIndex v : mesh.vertices()) {
      const std::size_t i = v.idx();
      if (opt.multi == MultiTexture::Curvature) raw[i] = 0.5 * (kmax[v] + kmin[v]);
      else if (opt.multi == MultiTexture::Height) raw[i] = (mesh.point(v) - CGAL::ORIGIN) * ax;
      else raw[i] = opt.vertex_scalar[i];
      if (!std::isfinite(raw[i]))
        throw InvalidInputError("synthesize_patches: multi-texturing value at vertex " +
                                std::to_string(i) + " is not finite");
    }
    std::vector<double> sorted = raw;
    std::sort(sorted.begin(), sorted.end());
    const double q = opt.multi == MultiTexture::Curvature ? 0.05 : 0.0;
    const double lo = sorted[static_cast<std::size_t>(q * (sorted.size() - 1))];
    const double hi = sorted[static_cast<std::size_t>((1 - q) * (sorted.size() - 1))];
    for (std::size_t i = 0; i < NV; ++i)
      vt[i] = hi > lo ? std::clamp((raw[i] - lo) / (hi - lo), 0.0, 1.0) : 0.5;
  }
  res.seconds_field = t.seconds();

  // 3. Flatten and rasterise (3.2).
  t.reset();
  report_progress(opt.progress, "flatten", 0.0);
  res.flat = flatten_patches(mesh, seeds, opt.flatten);
  res.seconds_flatten = t.seconds();
  auto& patches = res.flat.patches;
  std::vector<int> face_patch(NF, -1), face_slot(NF, -1);
  for (int p = 0; p < P; ++p)
    for (std::size_t i = 0; i < patches[p].triangles.size(); ++i) {
      face_patch[patches[p].triangles[i].face] = p;
      face_slot[patches[p].triangles[i].face] = static_cast<int>(i);
    }
  for (int id : opt.resynthesize)
    if (id < 0 || id >= P)
      throw InvalidInputError("synthesize_patches: resynthesize id " + std::to_string(id) +
                              " outside 0.." + std::to_string(P - 1));

  // Patch adjacency and the curvature score.
  std::vector<std::vector<int>> adj(P);
  for (FaceIndex f : mesh.faces())
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const FaceIndex g = mesh.face(mesh.opposite(h));
      if (g == Mesh::null_face()) continue;
      const int a = face_patch[f.idx()], b = face_patch[g.idx()];
      if (a != b) adj[a].push_back(b);
    }
  for (auto& a : adj) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  std::vector<double> score(P, 0.0);
  if (opt.order == PatchOrder::Curvature) {
    auto kmax = find(mesh, kVertexKmax).first;
    auto kmin = find(mesh, kVertexKmin).first;
    for (int p = 0; p < P; ++p) {
      double s = 0;
      for (const FlatTriangle& tr : patches[p].triangles)
        for (VertexIndex v : face_vertices(mesh, FaceIndex(static_cast<Mesh::size_type>(tr.face))))
          s += kmax[v] - kmin[v];
      score[p] = s / (3.0 * patches[p].triangles.size());
    }
  }

  // 4. Patch order (4).
  std::mt19937_64 rng(mix_seed(opt.seed, 0xA11CE, 0));
  {
    std::vector<char> taken(P, 0), front(P, 0);
    for (int k = 0; k < P; ++k) {
      std::vector<int> cand;
      for (int p = 0; p < P; ++p)
        if (!taken[p] && front[p]) cand.push_back(p);
      if (cand.empty())
        for (int p = 0; p < P; ++p)
          if (!taken[p]) cand.push_back(p);
      int pick;
      if (opt.order == PatchOrder::Curvature) {
        pick = cand[0];
        for (int p : cand)
          if (score[p] > score[pick]) pick = p;
      } else {
        pick = cand[std::uniform_int_distribution<std::size_t>(0, cand.size() - 1)(rng)];
      }
      taken[pick] = 1;
      res.order.push_back(pick);
      for (int q : adj[pick]) front[q] = 1;
    }
  }

  // 5. Synthesis per patch (3.3).
  t.reset();
  const int C = exemplars[0].channels;
  const int R = opt.flatten.resolution;
  const std::size_t N = static_cast<std::size_t>(R) * R;
  res.images.assign(P, Image(R, R, C, 0.f));
  res.sources.assign(P, std::vector<ElSource>(static_cast<std::size_t>(R) * R));
  // Exemplar rotations prepared once for every patch (not once per patch).
  const std::shared_ptr<const ElPreparedExemplars> prepared = el_prepare_exemplars(exemplars, opt.el);
  // Per patch: texels filled, of which seeded, Known boundary pixels.
  std::vector<std::size_t> texels(P, 0), seeded(P, 0), known(P, 0);
  std::mutex progress_mutex;
  const Vector3 light = normalized_or(vec(opt.light), Vector3(0, 0, 1));
  const int E = static_cast<int>(exemplars.size());
  std::size_t step = 0;
  const std::size_t steps = P + opt.resynthesize.size();

  // synth_one(p, pass, available): available(q) says whether patch q's
  // image is a boundary condition for p (synthesised before p in the order).
  auto synth_one = [&](int p, int pass, const auto& available, bool pixel_parallel) {
    const FlatPatch& fp = patches[p];
    // Synthesis runs on the bounding box of the patch's Inside and Boundary
    // pixels (most of the raster is Outside); row-major order, relative
    // positions and hence the result are those of the full raster.
    int x0 = R, y0 = R, x1 = -1, y1 = -1;
    for (int y = 0; y < R; ++y)
      for (int x = 0; x < R; ++x)
        if (fp.pixel[static_cast<std::size_t>(y) * R + x] != PatchPixel::Outside) {
          x0 = std::min(x0, x);
          x1 = std::max(x1, x);
          y0 = std::min(y0, y);
          y1 = std::max(y1, y);
        }
    if (x1 < 0) x0 = y0 = x1 = y1 = 0;  // nothing to do: one Outside pixel
    const int BW = x1 - x0 + 1, BH = y1 - y0 + 1;
    const std::size_t BN = static_cast<std::size_t>(BW) * BH;
    ElInput in;
    in.prepared = prepared;
    in.target = Image(BW, BH, C, 0.f);
    in.state.assign(BN, PixelState::Outside);
    const Vector3 e1 = vec(fp.e1), e2 = vec(fp.e2);
    if (oriented) in.angle = Image(BW, BH, 1, 0.f);
    if (opt.multi != MultiTexture::None) in.exemplar_index.assign(BN, 0);
    double mean_c = 0, mean_s = 0;
    for (std::size_t j = 0; j < BN; ++j) {
      const std::size_t i = static_cast<std::size_t>(y0 + j / BW) * R + x0 + j % BW;
      const PatchPixel kind = fp.pixel[i];
      if (kind == PatchPixel::Outside) continue;
      const FaceIndex f(static_cast<Mesh::size_type>(fp.pixel_face[i]));
      const auto& b = fp.pixel_bary[i];
      if (kind == PatchPixel::Boundary) {
        const int q = face_patch[f.idx()];
        if (!available(q)) continue;
        const FlatPatch& fq = patches[q];
        const FlatTriangle& tq = fq.triangles[face_slot[f.idx()]];
        const double u = b[0] * tq.corner[0][0] + b[1] * tq.corner[1][0] + b[2] * tq.corner[2][0];
        const double v = b[0] * tq.corner[0][1] + b[1] * tq.corner[1][1] + b[2] * tq.corner[2][1];
        const auto pq = fq.to_pixel(u, v);
        if (sample_inside(fq, res.images[q], pq[0], pq[1], &in.target.data[j * C])) {
          in.state[j] = PixelState::Known;
          ++known[p];
        }
        continue;
      }
      in.state[j] = PixelState::Fill;
      const auto vv = face_vertices(mesh, f);
      if (oriented) {
        const Vector3 fd = fdir[f.idx()];
        Vector3 d(0, 0, 0);
        for (int k = 0; k < 3; ++k) {
          Vector3 w = vdir[vv[k].idx()];
          if (line_field && w * fd < 0) w = -w;
          d = d + static_cast<double>(b[k]) * w;
        }
        double du = d * e1, dv = d * e2;
        if (du * du + dv * dv < 1e-12) { du = fd * e1; dv = fd * e2; }
        const double a = std::atan2(dv, du);  // exemplar +x along (du, dv) in the plane
        in.angle.data[j] = static_cast<float>(a);
        mean_c += std::cos(line_field ? 2 * a : a);
        mean_s += std::sin(line_field ? 2 * a : a);
      }
      if (opt.multi != MultiTexture::None) {
        double tt;
        if (opt.multi == MultiTexture::Illumination) {
          Vector3 n(0, 0, 0);
          for (int k = 0; k < 3; ++k) n = n + static_cast<double>(b[k]) * vnormal[vv[k]];
          tt = std::max(0.0, normalized_or(n, Vector3(0, 0, 1)) * light);
        } else {
          tt = b[0] * vt[vv[0].idx()] + b[1] * vt[vv[1].idx()] + b[2] * vt[vv[2].idx()];
        }
        in.exemplar_index[j] = std::clamp(static_cast<int>(std::floor(tt * E)), 0, E - 1);
      }
    }
    ElOptions eo = opt.el;
    eo.seed = mix_seed(opt.seed, static_cast<std::uint64_t>(p), static_cast<std::uint64_t>(pass));
    eo.progress = nullptr;
    eo.parallel_pixel_search = eo.parallel_pixel_search && pixel_parallel;
    if (eo.order == FillOrder::Direction) {
      double a = std::atan2(mean_s, mean_c);
      if (line_field) a *= 0.5;
      if (!oriented || (mean_c == 0 && mean_s == 0)) a = 0;
      eo.direction_x = std::cos(a);
      eo.direction_y = -std::sin(a);  // pixel y points down
    }
    ElResult r = efros_leung_synthesize(in, eo);
    texels[p] += r.synthesized + r.seeded;
    seeded[p] += r.seeded;
    // Keep only Inside pixels in the stored image (boundary filled at the end).
    Image& img = res.images[p];
    for (std::size_t j = 0; j < BN; ++j) {
      const std::size_t i = static_cast<std::size_t>(y0 + j / BW) * R + x0 + j % BW;
      if (fp.pixel[i] == PatchPixel::Inside) {
        for (int c = 0; c < C; ++c) img.data[i * C + c] = r.image.data[j * C + c];
        res.sources[p][i] = r.source[j];
      }
    }
    if (opt.progress) {
      std::lock_guard<std::mutex> lock(progress_mutex);
      report_progress(opt.progress, "synthesis", static_cast<double>(++step) / steps);
    }
  };

  // Main pass: patch p reads the images of its neighbours that come before
  // it in res.order, exactly as a sequential run in that order would; so p
  // may run as soon as those neighbours are done, and patches with no such
  // dependency between them run in parallel (TBB tasks). The result is the
  // same bytes for any thread count and schedule.
  {
    std::vector<int> rank(P);
    for (int i = 0; i < P; ++i) rank[res.order[i]] = i;
    std::vector<std::vector<int>> successors(P);
    std::unique_ptr<std::atomic<int>[]> pending(new std::atomic<int>[P]);
    for (int p = 0; p < P; ++p) {
      std::vector<int> deps;
      for (const FlatTriangle& tr : patches[p].boundary) {
        const int q = face_patch[tr.face];
        if (q != p && rank[q] < rank[p]) deps.push_back(q);
      }
      std::sort(deps.begin(), deps.end());
      deps.erase(std::unique(deps.begin(), deps.end()), deps.end());
      pending[p].store(static_cast<int>(deps.size()), std::memory_order_relaxed);
      for (int q : deps) successors[q].push_back(p);
    }
    // Splitting each pixel's search over threads only pays when few patches
    // can run side by side.
    const bool pixel_parallel = P < 4 * tbb::this_task_arena::max_concurrency();
    tbb::task_group tg;
    std::function<void(int)> run = [&](int p) {
      synth_one(p, 0, [&](int q) { return rank[q] < rank[p]; }, pixel_parallel);
      for (int q : successors[p])
        if (pending[q].fetch_sub(1, std::memory_order_acq_rel) == 1) tg.run([&run, q] { run(q); });
    };
    for (int p : res.order)
      if (pending[p].load(std::memory_order_relaxed) == 0) tg.run([&run, p] { run(p); });
    tg.wait();
  }
  // Re-synthesis (4.1) in the given order, each seeing every other patch.
  std::vector<char> done(P, 1);
  for (int p : opt.resynthesize) done[p] = 0;
  for (int p : opt.resynthesize) {
    synth_one(p, 1, [&](int q) { return done[q] != 0; }, true);
    done[p] = 1;
  }
  for (int p = 0; p < P; ++p) {
    res.texels += texels[p];
    res.seeded += seeded[p];
    res.known_boundary += known[p];
  }
  res.seconds_synthesis = t.seconds();

  // 7. Boundary pixels of every image from the neighbour's texture. Patch p
  // writes only its own Boundary pixels and reads only Inside pixels of
  // others, so the patches run in parallel.
  tbb::parallel_for(0, P, [&](int p) {
    const FlatPatch& fp = patches[p];
    for (std::size_t i = 0; i < N; ++i) {
      if (fp.pixel[i] != PatchPixel::Boundary) continue;
      const int f = fp.pixel_face[i];
      const int q = face_patch[f];
      const FlatPatch& fq = patches[q];
      const FlatTriangle& tq = fq.triangles[face_slot[f]];
      const auto& b = fp.pixel_bary[i];
      const double u = b[0] * tq.corner[0][0] + b[1] * tq.corner[1][0] + b[2] * tq.corner[2][0];
      const double v = b[0] * tq.corner[0][1] + b[1] * tq.corner[1][1] + b[2] * tq.corner[2][1];
      const auto pq = fq.to_pixel(u, v);
      sample_inside(fq, res.images[q], pq[0], pq[1], &res.images[p].data[i * C]);
    }
  });
  res.seconds_total = total.seconds();
  return res;
}

}  // namespace surftex
