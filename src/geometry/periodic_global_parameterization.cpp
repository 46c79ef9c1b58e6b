// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/periodic_global_parameterization.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <tbb/parallel_invoke.h>

#include <cmath>
#include <deque>
#include <string>

#include "geometry/effect_area.h"
#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"
#include "geometry/timer.h"

namespace surftex {
namespace {

using Cplx = std::complex<double>;
using SpMat = Eigen::SparseMatrix<Cplx>;
using Ldlt = Eigen::SimplicialLDLT<SpMat>;

struct FaceGrad {
  Vector3 gs, gt;
};

void check_options(const PgpOptions& o) {
  if (o.symmetry != 1 && o.symmetry != 2 && o.symmetry != 4)
    throw InvalidInputError("periodic_global_parameterization: symmetry must be 1, 2 or 4, got " +
                            std::to_string(o.symmetry));
}

std::vector<FaceGrad> face_gradients(const Mesh& mesh, const PgpOptions& o,
                                     std::vector<FaceFrame>* frames_out) {
  auto dir = mesh.property_map<FaceIndex, Vector3>(o.direction_map);
  if (!dir.second)
    throw InvalidInputError("periodic_global_parameterization: face map '" + o.direction_map +
                            "' absent (interpolate a direction field first)");
  auto scale = mesh.property_map<VertexIndex, double>(o.scale_map);
  std::vector<FaceGrad> g(mesh.num_faces());
  std::vector<FaceFrame> frames(mesh.num_faces());
  for (FaceIndex f : mesh.faces()) {
    const FaceFrame fr = face_frame(mesh, f);
    frames[f.idx()] = fr;
    double s = 0;
    for (VertexIndex v : face_vertices(mesh, f)) {
      const double sv = scale.second ? scale.first[v] : 1.0;
      if (!(sv > 0) || !std::isfinite(sv))
        throw InvalidInputError("periodic_global_parameterization: scale at vertex " +
                                std::to_string(v.idx()) + " is " + std::to_string(sv) +
                                " (must be > 0)");
      s += sv;
    }
    s /= 3;
    const Vector3 d = dir.first[f];
    const Vector3 ds = normalized_or(d - (d * fr.n) * fr.n, fr.e1);
    const Vector3 dt = CGAL::cross_product(fr.n, ds);
    g[f.idx()] = {ds / s, dt / s};
  }
  if (frames_out) *frames_out = std::move(frames);
  return g;
}

std::vector<std::array<double, 2>> halfedge_alphas(const Mesh& mesh, const PgpOptions& o,
                                                   const std::vector<FaceGrad>& g,
                                                   const std::vector<FaceFrame>& frames) {
  const double step = 2 * M_PI / o.symmetry;
  std::vector<std::array<double, 2>> alpha(mesh.num_halfedges(), {0.0, 0.0});
  for (EdgeIndex e : mesh.edges()) {
    HalfedgeIndex h = mesh.halfedge(e, 0);
    if (mesh.is_border(h)) h = mesh.opposite(h);
    if (mesh.is_border(h)) continue;  // isolated edge
    const Vector3 ev = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
    const std::size_t T = mesh.face(h).idx();
    Vector3 gs = g[T].gs, gt = g[T].gt;
    const HalfedgeIndex o = mesh.opposite(h);
    if (!mesh.is_border(o)) {
      const std::size_t U = mesh.face(o).idx();
      const FaceFrame &fT = frames[T], &fU = frames[U];
      const double tT = fT.angle_of(g[T].gs), tU = fU.angle_of(g[U].gs);
      const double transported = tT - fT.angle_of(ev) + fU.angle_of(ev);
      const double k = std::round((transported - tU) / step);
      const double inv_s = norm(g[U].gs);
      const Vector3 ds = fU.direction(tU + k * step);
      const Vector3 dt = CGAL::cross_product(fU.n, ds);
      gs = 0.5 * (gs + inv_s * ds);
      gt = 0.5 * (gt + inv_s * dt);
    }
    const std::array<double, 2> a{ev * gs, ev * gt};
    alpha[h.idx()] = a;
    alpha[o.idx()] = {-a[0], -a[1]};
  }
  return alpha;
}

}  // namespace

std::vector<std::array<double, 2>> pgp_halfedge_alphas(const Mesh& mesh, const PgpOptions& o) {
  check_options(o);
  std::vector<FaceFrame> frames;
  const auto g = face_gradients(mesh, o, &frames);
  return halfedge_alphas(mesh, o, g, frames);
}

std::vector<std::array<std::array<double, 3>, 2>> pgp_face_gradients(const Mesh& mesh,
                                                                     const PgpOptions& o) {
  check_options(o);
  const auto g = face_gradients(mesh, o, nullptr);
  std::vector<std::array<std::array<double, 3>, 2>> out(g.size());
  for (std::size_t i = 0; i < g.size(); ++i)
    out[i] = {{{g[i].gs.x(), g[i].gs.y(), g[i].gs.z()}, {g[i].gt.x(), g[i].gt.y(), g[i].gt.z()}}};
  return out;
}

struct PeriodicGlobalParameterization::Impl {
  Mesh& mesh;
  PgpOptions opt;
  std::vector<Cplx> zs, zt;
  bool initialized = false;
  std::vector<int> var;  // free-vertex numbering of the last analysis
  int n_var = 0;
  Ldlt solver[2];
  bool analyzed = false;

  Impl(Mesh& m, PgpOptions o) : mesh(m), opt(std::move(o)) {}

  PgpResult solve(const std::vector<char>& free_vertex, const std::vector<char>* free_face);
  void write_corners(const std::vector<std::array<double, 2>>& alpha, const std::vector<char>* free_face);
};

void PeriodicGlobalParameterization::Impl::write_corners(const std::vector<std::array<double, 2>>& alpha,
                                                        const std::vector<char>* free_face) {
  // Corner coordinates, equation (4): from corner 0 (i = target(halfedge(f)))
  // along the two edges (i,j) and (i,k), the integer jump chosen so that the
  // difference is nearest to the edge's alpha_ij, which both faces of the edge
  // share: two faces whose three edge differences close (no zero of z inside)
  // then agree on their common edge exactly.
  auto stm = mesh.add_property_map<HalfedgeIndex, STM>(opt.stm_map, STM{0, 0, 0}).first;
  auto mat = mesh.property_map<VertexIndex, double>(opt.material_map);
  for (FaceIndex f : mesh.faces()) {
    if (free_face && !(*free_face)[f.idx()]) continue;
    const HalfedgeIndex h0 = mesh.halfedge(f);
    const HalfedgeIndex hs[3] = {h0, mesh.next(h0), mesh.next(mesh.next(h0))};
    const VertexIndex vi = mesh.target(h0);
    const double si = std::arg(zs[vi.idx()]) / (2 * M_PI);
    const double ti = std::arg(zt[vi.idx()]) / (2 * M_PI);
    // alpha along i -> corner c: c = 1 via hs[1] (i -> j); c = 2 against hs[0] (k -> i).
    const std::array<double, 2> a1 = alpha[hs[1].idx()];
    const std::array<double, 2> a2{-alpha[hs[0].idx()][0], -alpha[hs[0].idx()][1]};
    for (int c = 0; c < 3; ++c) {
      const VertexIndex v = mesh.target(hs[c]);
      const double m = mat.second ? mat.first[v] : 0.0;
      if (c == 0) {
        stm[hs[c]] = {si, ti, m};
        continue;
      }
      const std::array<double, 2>& a = c == 1 ? a1 : a2;
      const double sj = std::arg(zs[v.idx()]) / (2 * M_PI);
      const double tj = std::arg(zt[v.idx()]) / (2 * M_PI);
      stm[hs[c]] = {sj + std::round(si + a[0] - sj), tj + std::round(ti + a[1] - tj), m};
    }
  }
}

PgpResult PeriodicGlobalParameterization::Impl::solve(const std::vector<char>& free_vertex,
                                                      const std::vector<char>* free_face) {
  Timer timer;
  check_options(opt);
  require_triangle_mesh(mesh, "periodic_global_parameterization");
  std::vector<FaceFrame> frames;
  const auto g = face_gradients(mesh, opt, &frames);
  const auto alpha = halfedge_alphas(mesh, opt, g, frames);

  const std::size_t nv = mesh.num_vertices();
  std::vector<int> new_var(nv, -1);
  int count = 0;
  for (VertexIndex v : mesh.vertices())
    if (free_vertex[v.idx()]) new_var[v.idx()] = count++;
  PgpResult res;
  res.free_vertices = static_cast<std::size_t>(count);
  const bool same_pattern = analyzed && new_var == var;
  res.reused_analysis = same_pattern;
  var = std::move(new_var);
  n_var = count;

  // Complex Hermitian form of F_PGP: for the residual z_j - r z_i (r = exp(2 pi
  // i alpha_ij)), A(i,i) += w, A(j,j) += w, A(j,i) = -w r, A(i,j) = -w conj(r).
  auto build = [&](int c, const std::vector<Cplx>& z, SpMat& A, Eigen::VectorXcd& rhs) {
    std::vector<Eigen::Triplet<Cplx>> trip;
    trip.reserve(static_cast<std::size_t>(n_var) * 8);
    rhs = Eigen::VectorXcd::Zero(n_var);
    for (EdgeIndex e : mesh.edges()) {
      const HalfedgeIndex h = mesh.halfedge(e, 0);
      const std::size_t i = mesh.source(h).idx(), j = mesh.target(h).idx();
      const int vi = var[i], vj = var[j];
      if (vi < 0 && vj < 0) continue;
      double w = 0;
      if (!mesh.is_border(h)) w += face_area(mesh, mesh.face(h));
      if (!mesh.is_border(mesh.opposite(h))) w += face_area(mesh, mesh.face(mesh.opposite(h)));
      const Cplx r = std::polar(1.0, 2 * M_PI * alpha[h.idx()][c]);
      if (vi >= 0) trip.emplace_back(vi, vi, Cplx(w, 0));
      if (vj >= 0) trip.emplace_back(vj, vj, Cplx(w, 0));
      if (vi >= 0 && vj >= 0) {
        trip.emplace_back(vj, vi, -w * r);
        trip.emplace_back(vi, vj, -w * std::conj(r));
      } else if (vj >= 0) {
        rhs[vj] += w * r * z[i];
      } else {
        rhs[vi] += w * std::conj(r) * z[j];
      }
    }
    A.resize(n_var, n_var);
    A.setFromTriplets(trip.begin(), trip.end());
  };

  std::vector<Cplx>* zc[2] = {&zs, &zt};
  std::string failure[2];
  auto run = [&](int c) {
    if (n_var == 0) return;
    SpMat A;
    Eigen::VectorXcd rhs;
    build(c, *zc[c], A, rhs);
    if (!same_pattern) solver[c].analyzePattern(A);
    solver[c].factorize(A);
    if (solver[c].info() != Eigen::Success) {
      failure[c] = "factorisation failed";
      return;
    }
    const Eigen::VectorXcd x = solver[c].solve(rhs);
    if (solver[c].info() != Eigen::Success) {
      failure[c] = "solve failed";
      return;
    }
    std::vector<Cplx>& z = *zc[c];
    for (std::size_t v = 0; v < var.size(); ++v) {
      if (var[v] < 0) continue;
      const Cplx val = x[var[v]];
      const double a = std::abs(val);
      z[v] = (a > 1e-300 && std::isfinite(a)) ? val / a : Cplx(1, 0);
    }
  };
  tbb::parallel_invoke([&] { run(0); }, [&] { run(1); });
  for (int c = 0; c < 2; ++c)
    if (!failure[c].empty())
      throw SolverError(std::string("periodic_global_parameterization: ") + (c ? "t" : "s") +
                        " system " + failure[c] + " (" + std::to_string(n_var) + " free vertices)");
  analyzed = n_var > 0;

  // Energies at the (normalised) solution.
  for (EdgeIndex e : mesh.edges()) {
    const HalfedgeIndex h = mesh.halfedge(e, 0);
    const std::size_t i = mesh.source(h).idx(), j = mesh.target(h).idx();
    double w = 0;
    if (!mesh.is_border(h)) w += face_area(mesh, mesh.face(h));
    if (!mesh.is_border(mesh.opposite(h))) w += face_area(mesh, mesh.face(mesh.opposite(h)));
    res.energy_s += w * std::norm(zs[j] - std::polar(1.0, 2 * M_PI * alpha[h.idx()][0]) * zs[i]);
    res.energy_t += w * std::norm(zt[j] - std::polar(1.0, 2 * M_PI * alpha[h.idx()][1]) * zt[i]);
  }

  write_corners(alpha, free_face);
  res.seconds = timer.seconds();
  return res;
}

PeriodicGlobalParameterization::PeriodicGlobalParameterization(Mesh& mesh, PgpOptions options)
    : impl_(std::make_unique<Impl>(mesh, std::move(options))) {
  check_options(impl_->opt);
}

PeriodicGlobalParameterization::~PeriodicGlobalParameterization() = default;

PgpResult PeriodicGlobalParameterization::initialize() {
  Mesh& mesh = impl_->mesh;
  const std::size_t nv = mesh.num_vertices();
  if (impl_->opt.locked_vertex >= nv || mesh.is_removed(VertexIndex(impl_->opt.locked_vertex)))
    throw InvalidInputError("periodic_global_parameterization: locked_vertex " +
                            std::to_string(impl_->opt.locked_vertex) + " out of range (" +
                            std::to_string(nv) + " vertices)");
  impl_->zs.assign(nv, Cplx(1, 0));
  impl_->zt.assign(nv, Cplx(1, 0));
  // One locked vertex per connected component.
  std::vector<char> free_vertex(nv, 1), seen(nv, 0);
  for (VertexIndex v : mesh.vertices()) seen[v.idx()] = 0;
  std::vector<VertexIndex> starts{VertexIndex(impl_->opt.locked_vertex)};
  for (VertexIndex v : mesh.vertices()) starts.push_back(v);
  for (VertexIndex s : starts) {
    if (seen[s.idx()]) continue;
    free_vertex[s.idx()] = 0;  // z = 1 <=> s = t = 0
    seen[s.idx()] = 1;
    std::deque<VertexIndex> q{s};
    while (!q.empty()) {
      const VertexIndex v = q.front();
      q.pop_front();
      if (mesh.halfedge(v) == Mesh::null_halfedge()) continue;
      for (VertexIndex w : CGAL::vertices_around_target(mesh.halfedge(v), mesh))
        if (!seen[w.idx()]) {
          seen[w.idx()] = 1;
          q.push_back(w);
        }
    }
  }
  for (std::size_t i = 0; i < nv; ++i)
    if (mesh.is_removed(VertexIndex(i))) free_vertex[i] = 0;
  impl_->analyzed = false;
  PgpResult r = impl_->solve(free_vertex, nullptr);
  impl_->initialized = true;
  return r;
}

PgpResult PeriodicGlobalParameterization::update(const EffectArea& area) {
  if (!impl_->initialized)
    throw InvalidInputError("PeriodicGlobalParameterization::update called before initialize()");
  if (area.vertex_free.size() != impl_->mesh.num_vertices() ||
      area.face_free.size() != impl_->mesh.num_faces())
    throw InvalidInputError("PeriodicGlobalParameterization::update: effect area does not match the mesh");
  return impl_->solve(area.vertex_free, &area.face_free);
}

const std::vector<std::complex<double>>& PeriodicGlobalParameterization::z_s() const {
  return impl_->zs;
}
const std::vector<std::complex<double>>& PeriodicGlobalParameterization::z_t() const {
  return impl_->zt;
}

void PeriodicGlobalParameterization::set_state(std::vector<std::complex<double>> zs,
                                               std::vector<std::complex<double>> zt) {
  const std::size_t nv = impl_->mesh.num_vertices();
  if (zs.size() != nv || zt.size() != nv)
    throw InvalidInputError("PeriodicGlobalParameterization::set_state: " + std::to_string(zs.size()) +
                            " values for " + std::to_string(nv) + " vertices");
  impl_->zs = std::move(zs);
  impl_->zt = std::move(zt);
  impl_->initialized = true;
  impl_->analyzed = false;
}

void PeriodicGlobalParameterization::write_corners() {
  if (!impl_->initialized)
    throw InvalidInputError("PeriodicGlobalParameterization::write_corners called before initialize()/set_state()");
  check_options(impl_->opt);
  require_triangle_mesh(impl_->mesh, "periodic_global_parameterization");
  std::vector<FaceFrame> frames;
  const auto g = face_gradients(impl_->mesh, impl_->opt, &frames);
  impl_->write_corners(halfedge_alphas(impl_->mesh, impl_->opt, g, frames), nullptr);
}

double pgp_default_scale(const Mesh& mesh, double edges_per_period) {
  if (!(edges_per_period > 0) || !std::isfinite(edges_per_period))
    throw InvalidInputError("pgp_default_scale: edges_per_period must be > 0, got " + std::to_string(edges_per_period));
  double sum = 0;
  std::size_t n = 0;
  for (EdgeIndex e : mesh.edges()) {
    const HalfedgeIndex h = mesh.halfedge(e);
    sum += norm(mesh.point(mesh.target(h)) - mesh.point(mesh.source(h)));
    ++n;
  }
  if (n == 0 || !(sum > 0)) throw InvalidInputError("pgp_default_scale: the mesh has no edge of positive length");
  return edges_per_period * sum / static_cast<double>(n);
}

PgpResult periodic_global_parameterization(Mesh& mesh, const PgpOptions& options) {
  PeriodicGlobalParameterization solver(mesh, options);
  return solver.initialize();
}

}  // namespace surftex
