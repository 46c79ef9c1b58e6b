// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/pgp_curl_correction.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "geometry/direction_field_singularities.h"
#include "geometry/errors.h"
#include "geometry/properties.h"
#include "geometry/mesh_util.h"

namespace surftex {
namespace {

using SpMat = Eigen::SparseMatrix<double>;

void check(const PgpCurlCorrectionOptions& o) {
  if (o.symmetry != 1 && o.symmetry != 2 && o.symmetry != 4)
    throw InvalidInputError("pgp_curl_correction: symmetry must be 1, 2 or 4, got " +
                            std::to_string(o.symmetry));
  if (!(o.stiffness > 0) || !std::isfinite(o.stiffness))
    throw InvalidInputError("pgp_curl_correction: stiffness must be > 0, got " + std::to_string(o.stiffness));
  if (!(o.max_factor >= 1) || !std::isfinite(o.max_factor))
    throw InvalidInputError("pgp_curl_correction: max_factor must be >= 1, got " +
                            std::to_string(o.max_factor));
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
  // Geometry, computed with the factorisation (the mesh must not change).
  std::size_t nv = 0, nf = 0;
  bool ready = false;
  std::vector<FaceFrame> frame;                      // per face
  std::vector<double> area;                          // per face
  std::vector<double> mass;                          // per vertex: a third of its faces' area
  std::vector<std::array<std::uint32_t, 3>> corner;  // per face: targets of h, next(h), next(next(h))
  std::vector<double> edge_angle;  // per halfedge: angle of target - source in face(h)'s frame
  Eigen::SimplicialLLT<SpMat> solver;

  void prepare(const Mesh& mesh);
};

void PgpCurlCorrector::Impl::prepare(const Mesh& mesh) {
  nv = mesh.num_vertices();
  nf = mesh.num_faces();
  frame.assign(nf, FaceFrame{});
  area.assign(nf, 0.0);
  corner.assign(nf, {0, 0, 0});
  edge_angle.assign(mesh.num_halfedges(), 0.0);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, nf, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t fi = r.begin(); fi != r.end(); ++fi) {
          const FaceIndex f(static_cast<Mesh::size_type>(fi));
          if (mesh.is_removed(f)) continue;
          frame[fi] = face_frame(mesh, f);
          area[fi] = face_area(mesh, f);
          HalfedgeIndex h = mesh.halfedge(f);
          for (int c = 0; c < 3; ++c, h = mesh.next(h)) {
            corner[fi][c] = static_cast<std::uint32_t>(mesh.target(h).idx());
            edge_angle[h.idx()] = frame[fi].angle_of(mesh.point(mesh.target(h)) - mesh.point(mesh.source(h)));
          }
        }
      });
  mass.assign(nv, 0.0);
  double total_area = 0;
  for (FaceIndex f : mesh.faces()) {
    for (std::uint32_t v : corner[f.idx()]) mass[v] += area[f.idx()] / 3;
    total_area += area[f.idx()];
  }
  if (!(total_area > 0))
    throw InvalidInputError("pgp_curl_correction: the mesh has no face of positive area");
  // Screened cotangent Laplacian L + mu M (sum_T A_T |grad phi|^2 = phi' L phi).
  const double mu = opt.stiffness / total_area;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(nv + 2 * mesh.num_edges());
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
  solver.compute(A);
  if (solver.info() != Eigen::Success)
    throw SolverError("pgp_curl_correction: factorisation of the screened Laplacian failed (" +
                      std::to_string(nv) + " vertices)");
  ready = true;
}

PgpCurlCorrector::PgpCurlCorrector(PgpCurlCorrectionOptions options) : impl_(std::make_unique<Impl>()) {
  check(options);
  impl_->opt = std::move(options);
}

PgpCurlCorrector::~PgpCurlCorrector() = default;

PgpCurlCorrection PgpCurlCorrector::compute(const Mesh& mesh) {
  Impl& im = *impl_;
  const PgpCurlCorrectionOptions& o = im.opt;
  auto dir = find(mesh, o.direction_map);
  if (!dir.second)
    throw InvalidInputError("pgp_curl_correction: face map '" + std::string(o.direction_map.name) +
                            "' absent (interpolate a direction field first)");
  require_triangle_mesh(mesh, "pgp_curl_correction");
  const std::size_t nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (!im.ready || im.nv != nv || im.nf != nf || im.edge_angle.size() != mesh.num_halfedges())
    im.prepare(mesh);
  const double step = 2 * M_PI / o.symmetry;

  // Faces with a vertex of nonzero field index: no target there (the exact
  // factor would be a cone r^k; the PGP's vortex handles the singularity).
  FieldIndexOptions fo;
  fo.symmetry = o.symmetry;
  fo.direction_map = o.direction_map;
  const std::vector<int> index = direction_field_indices(mesh, fo);
  // log S per vertex (absent map: S = 1); checked by the PGP, checked again here.
  auto scale = find(mesh, o.scale_map);
  std::vector<double> log_s(nv, 0.0);
  if (scale.second)
    for (VertexIndex v : mesh.vertices()) {
      const double sv = scale.first[v];
      if (!(sv > 0) || !std::isfinite(sv))
        throw InvalidInputError("pgp_curl_correction: scale at vertex " + std::to_string(v.idx()) + " is " +
                                std::to_string(sv) + " (must be > 0)");
      log_s[v.idx()] = std::log(sv);
    }
  // Per face: angle of the projected d_s in the face frame.
  std::vector<double> angle(nf, 0.0);
  std::vector<std::array<double, 3>> rhs(nf, {0.0, 0.0, 0.0});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nf, 2048),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t fi = r.begin(); fi != r.end(); ++fi) {
                        const FaceIndex f(static_cast<Mesh::size_type>(fi));
                        if (mesh.is_removed(f)) continue;
                        const Vector3 d = dir.first[f];
                        const FaceFrame& fr = im.frame[fi];
                        angle[fi] = fr.angle_of(normalized_or(d - (d * fr.n) * fr.n, fr.e1));
                      }
                    });
  // q_T = -curl(d_t) d_s + curl(d_s) d_t, and its right-hand side
  // contribution q_T . (n x e_c) / 2 per corner c (e_c the opposite edge, ccw).
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, nf, 2048), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t fi = r.begin(); fi != r.end(); ++fi) {
          const FaceIndex f(static_cast<Mesh::size_type>(fi));
          if (mesh.is_removed(f) || !(im.area[fi] > 0)) continue;
          const auto& cv = im.corner[fi];
          const FaceFrame& fT = im.frame[fi];
          const double A = im.area[fi];
          // Opposite edges (ccw) of the corners: grad of the hat function c is n x e_c / 2A.
          std::array<Vector3, 3> e;
          for (int c = 0; c < 3; ++c)
            e[c] = mesh.point(VertexIndex(cv[(c + 2) % 3])) - mesh.point(VertexIndex(cv[(c + 1) % 3]));
          Vector3 q(0, 0, 0);
          for (int c = 0; c < 3; ++c) q = q + (log_s[cv[c]] / (2 * A)) * CGAL::cross_product(fT.n, e[c]);
          const bool singular = index[cv[0]] != 0 || index[cv[1]] != 0 || index[cv[2]] != 0;
          for (int c = 0; c < 3 && singular; ++c) rhs[fi][c] = 0.5 * (q * CGAL::cross_product(fT.n, e[c]));
          if (singular) continue;
          const Vector3 ds = fT.direction(angle[fi]), dt = CGAL::cross_product(fT.n, ds);
          double circ_s = 0, circ_t = 0;
          HalfedgeIndex h = mesh.halfedge(f);
          for (int c = 0; c < 3; ++c, h = mesh.next(h)) {
            const Vector3 ev = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
            const HalfedgeIndex op = mesh.opposite(h);
            Vector3 us = ds, ut = dt;
            if (!mesh.is_border(op)) {
              // The matching of the PGP's alphas, with the edge angles cached
              // (ev in U's frame = the opposite halfedge's angle + pi).
              const std::size_t U = mesh.face(op).idx();
              const FaceFrame& fU = im.frame[U];
              const double transported = angle[fi] - im.edge_angle[h.idx()] + im.edge_angle[op.idx()] + M_PI;
              us = fU.direction(angle[U] + std::round((transported - angle[U]) / step) * step);
              ut = CGAL::cross_product(fU.n, us);
            }
            circ_s += 0.5 * (ev * (ds + us));
            circ_t += 0.5 * (ev * (dt + ut));
          }
          q = q + (-circ_t / A) * ds + (circ_s / A) * dt;
          for (int c = 0; c < 3; ++c) rhs[fi][c] = 0.5 * (q * CGAL::cross_product(fT.n, e[c]));
        }
      });
  Eigen::VectorXd b = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(nv));
  for (FaceIndex f : mesh.faces())  // serial: the same sums whatever the threads
    for (int c = 0; c < 3; ++c) b[im.corner[f.idx()][c]] += rhs[f.idx()][c];
  for (std::size_t v = 0; v < nv; ++v)
    if (!(im.mass[v] > 0)) b[static_cast<Eigen::Index>(v)] = 0;
  const Eigen::VectorXd phi = im.solver.solve(b);
  if (im.solver.info() != Eigen::Success || !phi.allFinite())
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
    const auto& cv = im.corner[f.idx()];
    const double k = std::exp((out.log_factor[cv[0]] + out.log_factor[cv[1]] + out.log_factor[cv[2]]) / 3);
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
