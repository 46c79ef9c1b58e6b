// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/direction_field.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <complex>
#include <deque>
#include <functional>
#include <queue>
#include <string>

#include "geometry/effect_area.h"
#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

void check_symmetry(int n, const char* who) {
  if (n != 1 && n != 2 && n != 4)
    throw InvalidInputError(std::string(who) + ": symmetry must be 1, 2 or 4, got " +
                            std::to_string(n));
}

/// Closest representative of `theta` (mod 2 pi / N) to `target`.
double closest_representative(double theta, double target, int n) {
  const double step = 2 * M_PI / n;
  const double k = std::round((target - theta) / step);
  return theta + k * step;
}


using Cplx = std::complex<double>;

// Solves the Hermitian positive definite system A x = rhs (SimplicialLDLT, info()
// checked after the factorisation and the solve); `step` and `size` name the
// system in the SolverError.
Eigen::VectorXcd solve_hermitian(const Eigen::SparseMatrix<Cplx>& A, const Eigen::VectorXcd& rhs,
                                 const std::string& step, const std::string& size) {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<Cplx>> solver(A);
  if (solver.info() != Eigen::Success)
    throw SolverError("interpolate_direction_field: " + step + "factorisation failed (" + size + ")");
  Eigen::VectorXcd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success) throw SolverError("interpolate_direction_field: " + step + "solve failed");
  return x;
}
using FaceDirs = std::vector<Vector3>;  // one direction per face index

/// What interpolate_direction_field knows about every face, stage to stage.
struct FieldState {
  FieldState(const Mesh& m, const DirectionFieldOptions& o) : mesh(m), opt(o), N(o.symmetry), nf(m.num_faces()) {}
  const Mesh& mesh;
  const DirectionFieldOptions& opt;
  const int N;           // symmetry
  const std::size_t nf;  // faces (indices)
  std::vector<char> relevant;     // free faces and their edge neighbours (nothing else is read)
  std::vector<FaceFrame> frames;  // of the relevant faces
  std::vector<char> locked;       // constrained or outside the area
  std::vector<double> theta;      // locked angle in the face frame
  std::vector<int> var;           // unknown per solved face, -1 otherwise
  std::vector<char> reach;        // locked, or free and reached from a locked face
  std::vector<FaceIndex> order;   // BFS order of the free faces from the locked ones
  int n_var = 0;
  std::vector<double> final_theta;  // per face: the field's angle

  bool is_free(FaceIndex f) const { return !opt.area || opt.area->face_free[f.idx()]; }
  /// Angle of the halfedge vector of h in the frame of face x.
  double edge_angle(HalfedgeIndex h, std::size_t x) const {
    const Vector3 e = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
    return frames[x].angle_of(e);
  }
};

void check_field_inputs(const Mesh& mesh, const DirectionFieldOptions& opt) {
  check_symmetry(opt.symmetry, "interpolate_direction_field");
  if (!(opt.smoothing >= 0) || !std::isfinite(opt.smoothing))
    throw InvalidInputError("interpolate_direction_field: smoothing must be >= 0, got " +
                            std::to_string(opt.smoothing));
  require_triangle_mesh(mesh, "interpolate_direction_field");
  const std::size_t nf = mesh.num_faces();
  if (opt.area && opt.area->face_free.size() != nf)
    throw InvalidInputError("interpolate_direction_field: effect area has " +
                            std::to_string(opt.area->face_free.size()) + " faces, mesh has " +
                            std::to_string(nf));
}

/// Faces that take part: the free ones and their edge neighbours (locked
/// boundary), and their frames. Outside that band nothing is read, so a local
/// edit costs in proportion to its area (frames, breadth-first walks).
void frame_relevant_faces(FieldState& s) {
  const Mesh& mesh = s.mesh;
  s.relevant.assign(s.nf, s.opt.area ? 0 : 1);
  if (s.opt.area)
    for (FaceIndex f : mesh.faces()) {
      if (!s.is_free(f)) continue;
      s.relevant[f.idx()] = 1;
      for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh))
        if (!mesh.is_border(mesh.opposite(h))) s.relevant[mesh.face(mesh.opposite(h)).idx()] = 1;
    }
  s.frames.resize(s.nf);
  for (FaceIndex f : mesh.faces())
    if (s.relevant[f.idx()]) s.frames[f.idx()] = face_frame(mesh, f);
}

/// Locks the constrained faces (their direction projected on the face, as an
/// angle in its frame) and the faces outside the area (their stored direction).
void lock_faces(FieldState& s, const std::vector<DirectionConstraint>& constraints, const FaceDirs& dir,
                DirectionFieldResult& res) {
  const Mesh& mesh = s.mesh;
  const std::size_t nf = s.nf;
  s.locked.assign(nf, 0);
  s.theta.assign(nf, 0.0);
  for (const DirectionConstraint& c : constraints) {
    if (c.face >= nf || mesh.is_removed(FaceIndex(c.face)))
      throw InvalidInputError("interpolate_direction_field: constraint face " +
                              std::to_string(c.face) + " out of range (" + std::to_string(nf) +
                              " faces)");
    const FaceIndex f(c.face);
    if (!s.is_free(f)) continue;  // outside the effect area: keeps its value
    const Vector3 d(c.direction[0], c.direction[1], c.direction[2]);
    const FaceFrame& fr = s.frames[c.face];
    const Vector3 t = d - (d * fr.n) * fr.n;
    if (!(norm(t) > 1e-9 * std::max(norm(d), 1e-300)) || !std::isfinite(norm(d)))
      throw InvalidInputError("interpolate_direction_field: constraint direction on face " +
                              std::to_string(c.face) + " is zero or normal to the face");
    if (!s.locked[c.face]) ++res.constrained_faces;
    s.locked[c.face] = 1;
    s.theta[c.face] = fr.angle_of(t);
  }
  for (FaceIndex f : mesh.faces()) {
    if (s.is_free(f)) continue;
    s.locked[f.idx()] = 1;
    if (!s.relevant[f.idx()]) continue;  // never read
    const Vector3 d = dir[f.idx()];
    s.theta[f.idx()] = norm(d) > 0 ? s.frames[f.idx()].angle_of(d) : 0.0;
  }
}

/// Free faces reachable from a locked face through free faces get solved,
/// numbered in breadth-first order from the locked ones; the others
/// (components without any constraint) get e1. Throws when nothing is locked.
void number_reached_faces(FieldState& s, DirectionFieldResult& res) {
  const Mesh& mesh = s.mesh;
  s.var.assign(s.nf, -1);
  s.reach.assign(s.nf, 0);
  std::deque<FaceIndex> queue;
  for (FaceIndex f : mesh.faces())
    if (s.locked[f.idx()]) {
      s.reach[f.idx()] = 1;
      if (s.relevant[f.idx()]) queue.push_back(f);  // the others have no free neighbour
    }
  while (!queue.empty()) {
    const FaceIndex f = queue.front();
    queue.pop_front();
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const HalfedgeIndex o = mesh.opposite(h);
      if (mesh.is_border(o)) continue;
      const FaceIndex g = mesh.face(o);
      if (s.reach[g.idx()]) continue;
      s.reach[g.idx()] = 1;
      s.order.push_back(g);
      queue.push_back(g);
    }
  }
  for (FaceIndex g : s.order) s.var[g.idx()] = s.n_var++;
  for (FaceIndex f : mesh.faces())
    if (!s.locked[f.idx()] && !s.reach[f.idx()]) ++res.unconstrained_faces;
  if (std::none_of(s.locked.begin(), s.locked.end(), [](char c) { return c != 0; }) &&
      mesh.number_of_faces() > 0)
    throw InvalidInputError("interpolate_direction_field: no orientation constraint given");
}

/// The smoothness energy E over the interior edges as a complex Hermitian
/// form (u_f as one complex number; half the unknowns and a quarter of the
/// entries of the equivalent real 2x2-block system) on the unknowns `v`
/// (face -> index, or -1): for the residual u_g - r u_f, r = exp(i N (a_g -
/// a_f)): A(f,f) += w, A(g,g) += w, A(g,f) = -w r, A(f,g) = -w conj(r). The
/// strictly lower off-diagonal entries go to `trip`, the terms of neighbours
/// that are not unknowns (angle from `known`) to `rhs`; the diagonal is
/// returned, one sum per unknown, for the caller to complete.
std::vector<double> assemble_energy(const FieldState& s, const std::vector<int>& v,
                                    const std::vector<double>& known, int n,
                                    std::vector<Eigen::Triplet<Cplx>>& trip, Eigen::VectorXcd& rhs) {
  const Mesh& mesh = s.mesh;
  const int N = s.N;
  std::vector<double> diag(static_cast<std::size_t>(n), 0.0);
  trip.reserve(static_cast<std::size_t>(n) * 4);
  rhs = Eigen::VectorXcd::Zero(n);
  for (EdgeIndex e : mesh.edges()) {
    if (mesh.is_border(e)) continue;
    const HalfedgeIndex h = mesh.halfedge(e, 0);
    const HalfedgeIndex o = mesh.opposite(h);
    const std::size_t f = mesh.face(h).idx(), g = mesh.face(o).idx();
    const int vf = v[f], vg = v[g];
    if (vf < 0 && vg < 0) continue;
    const double area = face_area(mesh, FaceIndex(f)) + face_area(mesh, FaceIndex(g));
    const double len2 = (mesh.point(mesh.target(h)) - mesh.point(mesh.source(h))).squared_length();
    const double w = area > 0 ? std::min(3 * len2 / area, 1e3) : 1e3;
    const Cplx r = std::polar(1.0, N * (s.edge_angle(h, g) - s.edge_angle(h, f)));
    if (vf >= 0) diag[vf] += w;
    if (vg >= 0) diag[vg] += w;
    if (vf >= 0 && vg >= 0) {
      if (vg > vf)
        trip.emplace_back(vg, vf, -w * r);
      else
        trip.emplace_back(vf, vg, -w * std::conj(r));
    } else if (vg >= 0) {  // f known: rhs_g += w r u_f
      rhs[vg] += w * r * std::polar(1.0, N * known[f]);
    } else {  // g known: rhs_f += w conj(r) u_g
      rhs[vf] += w * std::conj(r) * std::polar(1.0, N * known[g]);
    }
  }
  return diag;
}

/// The interpolation: minimises E over the reached free faces with the
/// locked faces' angles fixed (SimplicialLDLT), u_f = exp(i N theta_f); then
/// the field's angle per face, solved or locked.
void solve_free_angles(FieldState& s) {
  const Mesh& mesh = s.mesh;
  const int N = s.N, n_var = s.n_var;
  std::vector<double> solved(s.nf, 0.0);
  if (n_var > 0) {
    std::vector<Eigen::Triplet<Cplx>> trip;
    Eigen::VectorXcd rhs;
    const std::vector<double> diag = assemble_energy(s, s.var, s.theta, n_var, trip, rhs);
    for (int v = 0; v < n_var; ++v) trip.emplace_back(v, v, Cplx(diag[static_cast<std::size_t>(v)], 0));
    Eigen::SparseMatrix<Cplx> A(n_var, n_var);
    A.setFromTriplets(trip.begin(), trip.end());
    const Eigen::VectorXcd x = solve_hermitian(A, rhs, "", std::to_string(n_var) + " free faces");
    for (FaceIndex g : s.order) {
      const int v = s.var[g.idx()];
      const double a = std::atan2(x[v].imag(), x[v].real());  // atan2(0,0) = 0: never NaN
      solved[g.idx()] = (std::isfinite(a) ? a : 0.0) / N;
    }
  }
  s.final_theta.assign(s.nf, 0.0);
  for (FaceIndex g : s.order) s.final_theta[g.idx()] = solved[g.idx()];
  for (FaceIndex f : mesh.faces())
    if (s.locked[f.idx()]) s.final_theta[f.idx()] = s.theta[f.idx()];
}

/// Optional smoothing (opt.smoothing > 0): one implicit step of the same
/// energy over every face of the area, constrained ones included (their
/// constraint becomes soft): min E(u) + sum_f (D_f / smoothing) |u_f - u0_f|^2,
/// u0 the field just interpolated, D_f the face's diagonal of E. Faces outside
/// the area stay locked.
void smooth_field(FieldState& s) {
  const Mesh& mesh = s.mesh;
  const int N = s.N;
  std::vector<int> sv(s.nf, -1);
  int ns = 0;
  for (FaceIndex f : mesh.faces())
    if (s.is_free(f) && (s.locked[f.idx()] || s.reach[f.idx()])) sv[f.idx()] = ns++;
  if (ns == 0) return;
  std::vector<Eigen::Triplet<Cplx>> trip;
  Eigen::VectorXcd rhs;
  const std::vector<double> diag = assemble_energy(s, sv, s.final_theta, ns, trip, rhs);
  for (FaceIndex f : mesh.faces()) {
    const int v = sv[f.idx()];
    if (v < 0) continue;
    const double pull = diag[v] > 0 ? diag[v] / s.opt.smoothing : 1.0;  // an isolated face keeps u0
    trip.emplace_back(v, v, Cplx(diag[v] + pull, 0));
    rhs[v] += pull * std::polar(1.0, N * s.final_theta[f.idx()]);
  }
  Eigen::SparseMatrix<Cplx> A(ns, ns);
  A.setFromTriplets(trip.begin(), trip.end());
  const Eigen::VectorXcd x = solve_hermitian(A, rhs, "smoothing ", std::to_string(ns) + " faces");
  for (FaceIndex f : mesh.faces()) {
    const int v = sv[f.idx()];
    if (v < 0 || !(std::abs(x[v]) > 0)) continue;  // a zero keeps the interpolated angle
    s.final_theta[f.idx()] = std::atan2(x[v].imag(), x[v].real()) / N;
  }
}

/// Combing: every face in the area may take any of its N representatives
/// (constraints fix orientations modulo 2 pi / N only). Grown from the faces
/// outside the area (fixed), or from the lowest constrained face, each face
/// taking the representative closest to its parent's direction transported
/// across the shared edge. Smoothest edges first (Prim's algorithm on the
/// dual graph, the cost of crossing an edge = the angle left between the
/// transported direction and the closest representative): the
/// representatives then disagree (a quarter-turn "cut", where s and t swap
/// for the parameterization) only where the field turns fastest, near its
/// singularities, instead of wherever two breadth-first fronts happen to meet.
void comb_field(FieldState& s) {
  const Mesh& mesh = s.mesh;
  const int N = s.N;
  std::vector<double>& final_theta = s.final_theta;
  struct Candidate {
    double cost;
    std::uint32_t g, f, h;
    bool operator>(const Candidate& o) const {
      if (cost != o.cost) return cost > o.cost;
      if (g != o.g) return g > o.g;
      return h > o.h;
    }
  };
  std::priority_queue<Candidate, std::vector<Candidate>, std::greater<Candidate>> heap;
  std::vector<char> done(s.nf, 0);
  auto push_neighbours = [&](FaceIndex f) {
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const HalfedgeIndex o = mesh.opposite(h);
      if (mesh.is_border(o)) continue;
      const FaceIndex g = mesh.face(o);
      if (done[g.idx()] || !(s.locked[g.idx()] || s.reach[g.idx()])) continue;
      const double transported = final_theta[f.idx()] - s.edge_angle(h, f.idx()) + s.edge_angle(h, g.idx());
      const double rep = closest_representative(final_theta[g.idx()], transported, N);
      heap.push({std::abs(rep - transported), static_cast<std::uint32_t>(g.idx()),
                 static_cast<std::uint32_t>(f.idx()), static_cast<std::uint32_t>(h.idx())});
    }
  };
  auto grow = [&] {
    while (!heap.empty()) {
      const Candidate c = heap.top();
      heap.pop();
      if (done[c.g]) continue;
      done[c.g] = 1;
      const HalfedgeIndex h(c.h);
      const double transported = final_theta[c.f] - s.edge_angle(h, c.f) + s.edge_angle(h, c.g);
      final_theta[c.g] = closest_representative(final_theta[c.g], transported, N);
      push_neighbours(FaceIndex(c.g));
    }
  };
  for (FaceIndex f : mesh.faces())
    if (!s.is_free(f)) done[f.idx()] = 1;
  for (FaceIndex f : mesh.faces())
    if (!s.is_free(f) && s.relevant[f.idx()]) push_neighbours(f);  // the fixed outside
  grow();
  // Components not touching the outside start at a constrained face (it
  // keeps its given representative), else at their lowest face.
  std::vector<FaceIndex> starts;
  for (FaceIndex f : mesh.faces())
    if (s.locked[f.idx()]) starts.push_back(f);
  for (FaceIndex f : mesh.faces())
    if (!s.locked[f.idx()]) starts.push_back(f);
  for (FaceIndex f0 : starts) {
    if (done[f0.idx()] || !(s.locked[f0.idx()] || s.reach[f0.idx()])) continue;
    done[f0.idx()] = 1;
    push_neighbours(f0);
    grow();
  }
}

/// The directions of the free faces: the combed angle in the face frame, or
/// e1 on a component without constraints; faces outside the area keep
/// theirs bit for bit.
void write_directions(const FieldState& s, FaceDirs& dir) {
  for (FaceIndex f : s.mesh.faces()) {
    if (!s.is_free(f)) continue;  // bit for bit unchanged outside the area
    if (!s.locked[f.idx()] && !s.reach[f.idx()]) {
      dir[f.idx()] = s.frames[f.idx()].e1;
      continue;
    }
    dir[f.idx()] = s.frames[f.idx()].direction(s.final_theta[f.idx()]);
  }
}

}  // namespace

DirectionFieldResult interpolate_direction_field(Mesh& mesh,
                                                 const std::vector<DirectionConstraint>& constraints,
                                                 const DirectionFieldOptions& opt) {
  auto map = get_or_add(mesh, opt.direction_map, Vector3(0, 0, 0));
  FaceDirs dir(mesh.num_faces(), Vector3(0, 0, 0));
  for (FaceIndex f : mesh.faces()) dir[f.idx()] = map[f];
  const DirectionFieldResult res = interpolate_direction_field(mesh, constraints, dir, opt);
  for (FaceIndex f : mesh.faces()) map[f] = dir[f.idx()];
  return res;
}

DirectionFieldResult interpolate_direction_field(const Mesh& mesh,
                                                 const std::vector<DirectionConstraint>& constraints,
                                                 std::vector<Vector3>& dir, const DirectionFieldOptions& opt) {
  check_field_inputs(mesh, opt);
  if (dir.size() != mesh.num_faces())
    throw InvalidInputError("interpolate_direction_field: " + std::to_string(dir.size()) + " directions for " +
                            std::to_string(mesh.num_faces()) + " face indices");
  FieldState s(mesh, opt);
  DirectionFieldResult res;
  frame_relevant_faces(s);
  lock_faces(s, constraints, dir, res);
  number_reached_faces(s, res);
  solve_free_angles(s);
  if (opt.smoothing > 0) smooth_field(s);
  comb_field(s);
  write_directions(s, dir);
  res.solved_faces = static_cast<std::size_t>(s.n_var);
  return res;
}

std::vector<DirectionConstraint> constraints_from_principal_directions(const Mesh& mesh,
                                                                       double fraction) {
  if (!(fraction > 0 && fraction <= 1))
    throw InvalidInputError("constraints_from_principal_directions: fraction must be in (0,1], got " +
                            std::to_string(fraction));
  auto kmax = find(mesh, kVertexKmax);
  auto kmin = find(mesh, kVertexKmin);
  auto dmax = find(mesh, kVertexDmax);
  if (!kmax.second || !kmin.second || !dmax.second)
    throw InvalidInputError(
        "constraints_from_principal_directions: curvature maps v:kmax/v:kmin/v:dmax absent; run "
        "compute_principal_curvatures first");
  std::vector<std::pair<double, std::uint32_t>> aniso;
  for (FaceIndex f : mesh.faces()) {
    double a = 0;
    for (VertexIndex v : face_vertices(mesh, f)) a += kmax.first[v] - kmin.first[v];
    aniso.push_back({-a / 3, static_cast<std::uint32_t>(f.idx())});
  }
  const std::size_t keep =
      std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(fraction * aniso.size())));
  std::stable_sort(aniso.begin(), aniso.end());
  std::vector<DirectionConstraint> out;
  for (std::size_t i = 0; i < std::min(keep, aniso.size()); ++i) {
    const FaceIndex f(aniso[i].second);
    const Vector3 n = robust_face_normal(mesh, f);
    const auto vs = face_vertices(mesh, f);
    Vector3 ref = dmax.first[vs[0]];
    Vector3 sum(0, 0, 0);
    for (VertexIndex v : vs) {
      Vector3 d = dmax.first[v];
      if (d * ref < 0) d = -d;  // principal directions are lines
      sum = sum + d;
    }
    const Vector3 t = sum - (sum * n) * n;
    if (norm(t) < 1e-9) continue;
    out.push_back({aniso[i].second, {t.x(), t.y(), t.z()}});
  }
  std::sort(out.begin(), out.end(),
            [](const DirectionConstraint& a, const DirectionConstraint& b) { return a.face < b.face; });
  return out;
}

std::vector<DirectionConstraint> constraints_from_constant_vector(const Mesh& mesh,
                                                                  std::array<double, 3> v,
                                                                  double min_projection) {
  const Vector3 d(v[0], v[1], v[2]);
  if (!(norm(d) > 0) || !std::isfinite(norm(d)))
    throw InvalidInputError("constraints_from_constant_vector: vector must be non-zero and finite");
  std::vector<DirectionConstraint> out;
  for (FaceIndex f : mesh.faces()) {
    const Vector3 n = robust_face_normal(mesh, f);
    const Vector3 t = d - (d * n) * n;
    if (norm(t) >= min_projection * norm(d))
      out.push_back({static_cast<std::uint32_t>(f.idx()), {t.x(), t.y(), t.z()}});
  }
  return out;
}

std::array<double, 3> floor_vector(std::array<double, 3> v) {
  const Vector3 d(v[0], v[1], v[2]);
  if (!(norm(d) > 0) || !std::isfinite(norm(d)))
    throw InvalidInputError("floor_vector: vector must be non-zero and finite");
  int axis = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(v[i]) < std::abs(v[axis])) axis = i;
  const Vector3 e(axis == 0, axis == 1, axis == 2);
  const Vector3 f = CGAL::cross_product(d, e);
  const double len = norm(f);
  return {f.x() / len, f.y() / len, f.z() / len};
}

std::vector<DirectionConstraint> floor_constraints(const Mesh& mesh, std::array<double, 3> v,
                                                   double max_projection) {
  const Vector3 d(v[0], v[1], v[2]);
  const std::array<double, 3> fv = floor_vector(v);
  const Vector3 s(fv[0], fv[1], fv[2]);
  std::vector<Vector3> normal(mesh.num_faces(), Vector3(0, 0, 0));
  std::vector<std::uint8_t> flat(mesh.num_faces(), 0);
  for (FaceIndex f : mesh.faces()) {
    const Vector3 n = normal[f.idx()] = robust_face_normal(mesh, f);
    flat[f.idx()] = norm(d - (d * n) * n) < max_projection * norm(d);
  }
  std::vector<DirectionConstraint> out;
  for (FaceIndex f : mesh.faces()) {
    if (!flat[f.idx()]) continue;
    // A flat region, not a band of a curved surface (a flat torus's crest):
    // every face across an edge is flat too.
    bool inside = true;
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const FaceIndex g = mesh.face(mesh.opposite(h));
      inside = inside && (g == Mesh::null_face() || flat[g.idx()]);
    }
    if (!inside) continue;
    const Vector3& n = normal[f.idx()];
    const Vector3 t = s - (s * n) * n;
    if (norm(t) > 0.5)  // the face is near orthogonal to v, so s lies nearly in it
      out.push_back({static_cast<std::uint32_t>(f.idx()), {t.x(), t.y(), t.z()}});
  }
  return out;
}

}  // namespace surftex
