// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/shell_stretch.h"
#include "geometry/constants.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"

namespace surftex {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// Squared Frobenius norm of S T^-1 over 3 (= L2^2), or inf if det T <= 0.
// Columns of S and T are the edge vectors from vertex 0.
double l2_squared(const std::array<Vec3, 4>& s, const std::array<Vec3, 4>& t) {
  double S[3][3], T[3][3];
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) S[i][j] = s[j + 1][i] - s[0][i], T[i][j] = t[j + 1][i] - t[0][i];
  const double det = T[0][0] * (T[1][1] * T[2][2] - T[1][2] * T[2][1]) -
                     T[0][1] * (T[1][0] * T[2][2] - T[1][2] * T[2][0]) +
                     T[0][2] * (T[1][0] * T[2][1] - T[1][1] * T[2][0]);
  if (!(det > 0)) return kInf;
  double Ti[3][3];  // inverse by adjugate
  Ti[0][0] = (T[1][1] * T[2][2] - T[1][2] * T[2][1]) / det;
  Ti[0][1] = (T[0][2] * T[2][1] - T[0][1] * T[2][2]) / det;
  Ti[0][2] = (T[0][1] * T[1][2] - T[0][2] * T[1][1]) / det;
  Ti[1][0] = (T[1][2] * T[2][0] - T[1][0] * T[2][2]) / det;
  Ti[1][1] = (T[0][0] * T[2][2] - T[0][2] * T[2][0]) / det;
  Ti[1][2] = (T[0][2] * T[1][0] - T[0][0] * T[1][2]) / det;
  Ti[2][0] = (T[1][0] * T[2][1] - T[1][1] * T[2][0]) / det;
  Ti[2][1] = (T[0][1] * T[2][0] - T[0][0] * T[2][1]) / det;
  Ti[2][2] = (T[0][0] * T[1][1] - T[0][1] * T[1][0]) / det;
  double f = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double J = S[i][0] * Ti[0][j] + S[i][1] * Ti[1][j] + S[i][2] * Ti[2][j];
      f += J * J;
    }
  return f / 3.0;
}

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

std::array<Vec3, 4> shell_tet(const ShellSpace& s, const Tet& t) {
  return {s.shell_points[t[0]], s.shell_points[t[1]], s.shell_points[t[2]], s.shell_points[t[3]]};
}
std::array<Vec3, 4> texture_tet(const ShellSpace& s, const Tet& t) {
  return {s.texture_metric(t[0]), s.texture_metric(t[1]), s.texture_metric(t[2]), s.texture_metric(t[3])};
}

void check_stretch_options(const ShellSpace& s, const MinimizeStretchOptions& opt) {
  if (s.tets.empty()) throw InvalidInputError("minimize stretch: the shell has no tetrahedra");
  if (opt.iterations < 0) throw InvalidInputError("minimize stretch: iterations must be >= 0");
  if (opt.line_samples < 1) throw InvalidInputError("minimize stretch: line_samples must be >= 1");
  if (opt.refine_steps < 0) throw InvalidInputError("minimize stretch: refine_steps must be >= 0");
  if (!(opt.step_fraction > 0 && opt.step_fraction <= 1))
    throw InvalidInputError("minimize stretch: step_fraction must be in (0,1], got " +
                            std::to_string(opt.step_fraction));
  if (!(opt.tolerance >= 0)) throw InvalidInputError("minimize stretch: tolerance must be >= 0");
}

/// The shell with what the local moves read: vertex -> tets (CSR) and the
/// tets' shell volumes (fixed: only texture points move).
struct StretchShell {
  explicit StretchShell(ShellSpace& shell) : s(shell) {}
  ShellSpace& s;
  std::vector<int> start, items;  // tets of vertex v: items[start[v] .. start[v + 1])
  std::vector<double> vol_s;
};

void index_vertex_tets(StretchShell& st) {
  const ShellSpace& s = st.s;
  const std::size_t nv = s.shell_points.size(), nt = s.tets.size();
  st.start.assign(nv + 1, 0);
  st.items.resize(4 * nt);
  for (const Tet& t : s.tets)
    for (int v : t) ++st.start[static_cast<std::size_t>(v) + 1];
  for (std::size_t i = 0; i < nv; ++i) st.start[i + 1] += st.start[i];
  {
    std::vector<int> fill(st.start.begin(), st.start.end() - 1);
    for (std::size_t ti = 0; ti < nt; ++ti)
      for (int v : s.tets[ti]) st.items[static_cast<std::size_t>(fill[v]++)] = static_cast<int>(ti);
  }
  st.vol_s.resize(nt);
  for (std::size_t ti = 0; ti < nt; ++ti) {
    const auto S = shell_tet(s, s.tets[ti]);
    st.vol_s[ti] = std::abs(tet_signed_volume(S[0], S[1], S[2], S[3]));
  }
}

/// Greedy colouring of the free vertices (no two of one colour share a tet),
/// so that one colour's vertices move in parallel independently.
std::vector<std::vector<int>> color_free_vertices(const StretchShell& st, const std::vector<int>& free_vs) {
  const ShellSpace& s = st.s;
  std::vector<int> color(s.shell_points.size(), -1);
  std::vector<std::vector<int>> classes;
  for (int v : free_vs) {
    std::vector<char> used(classes.size() + 1, 0);
    for (int i = st.start[v]; i < st.start[v + 1]; ++i)
      for (int w : s.tets[static_cast<std::size_t>(st.items[static_cast<std::size_t>(i)])])
        if (w != v && color[w] >= 0) used[static_cast<std::size_t>(color[w])] = 1;
    int c = 0;
    while (used[static_cast<std::size_t>(c)]) ++c;
    color[v] = c;
    if (static_cast<std::size_t>(c) == classes.size()) classes.emplace_back();
    classes[static_cast<std::size_t>(c)].push_back(v);
  }
  return classes;
}

/// Local energy of vertex v placed at (u, w) (metric texture coordinates of
/// the others as they are): its tets' L2^2 weighted by shell volume, inf if
/// one inverts.
double local_energy(const StretchShell& st, int v, double u, double w) {
  const ShellSpace& s = st.s;
  double e = 0;
  for (int i = st.start[v]; i < st.start[v + 1]; ++i) {
    const int ti = st.items[static_cast<std::size_t>(i)];
    const Tet& t = s.tets[static_cast<std::size_t>(ti)];
    std::array<Vec3, 4> T = texture_tet(s, t);
    for (int k = 0; k < 4; ++k)
      if (t[k] == v) T[k][0] = u, T[k][1] = w;
    const double l = l2_squared(shell_tet(s, t), T);
    if (l == kInf) return kInf;
    e += l * st.vol_s[static_cast<std::size_t>(ti)];
  }
  return e;
}

/// Whether v at (u, w) leaves all its tets positive in texture space (exact predicate).
bool exact_ok(const StretchShell& st, int v, double u, double w) {
  const ShellSpace& s = st.s;
  for (int i = st.start[v]; i < st.start[v + 1]; ++i) {
    const Tet& t = s.tets[static_cast<std::size_t>(st.items[static_cast<std::size_t>(i)])];
    Point3 p[4];
    for (int k = 0; k < 4; ++k) {
      Vec3 q = s.texture_points[t[k]];
      if (t[k] == v) q[0] = u, q[1] = w;
      p[k] = Point3(q[0], q[1], q[2]);
    }
    if (CGAL::orientation(p[0], p[1], p[2], p[3]) != CGAL::POSITIVE) return false;
  }
  return true;
}

/// One random line search for free vertex v in sweep `sweep`: a direction
/// drawn from the vertex's own seeded generator, samples at geometric
/// distances within a fraction of the nearest offset-surface neighbour, a
/// golden-section refinement around the best; the move is kept if it lowers
/// the local energy and inverts no tet (exact check).
void move_vertex(StretchShell& st, int v, int sweep, const MinimizeStretchOptions& opt,
                 std::atomic<std::size_t>& tried, std::atomic<std::size_t>& accepted) {
  ShellSpace& s = st.s;
  const double golden = 0.5 * (std::sqrt(5.0) - 1.0);
  Vec3& tp = s.texture_points[static_cast<std::size_t>(v)];
  const double u0 = tp[0], w0 = tp[1];
  // Search radius from the neighbouring offset-surface vertices.
  double rmin = kInf;
  for (int i = st.start[v]; i < st.start[v + 1]; ++i)
    for (int q : s.tets[static_cast<std::size_t>(st.items[static_cast<std::size_t>(i)])])
      if (q != v && s.layer[q] == 1) {
        const Vec3& o = s.texture_points[q];
        rmin = std::min(rmin, std::hypot(o[0] - u0, o[1] - w0));
      }
  if (!(rmin < kInf) || !(rmin > 0)) return;
  const double radius = opt.step_fraction * rmin;
  std::mt19937_64 rng(splitmix64(opt.seed ^ splitmix64(static_cast<std::uint64_t>(sweep) * 0x100000001b3ULL +
                                                       static_cast<std::uint64_t>(v))));
  const double angle = std::uniform_real_distribution<double>(0.0, 2 * kPi)(rng);
  const double du = std::cos(angle), dw = std::sin(angle);
  auto E = [&](double t) { return local_energy(st, v, u0 + t * du, w0 + t * dw); };
  const double e0 = E(0);
  double best_t = 0, best_e = e0;
  // Samples at geometric distances radius / 2^k on both sides: the best
  // step can be far below the neighbour distance (thin texture tets).
  double t = radius;
  for (int k = 0; k < opt.line_samples; ++k, t *= 0.5)
    for (double sgn : {1.0, -1.0}) {
      const double e = E(sgn * t);
      if (e < best_e) best_e = e, best_t = sgn * t;
    }
  tried.fetch_add(1, std::memory_order_relaxed);
  if (!(best_e < e0)) return;
  // Golden-section refinement between half and one and a half times the best sample.
  double a = 0.5 * best_t, b = 1.5 * best_t;
  if (a > b) std::swap(a, b);
  double x1 = b - golden * (b - a), x2 = a + golden * (b - a);
  double f1 = E(x1), f2 = E(x2);
  for (int it = 0; it < opt.refine_steps; ++it) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - golden * (b - a), f1 = E(x1);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + golden * (b - a), f2 = E(x2);
    }
  }
  if (f1 < best_e) best_e = f1, best_t = x1;
  if (f2 < best_e) best_e = f2, best_t = x2;
  const double u1 = u0 + best_t * du, w1 = w0 + best_t * dw;
  if (best_e < e0 && exact_ok(st, v, u1, w1)) {
    tp[0] = u1, tp[1] = w1;
    accepted.fetch_add(1, std::memory_order_relaxed);
  }
}
}  // namespace

double tet_l2_stretch(const std::array<Vec3, 4>& s, const std::array<Vec3, 4>& t) {
  return std::sqrt(l2_squared(s, t));
}

ShellStretch shell_stretch(const ShellSpace& s) {
  if (s.tets.empty()) throw InvalidInputError("shell stretch: the shell has no tetrahedra");
  const std::size_t n = s.tets.size();
  std::vector<double> l2sq(n), vs(n), vt(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const auto S = shell_tet(s, s.tets[i]), T = texture_tet(s, s.tets[i]);
      l2sq[i] = l2_squared(S, T);
      vs[i] = std::abs(tet_signed_volume(S[0], S[1], S[2], S[3]));
      vt[i] = std::abs(tet_signed_volume(T[0], T[1], T[2], T[3]));
    }
  });
  ShellStretch r;
  double num = 0, maxsq = 0;
  for (std::size_t i = 0; i < n; ++i) {  // sequential sums: deterministic
    num += l2sq[i] * vs[i];
    r.shell_volume += vs[i];
    r.texture_volume += vt[i];
    maxsq = std::max(maxsq, l2sq[i]);
  }
  r.l2 = std::sqrt(num / r.shell_volume);
  const double norm = std::cbrt(r.texture_volume / r.shell_volume);
  r.l2_normalized = r.l2 * norm;
  r.max_tet = std::sqrt(maxsq) * norm;
  return r;
}

/// Stretch minimisation of the shell map (Zhou et al. 2006 s.3.1, after
/// Sander et al.'s L2 stretch): sweeps of random line searches over the free
/// offset-surface vertices' texture coordinates, one colour class at a time
/// in parallel, until a sweep gains less than the tolerance.
MinimizeStretchResult shell_map_minimize_stretch(ShellSpace& s, const MinimizeStretchOptions& opt) {
  check_stretch_options(s, opt);
  MinimizeStretchResult res;
  res.stretch_before = shell_stretch(s).l2_normalized;
  res.stretch_after = res.stretch_before;
  StretchShell st(s);
  index_vertex_tets(st);
  std::vector<int> free_vs;
  for (std::size_t v = 0; v < s.shell_points.size(); ++v)
    if (s.layer[v] == 1 && !s.lateral[v]) free_vs.push_back(static_cast<int>(v));
  res.free_vertices = free_vs.size();
  if (free_vs.empty() || opt.iterations == 0) return res;
  const std::vector<std::vector<int>> classes = color_free_vertices(st, free_vs);
  res.colors = static_cast<int>(classes.size());
  std::atomic<std::size_t> tried{0}, accepted{0};
  for (int sweep = 0; sweep < opt.iterations; ++sweep) {
    for (const auto& cls : classes) {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cls.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) move_vertex(st, cls[k], sweep, opt, tried, accepted);
      });
    }
    res.sweeps = sweep + 1;
    const double now = shell_stretch(s).l2_normalized;
    const double gain = (res.stretch_after - now) / res.stretch_after;
    res.stretch_after = now;
    if (gain < opt.tolerance) break;
  }
  res.moves_tried = tried.load();
  res.moves_accepted = accepted.load();
  return res;
}

}  // namespace surftex
