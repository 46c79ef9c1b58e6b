// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch-based oriented surface synthesis (Gorla et al. 2003, 3-5).
#include "texture/patches/patch_synthesis.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <utility>

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
  if (!(o.min_exemplar_widths >= 0 && o.min_exemplar_widths <= 1000))
    bad("min_exemplar_widths " + std::to_string(o.min_exemplar_widths) + " outside 0..1000");
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


// Partition (3.1) and overlap splitting (3.2): the seed face of every patch.
std::vector<int> partition_into_patches(Mesh& mesh, const PatchSynthesisOptions& opt,
                                        PatchSynthesisResult& res) {
  res.partition = partition_near_planar(mesh, opt.partition);
  std::vector<int> seeds = res.partition.seed_face;
  res.split_patches = split_overlapping_patches(mesh, seeds, std::min(89.0, opt.partition.max_angle_deg));
  return seeds;
}

// What the pixels of every patch read from the surface: the direction field
// per face and per vertex (3.3.2) and the multi-texturing scalar per vertex.
struct SurfaceFields {
  bool oriented = false;    // a direction field steers the synthesis
  bool line_field = false;  // 2-symmetric (principal directions): d and -d alike
  std::vector<Vector3> fdir, vdir;
  std::vector<double> vt;  // multi-texturing t in [0, 1] (all but Illumination, which is per pixel)
};

bool principal_field(PatchField f) {
  return f == PatchField::Kmax || f == PatchField::Kmin || f == PatchField::KmaxAbs ||
         f == PatchField::KminAbs;
}

// The constant field names where the exemplar's up (its top edge) goes, so a
// photograph stands upright on an upright model: bricks lie in horizontal
// rows on a wall (Gorla's Fig. 11, right). The synthesis orients the
// exemplar's +x (its rows) along kFaceDirection, so the projected vector d
// is turned to d x n: the rows run across it and, with rows-down = x x n,
// the exemplar's top points along d. Principal fields keep +x along the
// curvature direction (bricks "oriented in the direction of" k, Fig. 11).
template <class FaceVectorMap>
void turn_up_field_to_rows(const Mesh& mesh, FaceVectorMap fd) {
  for (FaceIndex f : mesh.faces()) {
    const Vector3 d = fd[f];
    if (d.squared_length() == 0) continue;
    const Vector3 x = CGAL::cross_product(d, robust_face_normal(mesh, f));
    const double len = std::sqrt(x.squared_length());
    if (len > 0) fd[f] = x / len;
  }
}

constexpr double kFloorProjection = 0.01;  // flat to 0.6 degrees

// The face directions: a constant vector projected (3.3.2.1, 1-symmetric) or
// the principal directions of the most anisotropic faces (3.3.2.2,
// 2-symmetric), interpolated over the rest; zero where there is no constraint.
std::vector<Vector3> face_directions(Mesh& mesh, const PatchSynthesisOptions& opt) {
  std::vector<Vector3> fdir(mesh.num_faces(), Vector3(0, 0, 0));
  DirectionFieldOptions dfo;
  std::vector<DirectionConstraint> cons;
  if (opt.field == PatchField::Constant) {
    dfo.symmetry = 1;
    cons = constraints_from_constant_vector(mesh, opt.constant_vector);
    if (cons.empty())  // every face nearly orthogonal to the vector: all but the floors
      cons = constraints_from_constant_vector(mesh, opt.constant_vector, kFloorProjection);
    // Flat faces facing along the vector (|projection| below kFloorProjection,
    // so no face is constrained twice): parallel rows (floor_constraints).
    for (const DirectionConstraint& c : floor_constraints(mesh, opt.constant_vector, kFloorProjection))
      cons.push_back(c);
  } else {
    dfo.symmetry = 2;
    cons = principal_constraints(mesh, opt.field, opt.constraint_fraction);
  }
  if (!cons.empty()) {
    interpolate_direction_field(mesh, cons, dfo);
    auto fd = find(mesh, kFaceDirection).first;
    if (opt.field == PatchField::Constant) turn_up_field_to_rows(mesh, fd);
    for (FaceIndex f : mesh.faces()) fdir[f.idx()] = fd[f];
  }
  return fdir;
}

// Per vertex: the mean of its faces' directions in its tangent plane (a line
// field's signs aligned first), unit or zero.
std::vector<Vector3> vertex_directions(const Mesh& mesh, const std::vector<Vector3>& fdir, bool line_field) {
  auto vnormal = find(mesh, kVertexNormal).first;
  std::vector<Vector3> vdir(mesh.num_vertices(), Vector3(0, 0, 0));
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
  return vdir;
}

// Multi-texturing scalar per vertex (Curvature, Height, VertexScalar),
// normalised to [0, 1] between its quantiles (5% and 95% for curvature, the
// extremes otherwise); zeros for the other modes.
std::vector<double> multi_texture_scalar(const Mesh& mesh, const PatchSynthesisOptions& opt) {
  const std::size_t NV = mesh.num_vertices();
  std::vector<double> vt(NV, 0.0);
  if (opt.multi != MultiTexture::Curvature && opt.multi != MultiTexture::Height &&
      opt.multi != MultiTexture::VertexScalar)
    return vt;
  std::vector<double> raw(NV, 0.0);
  auto kmax = find(mesh, kVertexKmax).first;
  auto kmin = find(mesh, kVertexKmin).first;
  const Vector3 ax = vec(opt.height_axis);
  for (VertexIndex v : mesh.vertices()) {
    const std::size_t i = v.idx();
    if (opt.multi == MultiTexture::Curvature)
      raw[i] = 0.5 * (kmax[v] + kmin[v]);
    else if (opt.multi == MultiTexture::Height)
      raw[i] = (mesh.point(v) - CGAL::ORIGIN) * ax;
    else
      raw[i] = opt.vertex_scalar[i];
    if (!std::isfinite(raw[i]))
      throw InvalidInputError("synthesize_patches: multi-texturing value at vertex " + std::to_string(i) +
                              " is not finite");
  }
  std::vector<double> sorted = raw;
  std::sort(sorted.begin(), sorted.end());
  const double q = opt.multi == MultiTexture::Curvature ? 0.05 : 0.0;
  const double lo = sorted[static_cast<std::size_t>(q * (sorted.size() - 1))];
  const double hi = sorted[static_cast<std::size_t>((1 - q) * (sorted.size() - 1))];
  for (std::size_t i = 0; i < NV; ++i)
    vt[i] = hi > lo ? std::clamp((raw[i] - lo) / (hi - lo), 0.0, 1.0) : 0.5;
  return vt;
}

// Direction field (3.3.2, section 4's orientation options) and the per-vertex
// quantities the pixels need: vertex normals always, principal curvatures
// when a principal field, the curvature order or curvature multi-texturing
// asks for them.
SurfaceFields compute_surface_fields(Mesh& mesh, const PatchSynthesisOptions& opt) {
  compute_vertex_normals(mesh);
  const bool principal = principal_field(opt.field);
  const bool need_curv =
      principal || opt.order == PatchOrder::Curvature || opt.multi == MultiTexture::Curvature;
  if (need_curv) compute_principal_curvatures(mesh);
  SurfaceFields sf;
  sf.oriented = opt.field != PatchField::None;
  sf.line_field = principal;
  sf.fdir.assign(mesh.num_faces(), Vector3(0, 0, 0));
  sf.vdir.assign(mesh.num_vertices(), Vector3(0, 0, 0));
  if (sf.oriented) {
    sf.fdir = face_directions(mesh, opt);
    sf.vdir = vertex_directions(mesh, sf.fdir, sf.line_field);
  }
  sf.vt = multi_texture_scalar(mesh, opt);
  return sf;
}

// For every face: its patch and its slot in that patch's triangle list.
struct PatchFaces {
  std::vector<int> patch, slot;
};

PatchFaces index_patch_faces(const std::vector<FlatPatch>& patches, std::size_t num_faces) {
  PatchFaces pf;
  pf.patch.assign(num_faces, -1);
  pf.slot.assign(num_faces, -1);
  for (std::size_t p = 0; p < patches.size(); ++p)
    for (std::size_t i = 0; i < patches[p].triangles.size(); ++i) {
      pf.patch[patches[p].triangles[i].face] = static_cast<int>(p);
      pf.slot[patches[p].triangles[i].face] = static_cast<int>(i);
    }
  return pf;
}

// Patches sharing an edge, per patch, sorted and without repeats.
std::vector<std::vector<int>> patch_adjacency(const Mesh& mesh, const std::vector<int>& face_patch, int P) {
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
  return adj;
}

// Per patch, the mean principal curvature difference kmax - kmin over its
// triangles' corners (section 4's curvature order).
std::vector<double> curvature_scores(const Mesh& mesh, const std::vector<FlatPatch>& patches) {
  const int P = static_cast<int>(patches.size());
  std::vector<double> score(P, 0.0);
  auto kmax = find(mesh, kVertexKmax).first;
  auto kmin = find(mesh, kVertexKmin).first;
  for (int p = 0; p < P; ++p) {
    double s = 0;
    for (const FlatTriangle& tr : patches[p].triangles)
      for (VertexIndex v : face_vertices(mesh, FaceIndex(static_cast<Mesh::size_type>(tr.face))))
        s += kmax[v] - kmin[v];
    score[p] = s / (3.0 * patches[p].triangles.size());
  }
  return score;
}

// Patch order (4): among the untaken patches next to a taken one (any
// untaken patch when none is, "filling in any holes at the end"), a random
// one, or the one of greatest curvature score.
std::vector<int> choose_patch_order(const std::vector<std::vector<int>>& adj,
                                    const std::vector<double>& score, const PatchSynthesisOptions& opt) {
  const int P = static_cast<int>(adj.size());
  std::vector<int> order;
  std::mt19937_64 rng(mix_seed(opt.seed, 0xA11CE, 0));
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
    order.push_back(pick);
    for (int q : adj[pick]) front[q] = 1;
  }
  return order;
}

// A patch point (barycentric b in a face of another patch): that patch and
// the point's position in its raster.
std::pair<int, std::array<double, 2>> neighbour_pixel(const std::vector<FlatPatch>& patches, const PatchFaces& pf,
                                                      int face, const std::array<float, 3>& b) {
  const int q = pf.patch[face];
  const FlatPatch& fq = patches[q];
  const FlatTriangle& tq = fq.triangles[pf.slot[face]];
  const double u = b[0] * tq.corner[0][0] + b[1] * tq.corner[1][0] + b[2] * tq.corner[2][0];
  const double v = b[0] * tq.corner[0][1] + b[1] * tq.corner[1][1] + b[2] * tq.corner[2][1];
  return {q, fq.to_pixel(u, v)};
}

// The point looked up in that patch's image, Inside pixels only (3.2: the
// boundary triangles rotated into the plane carry their own patch's
// texture); false if none is Inside.
bool sample_neighbour(const std::vector<FlatPatch>& patches, const PatchFaces& pf,
                      const std::vector<Image>& images, int face, const std::array<float, 3>& b, float* out) {
  const auto [q, pq] = neighbour_pixel(patches, pf, face, b);
  return sample_inside(patches[q], images[q], pq[0], pq[1], out);
}

// Where the neighbour's texture at that point came from (its nearest Inside
// pixel's source moved by the sub-pixel offset, in exemplar coordinates), so
// the synthesis can continue it across the seam (ElInput::known_source);
// exemplar -1 if no pixel of the 2 x 2 footprint is Inside with a source.
ElExemplarPoint neighbour_source(const std::vector<FlatPatch>& patches, const PatchFaces& pf,
                                 const std::vector<std::vector<ElSource>>& sources, int rotations, int face,
                                 const std::array<float, 3>& b) {
  const auto [q, pq] = neighbour_pixel(patches, pf, face, b);
  const FlatPatch& fq = patches[q];
  const double fx = pq[0] - 0.5, fy = pq[1] - 0.5;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  ElExemplarPoint best;
  double best_d = std::numeric_limits<double>::infinity();
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int x = x0 + i, y = y0 + j;
      if (fq.state(x, y) != PatchPixel::Inside || sources[q].empty()) continue;
      const ElSource& s = sources[q][fq.index(x, y)];
      const double ox = fx - x, oy = fy - y, d = ox * ox + oy * oy;
      if (s.exemplar < 0 || !(d < best_d)) continue;
      // A raster offset is the same offset in the rotated exemplar's canvas.
      const double a = 2.0 * M_PI * s.rotation / rotations, c = std::cos(a), sn = std::sin(a);
      best = {s.exemplar, static_cast<float>(s.ex + c * ox - sn * oy), static_cast<float>(s.ey + sn * ox + c * oy)};
      best_d = d;
    }
  return best;
}

// The synthesis of one patch image (3.3): its Inside pixels are filled by
// Efros-Leung, steered per pixel by the direction field, from the boundary
// conditions its available neighbours' images give.
class PatchSynthesizer {
 public:
  PatchSynthesizer(const Mesh& mesh, const std::vector<Image>& exemplars, const PatchSynthesisOptions& opt,
                   const SurfaceFields& fields, const PatchFaces& faces, PatchSynthesisResult& res)
      : mesh_(mesh),
        opt_(opt),
        fields_(fields),
        faces_(faces),
        res_(res),
        patches_(res.flat.patches),
        vnormal_(find(mesh, kVertexNormal).first),
        C_(exemplars[0].channels),
        E_(static_cast<int>(exemplars.size())),
        light_(normalized_or(vec(opt.light), Vector3(0, 0, 1))),
        // Exemplar rotations prepared once for every patch (not once per patch).
        prepared_(el_prepare_exemplars(exemplars, opt.el)),
        texels_(patches_.size(), 0),
        seeded_(patches_.size(), 0),
        known_(patches_.size(), 0),
        candidates_(patches_.size(), 0),
        widened_(patches_.size(), 0),
        steps_(patches_.size() + opt.resynthesize.size()) {
    // Each patch's image and sources are allocated by its own task
    // (store_inside), in parallel, not here.
    res_.images.resize(patches_.size());
    res_.sources.resize(patches_.size());
  }

  // Synthesises patch p (pass 0: main, 1: re-synthesis). available(q) says
  // whether patch q's image is a boundary condition for p (synthesised
  // before p in the order).
  template <class Available>
  void synthesize(int p, int pass, const Available& available, bool pixel_parallel) {
    const FlatPatch& fp = patches_[p];
    // Synthesis runs on the patch's window (the box of its Inside and
    // Boundary pixels); row-major order, relative positions and hence the
    // result are those of the full raster.
    const std::size_t n = fp.pixel.size();
    ElInput in;
    in.prepared = prepared_;
    in.target = Image(fp.bw, fp.bh, C_, 0.f);
    in.state.assign(n, PixelState::Outside);
    if (fields_.oriented) in.angle = Image(fp.bw, fp.bh, 1, 0.f);
    if (opt_.multi != MultiTexture::None) in.exemplar_index.assign(n, 0);
    if (opt_.el.coherence > 0) in.known_source.assign(n, ElExemplarPoint());
    double mean_c = 0, mean_s = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const PatchPixel kind = fp.pixel[i];
      if (kind == PatchPixel::Outside) continue;
      if (kind == PatchPixel::Boundary) {
        if (!available(faces_.patch[fp.pixel_face[i]])) continue;
        if (sample_neighbour(patches_, faces_, res_.images, fp.pixel_face[i], fp.pixel_bary[i],
                             &in.target.data[i * C_])) {
          in.state[i] = PixelState::Known;
          ++known_[p];
          if (!in.known_source.empty())
            in.known_source[i] = neighbour_source(patches_, faces_, res_.sources, opt_.el.rotations,
                                                  fp.pixel_face[i], fp.pixel_bary[i]);
        }
        continue;
      }
      in.state[i] = PixelState::Fill;
      fill_pixel_inputs(fp, i, in, mean_c, mean_s);
    }
    const ElResult r = efros_leung_synthesize(in, el_options(p, pass, pixel_parallel, mean_c, mean_s));
    texels_[p] += r.synthesized + r.seeded;
    seeded_[p] += r.seeded;
    candidates_[p] += r.pass1_candidates;
    widened_[p] += r.pass1_widened;
    store_inside(p, r);
    if (opt_.progress) {
      std::lock_guard<std::mutex> lock(progress_mutex_);
      report_progress(opt_.progress, "synthesis", static_cast<double>(++step_) / steps_);
    }
  }

  // The per-patch counts summed into the result.
  void add_counts() const {
    for (std::size_t p = 0; p < patches_.size(); ++p) {
      res_.texels += texels_[p];
      res_.seeded += seeded_[p];
      res_.known_boundary += known_[p];
      res_.pass1_candidates += candidates_[p];
      res_.pass1_widened += widened_[p];
    }
  }

 private:
  // A Fill pixel's angle (the vertex directions interpolated in its face and
  // expressed in the patch plane: exemplar +x along it) and exemplar index
  // (multi-texturing); mean_c/mean_s accumulate the angles' mean direction.
  void fill_pixel_inputs(const FlatPatch& fp, std::size_t i, ElInput& in, double& mean_c,
                         double& mean_s) const {
    const FaceIndex f(static_cast<Mesh::size_type>(fp.pixel_face[i]));
    const auto& b = fp.pixel_bary[i];
    const auto vv = face_vertices(mesh_, f);
    const bool line_field = fields_.line_field;
    if (fields_.oriented) {
      const Vector3 e1 = vec(fp.e1), e2 = vec(fp.e2);
      const Vector3 fd = fields_.fdir[f.idx()];
      Vector3 d(0, 0, 0);
      for (int k = 0; k < 3; ++k) {
        Vector3 w = fields_.vdir[vv[k].idx()];
        if (line_field && w * fd < 0) w = -w;
        d = d + static_cast<double>(b[k]) * w;
      }
      double du = d * e1, dv = d * e2;
      if (du * du + dv * dv < 1e-12) {
        du = fd * e1;
        dv = fd * e2;
      }
      const double a = std::atan2(dv, du);  // exemplar +x along (du, dv) in the plane
      in.angle.data[i] = static_cast<float>(a);
      mean_c += std::cos(line_field ? 2 * a : a);
      mean_s += std::sin(line_field ? 2 * a : a);
    }
    if (opt_.multi != MultiTexture::None) {
      double tt;
      if (opt_.multi == MultiTexture::Illumination) {
        Vector3 n(0, 0, 0);
        for (int k = 0; k < 3; ++k) n = n + static_cast<double>(b[k]) * vnormal_[vv[k]];
        tt = std::max(0.0, normalized_or(n, Vector3(0, 0, 1)) * light_);
      } else {
        const std::vector<double>& vt = fields_.vt;
        tt = b[0] * vt[vv[0].idx()] + b[1] * vt[vv[1].idx()] + b[2] * vt[vv[2].idx()];
      }
      in.exemplar_index[i] = std::clamp(static_cast<int>(std::floor(tt * E_)), 0, E_ - 1);
    }
  }

  // The run's Efros-Leung options: its own seed; a direction sweep follows
  // the patch's mean field direction (section 4, "following the direction
  // of the vector field").
  ElOptions el_options(int p, int pass, bool pixel_parallel, double mean_c, double mean_s) const {
    ElOptions eo = opt_.el;
    eo.seed = mix_seed(opt_.seed, static_cast<std::uint64_t>(p), static_cast<std::uint64_t>(pass));
    eo.progress = nullptr;
    eo.parallel_pixel_search = eo.parallel_pixel_search && pixel_parallel;
    if (eo.order == FillOrder::Direction) {
      double a = std::atan2(mean_s, mean_c);
      if (fields_.line_field) a *= 0.5;
      if (!fields_.oriented || (mean_c == 0 && mean_s == 0)) a = 0;
      eo.direction_x = std::cos(a);
      eo.direction_y = -std::sin(a);  // pixel y points down
    }
    return eo;
  }

  // Keeps only Inside pixels in the stored image (boundary filled at the end).
  void store_inside(int p, const ElResult& r) {
    const FlatPatch& fp = patches_[p];
    Image& img = res_.images[p];
    if (img.empty()) img = Image(fp.bw, fp.bh, C_, 0.f);
    if (res_.sources[p].empty()) res_.sources[p].resize(fp.pixel.size());
    for (std::size_t i = 0; i < fp.pixel.size(); ++i)
      if (fp.pixel[i] == PatchPixel::Inside) {
        for (int c = 0; c < C_; ++c) img.data[i * C_ + c] = r.image.data[i * C_ + c];
        res_.sources[p][i] = r.source[i];
      }
  }

  const Mesh& mesh_;
  const PatchSynthesisOptions& opt_;
  const SurfaceFields& fields_;
  const PatchFaces& faces_;
  PatchSynthesisResult& res_;
  const std::vector<FlatPatch>& patches_;
  PropertyMap<VertexIndex, Vector3> vnormal_;
  const int C_, E_;
  const Vector3 light_;
  const std::shared_ptr<const ElPreparedExemplars> prepared_;
  // Per patch: texels filled, of which seeded, Known boundary pixels.
  std::vector<std::size_t> texels_, seeded_, known_, candidates_, widened_;
  std::mutex progress_mutex_;
  std::size_t step_ = 0;
  const std::size_t steps_;
};

// Main pass (3.3) in `order`: patch p reads the images of its neighbours
// that come before it in the order, exactly as a sequential run in that
// order would; so p may run as soon as those neighbours are done, and
// patches with no such dependency between them run in parallel (TBB tasks).
// The result is the same bytes for any thread count and schedule.
void synthesize_in_order(PatchSynthesizer& synth, const std::vector<FlatPatch>& patches, const PatchFaces& pf,
                         const std::vector<int>& order) {
  const int P = static_cast<int>(patches.size());
  std::vector<int> rank(P);
  for (int i = 0; i < P; ++i) rank[order[i]] = i;
  std::vector<std::vector<int>> successors(P);
  std::unique_ptr<std::atomic<int>[]> pending(new std::atomic<int>[P]);
  for (int p = 0; p < P; ++p) {
    std::vector<int> deps;
    for (const FlatTriangle& tr : patches[p].boundary) {
      const int q = pf.patch[tr.face];
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
    synth.synthesize(
        p, 0, [&](int q) { return rank[q] < rank[p]; }, pixel_parallel);
    for (int q : successors[p])
      if (pending[q].fetch_sub(1, std::memory_order_acq_rel) == 1) tg.run([&run, q] { run(q); });
  };
  for (int p : order)
    if (pending[p].load(std::memory_order_relaxed) == 0) tg.run([&run, p] { run(p); });
  tg.wait();
}

// Re-synthesis (4.1) of the given patches in the given order, each seeing
// every other patch as a boundary condition.
void resynthesize(PatchSynthesizer& synth, int P, const std::vector<int>& ids) {
  std::vector<char> done(P, 1);
  for (int p : ids) done[p] = 0;
  for (int p : ids) {
    synth.synthesize(
        p, 1, [&](int q) { return done[q] != 0; }, true);
    done[p] = 1;
  }
}

// Boundary pixels of every image from the neighbour's texture. Patch p
// writes only its own Boundary pixels and reads only Inside pixels of
// others, so the patches run in parallel.
void fill_boundary_pixels(PatchSynthesisResult& res, const PatchFaces& pf, int C) {
  const std::vector<FlatPatch>& patches = res.flat.patches;
  tbb::parallel_for(0, static_cast<int>(patches.size()), [&](int p) {
    const FlatPatch& fp = patches[p];
    for (std::size_t i = 0; i < fp.pixel.size(); ++i) {
      if (fp.pixel[i] != PatchPixel::Boundary) continue;
      sample_neighbour(patches, pf, res.images, fp.pixel_face[i], fp.pixel_bary[i],
                       &res.images[p].data[i * C]);
    }
  });
}

}  // namespace

namespace {
// PatchSynthesisOptions::min_exemplar_widths: the flattening options whose
// texel shows `widths` exemplar widths across `longest` where `flat` (at `fo`)
// shows fewer: the raster's inside (resolution less both margins) grows by the
// missing factor, the margin keeps its share of the side. Never more than
// one atlas of atlas_side could hold: the raster windows' area grows with the
// square of the resolution (a 2048 px exemplar on a coarse mesh would
// otherwise ask for gigabytes of rasters before the atlas check).
FlattenOptions raised_for_widths(const FlattenOptions& fo, const FlattenResult& flat, double longest, int ex_width,
                                 double widths, int atlas_side) {
  const double shown = longest / (flat.texel * ex_width);
  if (!(shown > 0) || shown >= widths) return fo;
  const double f = widths / shown;
  FlattenOptions up = fo;
  up.margin = std::max(fo.margin, static_cast<int>(std::ceil(fo.margin * f)));
  const double inside = std::ceil((fo.resolution - 2 * fo.margin - 1) * f) + 1;  // flatten_patches keeps one texel
  up.resolution = static_cast<int>(std::min(4096.0, inside + 2 * up.margin));
  up.margin = std::min(up.margin, up.resolution / 4);
  double windows = 0;
  for (const FlatPatch& p : flat.patches) windows += static_cast<double>(p.bw) * p.bh;
  if (!(windows > 0) || up.resolution <= fo.resolution) return up;
  const double atlas = static_cast<double>(atlas_side) * atlas_side;
  const int cap = static_cast<int>(std::floor(fo.resolution * std::sqrt(atlas / windows)));
  if (up.resolution > cap) {
    up.margin = std::max(fo.margin, static_cast<int>(std::lround(up.margin * double(cap) / up.resolution)));
    up.resolution = std::max(fo.resolution, cap);
    up.margin = std::min(up.margin, up.resolution / 4);
  }
  return up;
}

// Step 3 with the texture-scale floor and the atlas check (see
// PatchSynthesisOptions::atlas): the rasters at flatten.resolution (raised for
// min_exemplar_widths), or lowered by eighths until one atlas holds them.
FlattenResult flatten_to_fit_atlas(const Mesh& mesh, const std::vector<int>& seeds, const PatchSynthesisOptions& opt,
                                   int ex_width, PatchSynthesisResult& res) {
  FlattenOptions fo = opt.flatten;
  FlattenResult flat = flatten_patches(mesh, seeds, fo);
  const double longest = longest_bbox_side(mesh);
  res.exemplar_widths_partition = longest / (flat.texel * ex_width);
  if (opt.fit_resolution && opt.min_exemplar_widths > 0) {
    const FlattenOptions up =
        raised_for_widths(fo, flat, longest, ex_width, opt.min_exemplar_widths, opt.atlas.max_size);
    if (up.resolution != fo.resolution) {
      fo = up;
      flat = flatten_patches(mesh, seeds, fo);
    }
  }
  res.resolution_wanted = fo.resolution;
  for (;;) {
    if (!opt.check_atlas || patch_rasters_fit(flat, opt.atlas)) {
      res.resolution = fo.resolution;
      res.exemplar_widths = longest / (flat.texel * ex_width);
      return flat;
    }
    const int lower = std::max(16, fo.resolution * 7 / 8);
    // A raised margin comes down with the resolution, to the options' own.
    const FlattenOptions& given = opt.flatten;
    const int margin = std::min(
        fo.margin, std::max(given.margin, static_cast<int>(std::lround(given.margin * double(lower) / given.resolution))));
    if (!opt.fit_resolution || lower == fo.resolution || margin > lower / 4)
      throw InvalidInputError("synthesize_patches: " + std::to_string(flat.patches.size()) + " patches of " +
                              std::to_string(fo.resolution) + " texels a side do not fit one " +
                              std::to_string(opt.atlas.max_size) + " px atlas: lower --patch-res or raise "
                              "--max-patch-faces (fewer, larger patches)");
    fo.margin = margin;
    fo.resolution = lower;
    flat = flatten_patches(mesh, seeds, fo);
  }
}
}  // namespace

PatchSynthesisResult synthesize_patches(Mesh& mesh, const std::vector<Image>& exemplars,
                                        const PatchSynthesisOptions& opt) {
  validate(mesh, exemplars, opt);
  require_triangle_mesh(mesh, "synthesize_patches");
  if (exemplars[0].channels > 8)
    throw InvalidInputError("synthesize_patches: exemplars have " + std::to_string(exemplars[0].channels) +
                            " channels, at most 8 supported");
  Timer total;
  PatchSynthesisResult res;
  // 1. Partition (3.1) and overlap splitting (3.2).
  Timer t;
  report_progress(opt.progress, "partition", 0.0);
  const std::vector<int> seeds = partition_into_patches(mesh, opt, res);
  const int P = static_cast<int>(seeds.size());
  res.seconds_partition = t.seconds();

  // 2. Direction field (3.3.2) and the per-vertex quantities the pixels need.
  t.reset();
  report_progress(opt.progress, "field", 0.0);
  const SurfaceFields fields = compute_surface_fields(mesh, opt);
  res.seconds_field = t.seconds();

  // 3. Flatten and rasterise (3.2).
  t.reset();
  report_progress(opt.progress, "flatten", 0.0);
  res.flat = flatten_to_fit_atlas(mesh, seeds, opt, exemplars[0].width, res);
  res.seconds_flatten = t.seconds();
  const PatchFaces faces = index_patch_faces(res.flat.patches, mesh.num_faces());
  for (int id : opt.resynthesize)
    if (id < 0 || id >= P)
      throw InvalidInputError("synthesize_patches: resynthesize id " + std::to_string(id) + " outside 0.." +
                              std::to_string(P - 1));

  // 4. Patch order (4).
  const std::vector<double> score = opt.order == PatchOrder::Curvature
                                        ? curvature_scores(mesh, res.flat.patches)
                                        : std::vector<double>(P, 0.0);
  res.order = choose_patch_order(patch_adjacency(mesh, faces.patch, P), score, opt);

  // 5. Synthesis per patch (3.3), re-synthesis (4.1), then every image's
  // boundary pixels from its neighbours.
  t.reset();
  PatchSynthesizer synth(mesh, exemplars, opt, fields, faces, res);
  synthesize_in_order(synth, res.flat.patches, faces, res.order);
  resynthesize(synth, P, opt.resynthesize);
  synth.add_counts();
  res.seconds_synthesis = t.seconds();
  fill_boundary_pixels(res, faces, exemplars[0].channels);
  res.seconds_total = total.seconds();
  return res;
}

}  // namespace surftex
