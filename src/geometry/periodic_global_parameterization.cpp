// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/periodic_global_parameterization.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
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
  if (o.init_iterations < 1)
    throw InvalidInputError("periodic_global_parameterization: init_iterations must be >= 1, got " +
                            std::to_string(o.init_iterations));
  if (o.update_iterations < 1)
    throw InvalidInputError("periodic_global_parameterization: update_iterations must be >= 1, got " +
                            std::to_string(o.update_iterations));
  if (!(o.stiffness > 0) || !std::isfinite(o.stiffness))
    throw InvalidInputError("periodic_global_parameterization: stiffness must be > 0, got " +
                            std::to_string(o.stiffness));
}

std::vector<FaceFrame> all_frames(const Mesh& mesh) {
  std::vector<FaceFrame> frames(mesh.num_faces());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.num_faces(), 2048),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t fi = r.begin(); fi != r.end(); ++fi) {
      const FaceIndex f(static_cast<Mesh::size_type>(fi));
      if (!mesh.is_removed(f)) frames[fi] = face_frame(mesh, f);
    }
  });
  return frames;
}

/// g = d / S^T per face (only where `mask` is set when given), written into `g`.
void face_gradients_into(const Mesh& mesh, const PgpOptions& o, const std::vector<FaceFrame>& frames,
                         const std::vector<char>* mask, std::vector<FaceGrad>& g) {
  auto dir = mesh.property_map<FaceIndex, Vector3>(o.direction_map);
  if (!dir.second)
    throw InvalidInputError("periodic_global_parameterization: face map '" + o.direction_map +
                            "' absent (interpolate a direction field first)");
  auto scale = mesh.property_map<VertexIndex, double>(o.scale_map);
  g.resize(mesh.num_faces());
  // Check the scale first (serially: the first bad vertex is reported).
  if (scale.second)
    for (VertexIndex v : mesh.vertices()) {
      const double sv = scale.first[v];
      if (!(sv > 0) || !std::isfinite(sv))
        throw InvalidInputError("periodic_global_parameterization: scale at vertex " +
                                std::to_string(v.idx()) + " is " + std::to_string(sv) +
                                " (must be > 0)");
    }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.num_faces(), 2048),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t fi = r.begin(); fi != r.end(); ++fi) {
      const FaceIndex f(static_cast<Mesh::size_type>(fi));
      if (mesh.is_removed(f) || (mask && !(*mask)[fi])) continue;
      const FaceFrame& fr = frames[fi];
      double s = 0;
      for (VertexIndex v : face_vertices(mesh, f)) s += scale.second ? scale.first[v] : 1.0;
      s /= 3;
      const Vector3 d = dir.first[f];
      const Vector3 ds = normalized_or(d - (d * fr.n) * fr.n, fr.e1);
      const Vector3 dt = CGAL::cross_product(fr.n, ds);
      g[fi] = {ds / s, dt / s};
    }
  });
}

std::vector<FaceGrad> face_gradients(const Mesh& mesh, const PgpOptions& o,
                                     std::vector<FaceFrame>* frames_out) {
  std::vector<FaceFrame> frames = all_frames(mesh);
  std::vector<FaceGrad> g;
  face_gradients_into(mesh, o, frames, nullptr, g);
  if (frames_out) *frames_out = std::move(frames);
  return g;
}

/// Alphas of equation (3) per halfedge (only edges where `edge_mask` is set
/// when given), written into `alpha`.
void halfedge_alphas_into(const Mesh& mesh, const PgpOptions& o, const std::vector<FaceGrad>& g,
                          const std::vector<FaceFrame>& frames, const std::vector<char>* edge_mask,
                          std::vector<std::array<double, 2>>& alpha) {
  const double step = 2 * M_PI / o.symmetry;
  alpha.resize(mesh.num_halfedges(), {0.0, 0.0});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.num_edges(), 2048),
                    [&](const tbb::blocked_range<std::size_t>& range) {
  for (std::size_t ei = range.begin(); ei != range.end(); ++ei) {
    const EdgeIndex e(static_cast<Mesh::size_type>(ei));
    if (mesh.is_removed(e) || (edge_mask && !(*edge_mask)[ei])) continue;
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
  });
}

std::vector<std::array<double, 2>> halfedge_alphas(const Mesh& mesh, const PgpOptions& o,
                                                   const std::vector<FaceGrad>& g,
                                                   const std::vector<FaceFrame>& frames) {
  std::vector<std::array<double, 2>> alpha;
  halfedge_alphas_into(mesh, o, g, frames, nullptr, alpha);
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

namespace {

// Connectivity and geometry of the mesh as the solver sees it, computed once
// (the mesh must not change between initialize() and update()).
struct PgpTopology {
  std::size_t nv = 0, nf = 0, ne = 0, nh = 0;
  std::vector<std::uint32_t> edges;        // live edge indices, in order
  std::vector<std::array<std::uint32_t, 2>> ends;  // (source, target) of halfedge(e, 0)
  std::vector<double> weight;              // A_T + A_T' per live edge (same order)
  std::vector<double> mass;                // per vertex: a third of its faces' area
  std::vector<int> component;              // per vertex: connected component, -1 = none
  int components = 0;
  std::vector<std::uint32_t> faces;        // live face indices
  std::vector<FaceFrame> frames;           // per face index

  bool matches(const Mesh& m) const {
    return nv == m.num_vertices() && nf == m.num_faces() && ne == m.num_edges() && nh == m.num_halfedges();
  }
};

PgpTopology make_topology(const Mesh& mesh) {
  PgpTopology t;
  t.nv = mesh.num_vertices();
  t.nf = mesh.num_faces();
  t.ne = mesh.num_edges();
  t.nh = mesh.num_halfedges();
  std::vector<double> area(t.nf, 0.0);
  for (FaceIndex f : mesh.faces()) {
    t.faces.push_back(static_cast<std::uint32_t>(f.idx()));
    area[f.idx()] = face_area(mesh, f);
  }
  t.frames = all_frames(mesh);
  t.mass.assign(t.nv, 0.0);
  for (FaceIndex f : mesh.faces())
    for (VertexIndex v : face_vertices(mesh, f)) t.mass[v.idx()] += area[f.idx()] / 3;
  for (EdgeIndex e : mesh.edges()) {
    const HalfedgeIndex h = mesh.halfedge(e, 0), o = mesh.opposite(h);
    double w = 0;
    if (!mesh.is_border(h)) w += area[mesh.face(h).idx()];
    if (!mesh.is_border(o)) w += area[mesh.face(o).idx()];
    t.edges.push_back(static_cast<std::uint32_t>(e.idx()));
    t.ends.push_back({static_cast<std::uint32_t>(mesh.source(h).idx()),
                      static_cast<std::uint32_t>(mesh.target(h).idx())});
    t.weight.push_back(w);
  }
  // Components by union-find over the edges (deterministic labels: order of
  // the lowest vertex index).
  std::vector<std::uint32_t> parent(t.nv);
  for (std::size_t i = 0; i < t.nv; ++i) parent[i] = static_cast<std::uint32_t>(i);
  auto find_root = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (const auto& ij : t.ends) {
    const std::uint32_t a = find_root(ij[0]), b = find_root(ij[1]);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  t.component.assign(t.nv, -1);
  std::vector<int> label(t.nv, -1);
  for (VertexIndex v : mesh.vertices()) {
    const std::uint32_t r = find_root(static_cast<std::uint32_t>(v.idx()));
    if (label[r] < 0) label[r] = t.components++;
    t.component[v.idx()] = label[r];
  }
  return t;
}

// Lower triangle of the Hermitian system over the free vertices, with the
// position of every edge's and vertex's entry so that refilling the values
// for new alphas costs one pass (no triplet sort).
struct PgpPattern {
  std::vector<int> var;              // per vertex: unknown index or -1
  int n = 0;
  SpMat A;                           // pattern (values overwritten per fill)
  std::vector<std::ptrdiff_t> diag;  // per unknown: position of (v,v)
  std::vector<std::ptrdiff_t> off;   // per live edge: position of its entry or -1
};

PgpPattern make_pattern(const PgpTopology& t, std::vector<int> var, int n) {
  PgpPattern p;
  p.var = std::move(var);
  p.n = n;
  std::vector<Eigen::Triplet<Cplx>> trip;
  trip.reserve(static_cast<std::size_t>(n) * 4);
  for (int v = 0; v < n; ++v) trip.emplace_back(v, v, Cplx(0, 0));
  for (const auto& ij : t.ends) {
    const int a = p.var[ij[0]], b = p.var[ij[1]];
    if (a >= 0 && b >= 0 && a != b) trip.emplace_back(std::max(a, b), std::min(a, b), Cplx(0, 0));
  }
  p.A.resize(n, n);
  p.A.setFromTriplets(trip.begin(), trip.end());
  p.A.makeCompressed();
  auto position = [&](int row, int col) -> std::ptrdiff_t {
    const int* begin = p.A.innerIndexPtr() + p.A.outerIndexPtr()[col];
    const int* end = p.A.innerIndexPtr() + p.A.outerIndexPtr()[col + 1];
    const int* it = std::lower_bound(begin, end, row);
    return it - p.A.innerIndexPtr();
  };
  p.diag.resize(static_cast<std::size_t>(n));
  for (int v = 0; v < n; ++v) p.diag[static_cast<std::size_t>(v)] = position(v, v);
  p.off.assign(t.ends.size(), -1);
  for (std::size_t k = 0; k < t.ends.size(); ++k) {
    const int a = p.var[t.ends[k][0]], b = p.var[t.ends[k][1]];
    if (a >= 0 && b >= 0 && a != b) p.off[k] = position(std::max(a, b), std::min(a, b));
  }
  return p;
}

}  // namespace

struct PeriodicGlobalParameterization::Impl {
  Mesh& mesh;
  PgpOptions opt;
  std::vector<Cplx> zs, zt;
  bool initialized = false;
  std::unique_ptr<PgpTopology> topo;
  std::unique_ptr<PgpPattern> pattern;
  Ldlt solver[2];
  bool analyzed = false;
  // Field-dependent values of the last solve; a local update recomputes them
  // only next to the free faces (the only faces whose direction or scale
  // may have changed).
  std::vector<FaceGrad> grad;
  std::vector<std::array<double, 2>> alpha;         // per halfedge
  std::vector<std::array<double, 2>> edge_energy;  // per live edge
  bool cache_valid = false;

  Impl(Mesh& m, PgpOptions o) : mesh(m), opt(std::move(o)) {}

  const PgpTopology& topology() {
    if (!topo || !topo->matches(mesh)) {
      topo = std::make_unique<PgpTopology>(make_topology(mesh));
      pattern.reset();
      analyzed = false;
      cache_valid = false;
    }
    return *topo;
  }
  /// Per live edge (order of topo->edges) the alpha pair along halfedge(e, 0).
  std::vector<std::array<double, 2>> edge_alphas(const std::vector<std::array<double, 2>>& alpha) const {
    std::vector<std::array<double, 2>> a(topo->edges.size());
    for (std::size_t k = 0; k < a.size(); ++k) a[k] = alpha[2 * std::size_t(topo->edges[k])];
    return a;
  }
  PgpResult solve(const std::vector<char>& free_vertex, const std::vector<char>* free_face, bool global);
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
  const std::vector<std::uint32_t>& faces = topology().faces;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, faces.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t q = r.begin(); q != r.end(); ++q) {
      const FaceIndex f(faces[q]);
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
  });
}

PgpResult PeriodicGlobalParameterization::Impl::solve(const std::vector<char>& free_vertex,
                                                      const std::vector<char>* free_face, bool global) {
  Timer timer;
  check_options(opt);
  require_triangle_mesh(mesh, "periodic_global_parameterization");
  const PgpTopology& t = topology();
  // Faces whose gradient may have changed (free faces) and edges whose alpha
  // may have (edges of free faces): everything when no valid cache.
  std::vector<char> face_mask, edge_mask;
  const bool partial = free_face && cache_valid;
  if (partial) {
    face_mask.assign(t.nf, 0);
    edge_mask.assign(t.ne, 0);
    for (std::uint32_t f : t.faces) {
      if (!(*free_face)[f]) continue;
      for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(FaceIndex(f)), mesh)) {
        edge_mask[mesh.edge(h).idx()] = 1;
        face_mask[f] = 1;
        // the opposite face's gradient enters the edge's alpha: unchanged
        // unless free, so it is read from the cache
      }
    }
  }
  face_gradients_into(mesh, opt, t.frames, partial ? &face_mask : nullptr, grad);
  halfedge_alphas_into(mesh, opt, grad, t.frames, partial ? &edge_mask : nullptr, alpha);
  const auto ealpha = edge_alphas(alpha);

  std::vector<int> var(t.nv, -1);
  int count = 0;
  for (VertexIndex v : mesh.vertices())
    if (free_vertex[v.idx()]) var[v.idx()] = count++;
  PgpResult res;
  res.free_vertices = static_cast<std::size_t>(count);
  const bool same_pattern = analyzed && pattern && pattern->var == var;
  res.reused_analysis = same_pattern;
  if (!pattern || pattern->var != var) pattern = std::make_unique<PgpPattern>(make_pattern(t, std::move(var), count));
  analyzed = analyzed && same_pattern;
  const PgpPattern& P = *pattern;
  const int n = P.n;

  // Complex Hermitian form of F_PGP: for the residual z_j - r z_i (r = exp(2 pi
  // i alpha_ij)), A(i,i) += w, A(j,j) += w, A(j,i) = -w r, A(i,j) = -w conj(r);
  // only the lower triangle is stored. `b` collects the locked neighbours' terms.
  auto fill = [&](int c, double shift, SpMat& A, Eigen::VectorXcd& b, Eigen::VectorXd& mass) {
    A = P.A;
    Cplx* val = A.valuePtr();
    std::fill(val, val + A.nonZeros(), Cplx(0, 0));
    b = Eigen::VectorXcd::Zero(n);
    mass.resize(n);
    const std::vector<Cplx>& z = c ? zt : zs;
    for (std::size_t v = 0; v < t.nv; ++v)
      if (P.var[v] >= 0) mass[P.var[v]] = t.mass[v];
    for (std::size_t k = 0; k < t.ends.size(); ++k) {
      const std::uint32_t i = t.ends[k][0], j = t.ends[k][1];
      const int vi = P.var[i], vj = P.var[j];
      if (vi < 0 && vj < 0) continue;
      const double w = t.weight[k];
      const Cplx r = std::polar(1.0, 2 * M_PI * ealpha[k][c]);
      if (vi >= 0) val[P.diag[vi]] += w;
      if (vj >= 0) val[P.diag[vj]] += w;
      if (vi >= 0 && vj >= 0) {
        if (P.off[k] >= 0) val[P.off[k]] += vj > vi ? -w * r : -w * std::conj(r);
      } else if (vj >= 0) {
        b[vj] += w * r * z[i];
      } else {
        b[vi] += w * std::conj(r) * z[j];
      }
    }
    for (int v = 0; v < n; ++v) val[P.diag[v]] += shift * mass[v];
  };

  // Reference scale of the shift: mean diagonal of F_PGP over mean mass.
  double trace_w = 0, trace_m = 0;
  for (std::size_t k = 0; k < t.ends.size(); ++k) trace_w += 2 * t.weight[k];
  for (double m : t.mass) trace_m += m;
  const double unit = trace_m > 0 ? trace_w / trace_m : 1.0;

  std::vector<Cplx>* zc[2] = {&zs, &zt};
  std::string failure[2];
  auto run = [&](int c) {
    if (n == 0) return;
    SpMat A;
    Eigen::VectorXcd b;
    Eigen::VectorXd mass;
    std::vector<Cplx>& z = *zc[c];
    Eigen::VectorXcd x(n);
    for (std::size_t v = 0; v < t.nv; ++v)
      if (P.var[v] >= 0) x[P.var[v]] = z[v];
    // Ginzburg-Landau relaxation with one factorisation of F_PGP + mu M:
    // min F + mu sum_i M_i |z_i - u_i|^2, u = z/|z| of the previous iterate
    // (from the tree-integrated start at initialisation, from the previous
    // solution in a local update, locked vertices entering through b). The
    // unit-modulus pull matters: F alone with one locked vertex has a
    // solution decaying away from it (median |z| ~ 3e-3 on fandisk), and
    // F's smallest eigenvector localises where the field's curl is low,
    // its tail not following the field (80% distorted faces on a torus).
    const double shift = opt.stiffness * unit;
    fill(c, shift, A, b, mass);
    if (!same_pattern || !analyzed) solver[c].analyzePattern(A);
    solver[c].factorize(A);
    if (solver[c].info() != Eigen::Success) {
      failure[c] = "factorisation failed";
      return;
    }
    const int iterations = global ? opt.init_iterations : opt.update_iterations;
    Eigen::VectorXcd rhs(n);
    for (int it = 0; it < iterations; ++it) {
      for (int v = 0; v < n; ++v) {
        const double a = std::abs(x[v]);
        rhs[v] = b[v] + shift * mass[v] * ((a > 1e-300 && std::isfinite(a)) ? x[v] / a : Cplx(1, 0));
      }
      x = solver[c].solve(rhs);
      if (solver[c].info() != Eigen::Success) {
        failure[c] = "solve failed";
        return;
      }
    }
    // Normalise to unit complex numbers.
    for (std::size_t v = 0; v < t.nv; ++v) {
      if (P.var[v] < 0) continue;
      const Cplx val = x[P.var[v]];
      const double a = std::abs(val);
      z[v] = (a > 1e-300 && std::isfinite(a)) ? val / a : Cplx(1, 0);
    }
  };
  if (global) {
    {
      // Integrate the alphas along a breadth-first spanning tree from each
      // component's lowest vertex: exact on the tree edges, the holonomy of
      // the field (what forces singularities) piles up where the tree's
      // branches meet; the relaxation below spreads it into vortices.
      std::vector<std::vector<std::pair<std::uint32_t, std::size_t>>> adj(t.nv);
      for (std::size_t k = 0; k < t.ends.size(); ++k) {
        adj[t.ends[k][0]].push_back({t.ends[k][1], k});
        adj[t.ends[k][1]].push_back({t.ends[k][0], k});
      }
      std::vector<char> seen(t.nv, 0);
      std::vector<double> ss(t.nv, 0.0), tt(t.nv, 0.0);
      std::vector<std::uint32_t> q;
      for (VertexIndex v0 : mesh.vertices()) {
        if (seen[v0.idx()]) continue;
        seen[v0.idx()] = 1;
        q.assign(1, v0.idx());
        for (std::size_t qi = 0; qi < q.size(); ++qi) {
          const std::uint32_t i = q[qi];
          for (auto [j, k] : adj[i]) {
            if (seen[j]) continue;
            seen[j] = 1;
            const double sg = t.ends[k][0] == i ? 1.0 : -1.0;
            ss[j] = ss[i] + sg * ealpha[k][0];
            tt[j] = tt[i] + sg * ealpha[k][1];
            q.push_back(j);
          }
        }
      }
      for (std::size_t v = 0; v < t.nv; ++v) {
        zs[v] = std::polar(1.0, 2 * M_PI * ss[v]);
        zt[v] = std::polar(1.0, 2 * M_PI * tt[v]);
      }
    }
  }
  tbb::parallel_invoke([&] { run(0); }, [&] { run(1); });
  for (int c = 0; c < 2; ++c)
    if (!failure[c].empty())
      throw SolverError(std::string("periodic_global_parameterization: ") + (c ? "t" : "s") +
                        " system " + failure[c] + " (" + std::to_string(n) + " free vertices)");
  analyzed = n > 0;

  if (global) {
    // The eigenvector is defined up to a global phase per component: rotate
    // each so that its reference vertex (locked_vertex for its component, the
    // lowest index otherwise) has s = t = 0.
    std::vector<Cplx> ref_s(static_cast<std::size_t>(t.components), Cplx(0, 0)), ref_t = ref_s;
    std::vector<char> has(static_cast<std::size_t>(t.components), 0);
    auto take = [&](std::size_t v) {
      const int c = t.component[v];
      if (c < 0 || has[c]) return;
      has[c] = 1;
      ref_s[c] = std::conj(zs[v]);
      ref_t[c] = std::conj(zt[v]);
    };
    take(opt.locked_vertex);
    for (VertexIndex v : mesh.vertices()) take(v.idx());
    for (std::size_t v = 0; v < t.nv; ++v) {
      const int c = t.component[v];
      if (c < 0) continue;
      zs[v] *= ref_s[c];
      zt[v] *= ref_t[c];
    }
    zs[opt.locked_vertex] = Cplx(1, 0);
    zt[opt.locked_vertex] = Cplx(1, 0);
  }

  // Energies at the (normalised) solution: per edge (only edges of free
  // faces change in an update), then a serial sum (deterministic).
  edge_energy.resize(t.ends.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, t.ends.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      if (partial && !edge_mask[t.edges[k]]) continue;
      const std::uint32_t i = t.ends[k][0], j = t.ends[k][1];
      const double w = t.weight[k];
      edge_energy[k] = {w * std::norm(zs[j] - std::polar(1.0, 2 * M_PI * ealpha[k][0]) * zs[i]),
                        w * std::norm(zt[j] - std::polar(1.0, 2 * M_PI * ealpha[k][1]) * zt[i])};
    }
  });
  for (const auto& en : edge_energy) {
    res.energy_s += en[0];
    res.energy_t += en[1];
  }
  cache_valid = true;

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
  // Every vertex with an edge is free; the phase is fixed afterwards.
  const PgpTopology& t = impl_->topology();
  std::vector<char> free_vertex(nv, 0);
  for (const auto& ij : t.ends) free_vertex[ij[0]] = free_vertex[ij[1]] = 1;
  PgpResult r = impl_->solve(free_vertex, nullptr, true);
  impl_->initialized = true;
  return r;
}

PgpResult PeriodicGlobalParameterization::update(const EffectArea& area) {
  if (!impl_->initialized)
    throw InvalidInputError("PeriodicGlobalParameterization::update called before initialize()");
  if (area.vertex_free.size() != impl_->mesh.num_vertices() ||
      area.face_free.size() != impl_->mesh.num_faces())
    throw InvalidInputError("PeriodicGlobalParameterization::update: effect area does not match the mesh");
  return impl_->solve(area.vertex_free, &area.face_free, false);
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
  impl_->cache_valid = false;
}

void PeriodicGlobalParameterization::write_corners() {
  if (!impl_->initialized)
    throw InvalidInputError("PeriodicGlobalParameterization::write_corners called before initialize()/set_state()");
  check_options(impl_->opt);
  require_triangle_mesh(impl_->mesh, "periodic_global_parameterization");
  Impl& im = *impl_;
  const PgpTopology& t = im.topology();
  face_gradients_into(im.mesh, im.opt, t.frames, nullptr, im.grad);
  halfedge_alphas_into(im.mesh, im.opt, im.grad, t.frames, nullptr, im.alpha);
  im.edge_energy.clear();
  im.cache_valid = false;  // energies not computed
  im.write_corners(im.alpha, nullptr);
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
