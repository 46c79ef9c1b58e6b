// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/pgp_curl_correction.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh_util.h"

namespace surftex {
namespace {

using SpMat = Eigen::SparseMatrix<double>;

void check(const PgpCurlCorrectionOptions& o) {
  if (o.symmetry != 1 && o.symmetry != 2 && o.symmetry != 4)
    throw InvalidInputError("pgp_curl_correction: symmetry must be 1, 2 or 4, got " + std::to_string(o.symmetry));
  if (!(o.stiffness > 0) || !std::isfinite(o.stiffness))
    throw InvalidInputError("pgp_curl_correction: stiffness must be > 0, got " + std::to_string(o.stiffness));
  if (!(o.max_factor >= 1) || !std::isfinite(o.max_factor))
    throw InvalidInputError("pgp_curl_correction: max_factor must be >= 1, got " + std::to_string(o.max_factor));
}

/// Quarter-turn-free matching of the PGP (halfedge_alphas): the representative
/// of face U's cross (angle tU in U's frame, step 2 pi / N) nearest to face T's
/// (angle tT in T's frame) after transport across the edge vector ev, as an
/// angle in U's frame. Evaluating e . v in 3D with v in U's plane is the same
/// as transporting v into T's plane first (the hinge rotation about e keeps e . v).
double matched_angle(const FaceFrame& fT, double tT, const FaceFrame& fU, double tU, const Vector3& ev,
                     double step) {
  const double transported = tT - fT.angle_of(ev) + fU.angle_of(ev);
  return tU + std::round((transported - tU) / step) * step;
}

}  // namespace

struct PgpCurlCorrector::Impl {
  PgpCurlCorrectionOptions opt;
  Eigen::SimplicialLLT<SpMat> solver;
  std::size_t nv = 0, nf = 0;
  bool factored = false;
};

PgpCurlCorrector::PgpCurlCorrector(PgpCurlCorrectionOptions options) : impl_(std::make_unique<Impl>()) {
  check(options);
  impl_->opt = std::move(options);
}

PgpCurlCorrector::~PgpCurlCorrector() = default;

PgpCurlCorrection PgpCurlCorrector::compute(const Mesh& mesh) {
  const PgpCurlCorrectionOptions& o = impl_->opt;
  auto dir = mesh.property_map<FaceIndex, Vector3>(o.direction_map);
  if (!dir.second)
    throw InvalidInputError("pgp_curl_correction: face map '" + o.direction_map +
                            "' absent (interpolate a direction field first)");
  require_triangle_mesh(mesh, "pgp_curl_correction");
  const std::size_t nv = mesh.num_vertices(), nf = mesh.num_faces();
  const double step = 2 * M_PI / o.symmetry;

  // Per face: frame, area, unit d_s and its angle.
  std::vector<FaceFrame> frame(nf);
  std::vector<double> area(nf, 0.0), angle(nf, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t fi = r.begin(); fi != r.end(); ++fi) {
      const FaceIndex f(static_cast<Mesh::size_type>(fi));
      if (mesh.is_removed(f)) continue;
      frame[fi] = face_frame(mesh, f);
      area[fi] = face_area(mesh, f);
      const Vector3 d = dir.first[f];
      angle[fi] = frame[fi].angle_of(normalized_or(d - (d * frame[fi].n) * frame[fi].n, frame[fi].e1));
    }
  });
  // q_T = -curl(d_t) d_s + curl(d_s) d_t, and its right-hand side
  // contribution q_T . (n x e_i) / 2 per corner (e_i the opposite edge, ccw).
  std::vector<std::array<double, 3>> rhs(nf, {0.0, 0.0, 0.0});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t fi = r.begin(); fi != r.end(); ++fi) {
      const FaceIndex f(static_cast<Mesh::size_type>(fi));
      if (mesh.is_removed(f) || !(area[fi] > 0)) continue;
      const FaceFrame& fT = frame[fi];
      const Vector3 ds = fT.direction(angle[fi]), dt = CGAL::cross_product(fT.n, ds);
      double circ_s = 0, circ_t = 0;
      const HalfedgeIndex h0 = mesh.halfedge(f);
      const HalfedgeIndex hs[3] = {h0, mesh.next(h0), mesh.next(mesh.next(h0))};
      for (HalfedgeIndex h : hs) {
        const Vector3 ev = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
        const HalfedgeIndex op = mesh.opposite(h);
        Vector3 us = ds, ut = dt;
        if (!mesh.is_border(op)) {
          const std::size_t U = mesh.face(op).idx();
          const FaceFrame& fU = frame[U];
          us = fU.direction(matched_angle(fT, angle[fi], fU, angle[U], ev, step));
          ut = CGAL::cross_product(fU.n, us);
        }
        circ_s += 0.5 * (ev * (ds + us));
        circ_t += 0.5 * (ev * (dt + ut));
      }
      const Vector3 q = (-circ_t / area[fi]) * ds + (circ_s / area[fi]) * dt;
      for (int c = 0; c < 3; ++c) {
        // Corner c = target(hs[c]); its opposite edge, ccw: hs[(c + 2) % 3]'s
        // target... i.e. from target(hs[c+1]) to target(hs[c+2]).
        const Vector3 e = mesh.point(mesh.target(hs[(c + 2) % 3])) - mesh.point(mesh.target(hs[(c + 1) % 3]));
        rhs[fi][c] = 0.5 * (q * CGAL::cross_product(fT.n, e));
      }
    }
  });
  Eigen::VectorXd b = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(nv));
  std::vector<double> mass(nv, 0.0);
  double total_area = 0;
  for (FaceIndex f : mesh.faces()) {
    const HalfedgeIndex h0 = mesh.halfedge(f);
    const HalfedgeIndex hs[3] = {h0, mesh.next(h0), mesh.next(mesh.next(h0))};
    for (int c = 0; c < 3; ++c) {
      b[mesh.target(hs[c]).idx()] += rhs[f.idx()][c];
      mass[mesh.target(hs[c]).idx()] += area[f.idx()] / 3;
    }
    total_area += area[f.idx()];
  }
  if (!(total_area > 0))
    throw InvalidInputError("pgp_curl_correction: the mesh has no face of positive area");

  if (!impl_->factored || impl_->nv != nv || impl_->nf != nf) {
    // Screened cotangent Laplacian L + mu M (sum_T A_T |grad phi|^2 = phi' L phi).
    const double mu = o.stiffness / total_area;
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(nv + 4 * mesh.num_edges());
    std::vector<double> diag(nv, 0.0);
    for (EdgeIndex e : mesh.edges()) {
      const HalfedgeIndex h = mesh.halfedge(e, 0), op = mesh.opposite(h);
      const double w = 0.5 * (cotan_opposite(mesh, h) + cotan_opposite(mesh, op));
      const int i = static_cast<int>(mesh.source(h).idx()), j = static_cast<int>(mesh.target(h).idx());
      trip.emplace_back(i, j, -w);
      trip.emplace_back(j, i, -w);
      diag[i] += w;
      diag[j] += w;
    }
    for (std::size_t v = 0; v < nv; ++v) {
      // Isolated (or removed) vertices: identity rows, phi = 0.
      const double d = mass[v] > 0 ? diag[v] + mu * mass[v] : 1.0;
      trip.emplace_back(static_cast<int>(v), static_cast<int>(v), d);
    }
    SpMat A(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(nv));
    A.setFromTriplets(trip.begin(), trip.end());
    impl_->solver.compute(A);
    if (impl_->solver.info() != Eigen::Success)
      throw SolverError("pgp_curl_correction: factorisation of the screened Laplacian failed (" +
                        std::to_string(nv) + " vertices)");
    impl_->nv = nv;
    impl_->nf = nf;
    impl_->factored = true;
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (!(mass[v] > 0)) b[static_cast<Eigen::Index>(v)] = 0;
  const Eigen::VectorXd phi = impl_->solver.solve(b);
  if (impl_->solver.info() != Eigen::Success || !phi.allFinite())
    throw SolverError("pgp_curl_correction: solve failed (" + std::to_string(nv) + " vertices)");

  PgpCurlCorrection out;
  const double cap = std::log(o.max_factor);
  out.log_factor.assign(nv, 0.0);
  for (std::size_t v = 0; v < nv; ++v) {
    const double x = phi[static_cast<Eigen::Index>(v)];
    out.log_factor[v] = std::clamp(x, -cap, cap);
    out.clamped_vertices += std::abs(x) > cap;
  }
  out.face_factor.assign(nf, 1.0);
  out.min_factor = std::numeric_limits<double>::infinity();
  out.max_factor = 0;
  for (FaceIndex f : mesh.faces()) {
    double s = 0;
    for (VertexIndex v : face_vertices(mesh, f)) s += out.log_factor[v.idx()];
    const double k = std::exp(s / 3);
    out.face_factor[f.idx()] = k;
    out.min_factor = std::min(out.min_factor, k);
    out.max_factor = std::max(out.max_factor, k);
  }
  if (out.max_factor == 0) out.min_factor = out.max_factor = 1;
  return out;
}

PgpCurlCorrection pgp_curl_correction(const Mesh& mesh, const PgpCurlCorrectionOptions& options) {
  PgpCurlCorrector c(options);
  return c.compute(mesh);
}

std::vector<std::array<double, 2>> pgp_face_circulation(const Mesh& mesh, const PgpOptions& options) {
  const auto g = pgp_face_gradients(mesh, options);
  const std::size_t nf = mesh.num_faces();
  const double step = 2 * M_PI / options.symmetry;
  std::vector<FaceFrame> frame(nf);
  for (FaceIndex f : mesh.faces()) frame[f.idx()] = face_frame(mesh, f);
  auto vec = [](const std::array<double, 3>& a) { return Vector3(a[0], a[1], a[2]); };
  std::vector<std::array<double, 2>> out(nf, {0.0, 0.0});
  for (FaceIndex f : mesh.faces()) {
    const std::size_t T = f.idx();
    const FaceFrame& fT = frame[T];
    const Vector3 gs = vec(g[T][0]), gt = vec(g[T][1]);
    const double tT = fT.angle_of(gs);
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const Vector3 ev = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
      const HalfedgeIndex op = mesh.opposite(h);
      Vector3 us = gs, ut = gt;
      if (!mesh.is_border(op)) {
        const std::size_t U = mesh.face(op).idx();
        const FaceFrame& fU = frame[U];
        const Vector3 gu = vec(g[U][0]);
        us = norm(gu) * fU.direction(matched_angle(fT, tT, fU, fU.angle_of(gu), ev, step));
        ut = CGAL::cross_product(fU.n, us);
      }
      out[T][0] += 0.5 * (ev * (gs + us));
      out[T][1] += 0.5 * (ev * (gt + ut));
    }
  }
  return out;
}

}  // namespace surftex
