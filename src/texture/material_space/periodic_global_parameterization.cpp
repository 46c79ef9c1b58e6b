// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/periodic_global_parameterization.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <dlfcn.h>
#include <metis.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cmath>
#include <deque>
#include <mutex>
#include <string>

#include "geometry/effect_area.h"
#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "texture/material_space/pgp_curl_correction.h"
#include "geometry/properties.h"
#include "geometry/union_find.h"
#include "geometry/timer.h"

namespace surftex {
namespace {

using Cplx = std::complex<double>;
using SpMat = Eigen::SparseMatrix<double>;
// Supernodal Cholesky (CHOLMOD, unknowns pre-ordered by METIS nested
// dissection of the vertex graph; deterministic). The dense
// supernode kernels go through the BLAS libcholmod is linked with.
using Cholesky = Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower>;

/// METIS nested dissection of one graph (CSR, 0-based); iperm[v] = position
/// of v. Returns false on a METIS failure.
bool metis_order(std::vector<idx_t>& xadj, std::vector<idx_t>& adjncy, std::vector<idx_t>& iperm) {
  idx_t nv = static_cast<idx_t>(xadj.size()) - 1;
  iperm.assign(static_cast<std::size_t>(nv), 0);
  if (nv == 0) return true;
  std::vector<idx_t> perm(static_cast<std::size_t>(nv));
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  // METIS draws from libc's one rand() state (srand(seed) per call, see
  // nested_dissection_order): two solvers ordering at once on two threads
  // would interleave their draws. One at a time.
  static std::mutex metis_mutex;
  std::lock_guard<std::mutex> lock(metis_mutex);
  return METIS_NodeND(&nv, xadj.data(), adjncy.data(), nullptr, options, perm.data(), iperm.data()) == METIS_OK;
}

/// Fill-reducing order of the free vertices: METIS nested dissection of the
/// vertex graph (free vertices, edges between two of them), each vertex's
/// 4 unknowns kept together. Ordering this graph (n nodes) instead of the
/// 4n-unknown scalar graph takes a fraction of the time (CHOLMOD's METIS
/// on the scalar graph: ~1.9 s wall under load at 52K triangles, 1.45e9
/// flops) and gives CHOLMOD supernodes of whole vertices; on armadillo_52k
/// the factorisation takes 1.83e9 flops, against 2.32e9 with CHOLMOD's
/// default AMD on the scalar graph (the 25% update area: 2.18e8 vs 2.22e8,
/// no gain there). Measured alternatives (armadillo_52k, issue #5): METIS on
/// the 2n-node graph of the (s,t) pairs (the parity double cover) 1.49e9
/// flops, 1.39e9 with 3 separators per level, but 2.5-5x the ordering time
/// and it depends on the field (cannot run beside it); full 4x4 blocks
/// instead of the parity pattern 2.25e9; CHOLMOD's supernode relaxation
/// (nrelax/zrelax) changed nothing measurable. Deterministic (METIS' default
/// seed) provided no other thread calls rand() meanwhile: Debian's METIS 5.1
/// draws its random numbers from libc's rand() (srand(seed) at each call),
/// one global state. Two METIS calls side by side (the two halves of the top
/// separator ordered in parallel, tried for issue #5) gave a different order
/// on each run; surftex itself never calls rand() (seeded std::mt19937_64),
/// so the order may run beside the field's work. Returns var renumbered; on
/// a METIS failure (or tiny systems) the input order is kept.
std::vector<int> nested_dissection_order(const std::vector<int>& var, int n,
                                         const std::vector<std::array<std::uint32_t, 2>>& ends) {
  if (n < 16) return var;
  std::vector<idx_t> degree(static_cast<std::size_t>(n) + 1, 0);
  for (const auto& ij : ends) {
    const int a = var[ij[0]], b = var[ij[1]];
    if (a < 0 || b < 0 || a == b) continue;
    ++degree[static_cast<std::size_t>(a) + 1];
    ++degree[static_cast<std::size_t>(b) + 1];
  }
  for (int v = 0; v < n; ++v) degree[v + 1] += degree[v];
  std::vector<idx_t> xadj = degree, adjncy(static_cast<std::size_t>(xadj[n]));
  for (const auto& ij : ends) {
    const int a = var[ij[0]], b = var[ij[1]];
    if (a < 0 || b < 0 || a == b) continue;
    adjncy[degree[a]++] = b;
    adjncy[degree[b]++] = a;
  }
  std::vector<idx_t> iperm;
  const bool ok = metis_order(xadj, adjncy, iperm);
  if (!ok) return var;
  std::vector<int> out(var.size(), -1);
  for (std::size_t v = 0; v < var.size(); ++v)
    if (var[v] >= 0) out[v] = static_cast<int>(iperm[static_cast<std::size_t>(var[v])]);
  return out;
}

/// The BLAS behind CHOLMOD's dense supernode kernels, set up once per
/// process before the first factorisation; returns the name of OpenBLAS's
/// kernel set ("" for another BLAS).
///  - Same bytes whatever the thread count: Debian's default BLAS (netlib) is
///    single-threaded; an OpenBLAS providing libblas.so.3
///    (update-alternatives) is pinned to one thread, since its thread count
///    (the machine's cores by default) changes the bytes: measured with the
///    pthread build on armadillo_52k, 1, 2, 3 and 4 BLAS threads gave four
///    different solutions (its dpotrf blocks by thread count).
///  - Kernels: OpenBLAS 0.3.21 (Debian 12) picks its kernels by CPU model
///    and falls back to the generic SSE3 "Prescott" set on CPUs newer than
///    it knows (this machine's Xeon with AVX-512: dgemm 12 GFlop/s instead
///    of 63 with the SkylakeX set, dpotrf 15 instead of 29 on 600x600). When
///    it reports Prescott on a CPU with AVX-512 (or AVX2+FMA) and the user has
///    not chosen OPENBLAS_CORETYPE, it is re-initialised with the SkylakeX
///    (Haswell) set through its dynamic-arch entry points (the documented
///    OPENBLAS_CORETYPE variable, set for the call only). The kernels change
///    the rounding of the factor (as on any other machine model), not the
///    determinism: same machine, same bytes.
const std::string& configure_blas() {
  static const std::string core = [] {
    using SetThreads = void (*)(int);
    for (const char* name : {"openblas_set_num_threads", "goto_set_num_threads"})
      if (void* f = dlsym(RTLD_DEFAULT, name)) reinterpret_cast<SetThreads>(f)(1);
    using CoreName = char* (*)();
    using Hook = void (*)();
    void* name_fn = dlsym(RTLD_DEFAULT, "openblas_get_corename");
    if (!name_fn) return std::string();
    auto corename = [&] {
      const char* c = reinterpret_cast<CoreName>(name_fn)();
      return std::string(c ? c : "");
    };
    std::string current = corename();
    std::string lower = current;
    for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    void* quit = dlsym(RTLD_DEFAULT, "gotoblas_dynamic_quit");
    void* init = dlsym(RTLD_DEFAULT, "gotoblas_dynamic_init");
    if (lower != "prescott" || std::getenv("OPENBLAS_CORETYPE") || !quit || !init) return current;
    const char* target = nullptr;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"))
      target = "SkylakeX";
    else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
      target = "Haswell";
#endif
    if (!target) return current;
    setenv("OPENBLAS_CORETYPE", target, 1);
    reinterpret_cast<Hook>(quit)();
    reinterpret_cast<Hook>(init)();
    unsetenv("OPENBLAS_CORETYPE");
    // re-pin (the thread count is kept by the re-initialisation, but cheaply sure)
    for (const char* name : {"openblas_set_num_threads", "goto_set_num_threads"})
      if (void* f = dlsym(RTLD_DEFAULT, name)) reinterpret_cast<SetThreads>(f)(1);
    return corename();
  }();
  return core;
}

/// Whether the BLAS behind CHOLMOD may be entered from two threads at once.
/// OpenBLAS says how it was built: openblas_get_parallel() is 0 for the
/// single-threaded build (USE_THREAD=0), which Debian 12 ships as
/// libopenblas0-serial 0.3.21 without USE_LOCKING: not safe for concurrent
/// calls (openblas_get_config(): "... SkylakeX SINGLE_THREADED"; in the
/// disassembly blas_memory_free takes no lock and blas_memory_alloc claims
/// a work-buffer slot with an unlocked test-and-set, so two level-3 calls at
/// once can share a work buffer; measured: the no-swap s and t halves
/// factored side by side failed with "not positive definite" in 3 of 4
/// two-thread armadillo_52k runs). The pthread build (libopenblas0-pthread,
/// what scripts/setup.sh installs; 1 for pthreads, 2 for OpenMP) locks its
/// buffers and, pinned to one thread by configure_blas, gives the serial
/// build's bytes (material-map on armadillo_52k: same mesh.obj). Any other
/// BLAS is not known here and is treated as unsafe.
bool blas_allows_concurrent_calls() {
  static const bool safe = [] {
    configure_blas();
    using Parallel = int (*)();
    void* f = dlsym(RTLD_DEFAULT, "openblas_get_parallel");
    return f && reinterpret_cast<Parallel>(f)() > 0;
  }();
  return safe;
}

/// Held around every call into CHOLMOD that reaches the BLAS (numeric
/// factorisation, solve) unless the BLAS allows concurrent calls
/// (blas_allows_concurrent_calls): then two solvers on two threads, and the
/// no-swap s and t halves, run side by side; otherwise they take turns (same
/// bytes either way). (A private copy of libcholmod + OpenBLAS loaded with
/// dlmopen was tried for the serial build: same bytes, but its second
/// libgomp and C library share the threads' pthread-key slots with the
/// first, and a thread that had run OpenMP code of both aborted at exit in
/// libgomp's goacc_destroy_thread. Dropped.)
class BlasGuard {
 public:
  BlasGuard() : lock_(mutex(), std::defer_lock) {
    if (!blas_allows_concurrent_calls()) lock_.lock();
  }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::unique_lock<std::mutex> lock_;
};

/// Supernodal LL' (LL^H) of one real symmetric (complex Hermitian) matrix,
/// lower triangle given, the order kept (natural, postordered): the settings
/// of Eigen's CholmodSupernodalLLT as used for the one-system path.
class SupernodalHalf {
 public:
  SupernodalHalf() {
    cholmod_start(&common_);
    common_.print = 0;  // failures are thrown as SolverError, not printed
    common_.nmethods = 1;
    common_.method[0].ordering = CHOLMOD_NATURAL;  // the nested-dissection order given
    common_.postorder = 1;
    common_.final_asis = 1;
    common_.supernodal = CHOLMOD_SUPERNODAL;
  }
  SupernodalHalf(const SupernodalHalf&) = delete;
  SupernodalHalf& operator=(const SupernodalHalf&) = delete;
  ~SupernodalHalf() {
    if (factor_) cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  /// Symbolic analysis of `a` (its pattern), then numeric factorisation of
  /// a matrix with that pattern.
  bool analyze(cholmod_sparse a) {
    if (factor_) cholmod_free_factor(&factor_, &common_);
    factor_ = cholmod_analyze(&a, &common_);
    return factor_ && common_.status == CHOLMOD_OK;
  }
  bool factorize(cholmod_sparse a) {
    if (!factor_) return false;
    BlasGuard blas_guard;
    cholmod_factorize(&a, factor_, &common_);
    return common_.status == CHOLMOD_OK && factor_->minor == factor_->n;
  }
  /// x = A^-1 b for one column of `rows` entries of type `xtype`
  /// (interleaved (re, im) for CHOLMOD_COMPLEX); x must have room.
  bool solve(const double* b, std::size_t rows, int xtype, double* x) {
    cholmod_dense d{};
    d.nrow = rows;
    d.ncol = 1;
    d.nzmax = rows;
    d.d = rows;
    d.x = const_cast<double*>(b);
    d.xtype = xtype;
    d.dtype = CHOLMOD_DOUBLE;
    BlasGuard blas_guard;
    cholmod_dense* r = cholmod_solve(CHOLMOD_A, factor_, &d, &common_);
    if (!r) return false;
    const std::size_t count = xtype == CHOLMOD_COMPLEX ? 2 * rows : rows;
    std::copy(static_cast<const double*>(r->x), static_cast<const double*>(r->x) + count, x);
    cholmod_free_dense(&r, &common_);
    return true;
  }
  double flops() const { return common_.fl; }
  double nonzeros() const { return common_.lnz; }

 private:
  cholmod_common common_{};
  cholmod_factor* factor_ = nullptr;
};

using Vec4 = std::array<double, 4>;  // (Re z_s, Im z_s, Re z_t, Im z_t) of one vertex
using Mat4 = std::array<Vec4, 4>;    // [row][col]
using St = std::array<double, 2>;

/// (s,t) seen from a frame whose representative is turned by q quarter turns
/// (d_s' = d_t, d_t' = -d_s per turn): (s,t) -> (t,-s) per turn.
St turn_st(St a, int q) {
  q = ((q % 4) + 4) % 4;
  for (int r = 0; r < q; ++r) a = {a[1], -a[0]};
  return a;
}
/// The same on the unit complex numbers: z_s' = z_t, z_t' = conj(z_s) per turn.
Vec4 turn_z(Vec4 x, int q) {
  q = ((q % 4) + 4) % 4;
  for (int r = 0; r < q; ++r) x = {x[2], x[3], x[0], -x[1]};
  return x;
}
/// x -> (exp(2 pi i a_s) z_s, exp(2 pi i a_t) z_t), given (cos, sin) of both angles.
Vec4 rotate_z(const Vec4& x, const Vec4& cs) {
  return {cs[0] * x[0] - cs[1] * x[1], cs[1] * x[0] + cs[0] * x[1], cs[2] * x[2] - cs[3] * x[3],
          cs[3] * x[2] + cs[2] * x[3]};
}
/// Edge map of the coupled system: x_j = M x_i in the vertices' own frames,
/// M = P_mj Rot(alpha) P_-mi (alpha in the edge's face frame, m_v the turns
/// from that face's frame to vertex v's frame). Orthogonal.
Mat4 edge_map(int mi, int mj, const St& a) {
  Mat4 M{};
  const Vec4 cs{std::cos(2 * M_PI * a[0]), std::sin(2 * M_PI * a[0]), std::cos(2 * M_PI * a[1]),
                std::sin(2 * M_PI * a[1])};
  for (int c = 0; c < 4; ++c) {
    Vec4 e{0, 0, 0, 0};
    e[c] = 1;
    const Vec4 y = turn_z(rotate_z(turn_z(e, -mi), cs), mj);
    for (int r = 0; r < 4; ++r) M[r][c] = y[r];
  }
  return M;
}

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
  if (!(o.curl_stiffness > 0) || !std::isfinite(o.curl_stiffness))
    throw InvalidInputError("periodic_global_parameterization: curl_stiffness must be > 0, got " +
                            std::to_string(o.curl_stiffness));
  if (!(o.curl_max_factor >= 1) || !std::isfinite(o.curl_max_factor))
    throw InvalidInputError("periodic_global_parameterization: curl_max_factor must be >= 1, got " +
                            std::to_string(o.curl_max_factor));
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

PgpCurlCorrectionOptions curl_options(const PgpOptions& o) {
  PgpCurlCorrectionOptions c;
  c.symmetry = o.symmetry;
  c.stiffness = o.curl_stiffness;
  c.max_factor = o.curl_max_factor;
  c.direction_map = o.direction_map;
  c.scale_map = o.scale_map;
  return c;
}

/// g = d / S^T per face (only where `mask` is set when given), written into
/// `g`; times the curl-correction factor when o.curl_correction (computed
/// over the whole mesh by `corrector`, which keeps its factorisation, or a
/// one-shot one; the faces outside `mask` keep their previous gradient).
void face_gradients_into(const Mesh& mesh, const PgpOptions& o, const std::vector<FaceFrame>& frames,
                         const std::vector<char>* mask, std::vector<FaceGrad>& g,
                         PgpCurlCorrector* corrector = nullptr) {
  auto dir = find(mesh, o.direction_map);
  if (!dir.second)
    throw InvalidInputError("periodic_global_parameterization: face map '" + std::string(o.direction_map.name) +
                            "' absent (interpolate a direction field first)");
  auto scale = find(mesh, o.scale_map);
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
  if (o.curl_correction) {
    PgpCurlCorrector one_shot(curl_options(o));
    const PgpCurlCorrection c = (corrector ? *corrector : one_shot).compute(mesh);
    for (std::size_t fi = 0; fi < g.size(); ++fi)
      if (!mesh.is_removed(FaceIndex(static_cast<Mesh::size_type>(fi))) && (!mask || (*mask)[fi]))
        g[fi] = {c.face_factor[fi] * g[fi].gs, c.face_factor[fi] * g[fi].gt};
  }
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
                          std::vector<std::array<double, 2>>& alpha,
                          std::vector<std::uint8_t>* quarter = nullptr) {
  const double step = 2 * M_PI / o.symmetry;
  alpha.resize(mesh.num_halfedges(), {0.0, 0.0});
  if (quarter) quarter->resize(mesh.num_halfedges(), 0);
  const long per = 4 / o.symmetry;  // quarter turns per symmetry step
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
      if (quarter) {
        // Matching: T's representative = U's turned by q quarter turns
        // (frame(face(h)) = frame(face(opposite)) rotated by quarter[h]).
        const long q = ((static_cast<long>(k) * per) % 4 + 4) % 4;
        (*quarter)[h.idx()] = static_cast<std::uint8_t>(q);
        (*quarter)[o.idx()] = static_cast<std::uint8_t>((4 - q) % 4);
      }
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

PgpTarget pgp_target(const Mesh& mesh, const PgpOptions& o) {
  check_options(o);
  std::vector<FaceFrame> frames;
  const auto g = face_gradients(mesh, o, &frames);
  PgpTarget out;
  out.alphas = halfedge_alphas(mesh, o, g, frames);
  out.gradients.resize(g.size());
  for (std::size_t i = 0; i < g.size(); ++i)
    out.gradients[i] = {{{g[i].gs.x(), g[i].gs.y(), g[i].gs.z()}, {g[i].gt.x(), g[i].gt.y(), g[i].gt.z()}}};
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
  UnionFind<std::uint32_t> sets(t.nv);
  for (const auto& ij : t.ends) sets.unite(ij[0], ij[1]);
  t.component.assign(t.nv, -1);
  std::vector<int> label(t.nv, -1);
  for (VertexIndex v : mesh.vertices()) {
    const std::uint32_t r = sets.find(static_cast<std::uint32_t>(v.idx()));
    if (label[r] < 0) label[r] = t.components++;
    t.component[v.idx()] = label[r];
  }
  return t;
}

// Lower triangle of the Hermitian system over the free vertices, with the
// position of every edge's and vertex's entry so that refilling the values
// for new alphas costs one pass (no triplet sort).
struct PgpPattern {
  std::vector<int> var;              // per vertex: unknown index or -1 (fill-reducing order)
  std::vector<int> natural;          // the same in vertex order (identifies the free set)
  int n = 0;                         // free vertices (4 real unknowns each)
  SpMat A;                           // pattern (values overwritten per fill)
  std::vector<std::ptrdiff_t> diag;  // per real unknown: position of (r,r)
  /// per live edge: parity of the turns between its two vertex frames (0: s
  /// couples to s and t to t; 1: s to t), which decides the block's nonzeros
  std::vector<std::uint8_t> parity;
  /// unknown numbering (see unknown_index): false = 4 per vertex together
  /// (coupled), true = all s pairs then all t pairs (paper's simplified PGP)
  bool split_st = false;
  /// per live edge: positions of the 4x4 block (row-major) below the diagonal,
  /// -1 for the entries that are structurally zero (or no block)
  std::vector<std::array<std::ptrdiff_t, 16>> off;
  /// split_st only: the two diagonal blocks of A (s: unknowns 0..2n-1, t:
  /// 2n..4n-1; A has nothing outside them) as two complex Hermitian n x n
  /// matrices (lower triangle, CHOLMOD's interleaved complex values): each
  /// 2x2 block of a half is a scaled rotation [[c, -s], [s, c]] (vertex
  /// blocks c I), i.e. multiplication by c + i s, so the half is the real
  /// form of the complex system of z_s (z_t) itself.
  struct ComplexHalf {
    std::vector<int> col, row;  ///< CSC pattern (n + 1 column starts, row indices)
    std::vector<double> x;      ///< (re, im) per entry
    /// per entry: positions in A's values of its real part (entry (2r, 2c)
    /// of the half) and imaginary part ((2r+1, 2c); -1 on the diagonal)
    std::vector<std::ptrdiff_t> re, im;
  };
  std::array<ComplexHalf, 2> half;
};

/// The two complex halves of a block-diagonal lower triangle (split
/// numbering): per vertex column c of half h, the even real column 2c (its
/// odd column holds the same numbers by the rotation structure).
void split_halves(PgpPattern& p) {
  const int n = p.n, m = 2 * n;
  const SpMat& A = p.A;
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  for (int h = 0; h < 2; ++h) {
    PgpPattern::ComplexHalf& C = p.half[static_cast<std::size_t>(h)];
    C.col.assign(static_cast<std::size_t>(n) + 1, 0);
    C.row.clear();
    C.re.clear();
    C.im.clear();
    for (int c = 0; c < n; ++c) {
      const int real_col = h * m + 2 * c;
      for (int q = outer[real_col]; q < outer[real_col + 1]; ++q) {
        const int r = inner[q] - h * m;  // real row within the half
        if (r < 0 || r >= m)
          throw SolverError("periodic_global_parameterization: s and t systems not independent (entry row " +
                            std::to_string(inner[q]) + ")");
        if (r % 2 != 0) continue;  // an imaginary part, taken with its real part
        C.row.push_back(r / 2);
        C.re.push_back(q);
        std::ptrdiff_t im = -1;
        if (r / 2 != c) {
          // the next stored row of this column is r + 1 (rows sorted)
          if (q + 1 >= outer[real_col + 1] || inner[q + 1] - h * m != r + 1)
            throw SolverError("periodic_global_parameterization: s and t blocks not rotations at row " +
                              std::to_string(inner[q]));
          im = q + 1;
        }
        C.im.push_back(im);
      }
      C.col[static_cast<std::size_t>(c) + 1] = static_cast<int>(C.row.size());
    }
    C.x.assign(2 * C.row.size(), 0.0);
  }
}

/// Entry (r, c) of an edge block is structurally nonzero iff the pairs of r
/// and c (s = 0, t = 1) match up to the parity of the frames' turns.
bool block_entry(int r, int c, int parity) { return ((r / 2) ^ (c / 2)) == parity; }

/// Index of real unknown r (0..3 = Re z_s, Im z_s, Re z_t, Im z_t) of free
/// vertex `var` among the 4n: coupled, a vertex's 4 together (4 var + r);
/// split (swap_coordinates false: s and t never meet, the matrix is block
/// diagonal), the 2n s unknowns first and the 2n t unknowns after, each half
/// in the same vertex order, so that CHOLMOD factors two independent trees.
inline int unknown_index(int var, int r, int n, bool split_st) {
  return split_st ? (r / 2) * 2 * n + 2 * var + (r % 2) : 4 * var + r;
}

PgpPattern make_pattern(const PgpTopology& t, std::vector<int> var, int n, std::vector<std::uint8_t> parity,
                        bool split_st) {
  PgpPattern p;
  p.var = std::move(var);
  p.n = n;
  p.parity = std::move(parity);
  p.split_st = split_st;
  // Visits every stored off-diagonal entry of every edge block:
  // f(edge k, index 4r+c in the 4x4 block, row, column) in the lower triangle.
  auto for_each_block_entry = [&](auto&& f) {
    for (std::size_t k = 0; k < t.ends.size(); ++k) {
      const int a = p.var[t.ends[k][0]], b = p.var[t.ends[k][1]];
      if (a < 0 || b < 0 || a == b) continue;
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c)
          if (block_entry(r, c, p.parity[k]))
            f(k, 4 * r + c, unknown_index(std::max(a, b), r, n, split_st), unknown_index(std::min(a, b), c, n, split_st));
    }
  };
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(static_cast<std::size_t>(n) * 4 + t.ends.size() * 8);
  for (int v = 0; v < 4 * n; ++v) trip.emplace_back(v, v, 0.0);
  for_each_block_entry([&](std::size_t, int, int row, int col) { trip.emplace_back(row, col, 0.0); });
  p.A.resize(4 * n, 4 * n);
  p.A.setFromTriplets(trip.begin(), trip.end());
  p.A.makeCompressed();
  auto position = [&](int row, int col) -> std::ptrdiff_t {
    const int* begin = p.A.innerIndexPtr() + p.A.outerIndexPtr()[col];
    const int* end = p.A.innerIndexPtr() + p.A.outerIndexPtr()[col + 1];
    const int* it = std::lower_bound(begin, end, row);
    return it - p.A.innerIndexPtr();
  };
  p.diag.resize(static_cast<std::size_t>(4 * n));
  for (int v = 0; v < 4 * n; ++v) p.diag[static_cast<std::size_t>(v)] = position(v, v);
  std::array<std::ptrdiff_t, 16> none;
  none.fill(-1);
  p.off.assign(t.ends.size(), none);
  for_each_block_entry([&](std::size_t k, int rc, int row, int col) { p.off[k][rc] = position(row, col); });
  if (split_st) split_halves(p);
  return p;
}

/// Per halfedge h (not border): turns q such that the frame of target(h) (the
/// representative of its reference face, the first non-border face met from
/// halfedge(v)) is face(h)'s representative turned by q. Walks each vertex's
/// fan both ways from the reference face, accumulating the edge matchings
/// (around a field singularity the walk stops where it started: one spoke
/// then carries the holonomy).
/// Into `cm` (resized to the halfedges); with `vertex_mask`, only the
/// vertices set in it are recomputed (a vertex's matchings depend on the
/// edge matchings of its own edges only), the others keep their entries.
void corner_matchings_into(const Mesh& mesh, const std::vector<std::uint8_t>& quarter,
                           const std::vector<char>* vertex_mask, std::vector<std::uint8_t>& cm) {
  cm.resize(mesh.num_halfedges(), 0);
  // Each vertex writes only the halfedges pointing to it: independent, so
  // the vertices run in parallel (same bytes for any thread count).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.num_vertices(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
  std::vector<HalfedgeIndex> fan;
  std::vector<int> m;
  for (std::size_t vi = range.begin(); vi != range.end(); ++vi) {
    if (vertex_mask && !(*vertex_mask)[vi]) continue;
    const VertexIndex v(static_cast<Mesh::size_type>(vi));
    if (mesh.is_removed(v) || mesh.halfedge(v) == Mesh::null_halfedge()) continue;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) cm[h.idx()] = 0;
    fan.clear();
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) fan.push_back(h);
    const std::size_t d = fan.size();
    std::size_t s0 = d;
    for (std::size_t i = 0; i < d; ++i)
      if (!mesh.is_border(fan[i])) {
        s0 = i;
        break;
      }
    if (s0 == d) continue;
    m.assign(d, -1);
    m[s0] = 0;
    // Forward: fan[i+1] = opposite(next(fan[i])), across next(fan[i]).
    for (std::size_t r = 0; r + 1 < d; ++r) {
      const std::size_t i = (s0 + r) % d, j = (i + 1) % d;
      if (mesh.is_border(fan[j]) || m[j] >= 0) break;
      m[j] = (m[i] + quarter[mesh.next(fan[i]).idx()]) % 4;
    }
    // Backward: across opposite(next(fan[j])) = edge of fan[i] in face(fan[j])... i.e.
    // from face(fan[i]) to face(fan[j]), j = i - 1, through halfedge opposite(fan[i]) of face(fan[j])'s next.
    for (std::size_t r = 0; r + 1 < d; ++r) {
      const std::size_t i = (s0 + d - r) % d, j = (i + d - 1) % d;
      if (mesh.is_border(fan[j]) || m[j] >= 0) break;
      // next(fan[j]) is the shared edge's halfedge in face(fan[j]); its opposite lies in face(fan[i]).
      m[j] = (m[i] + quarter[mesh.opposite(mesh.next(fan[j])).idx()]) % 4;
    }
    for (std::size_t i = 0; i < d; ++i)
      if (m[i] >= 0) cm[fan[i].idx()] = static_cast<std::uint8_t>(m[i]);
  }
  });
}

std::vector<std::uint8_t> corner_matchings(const Mesh& mesh, const std::vector<std::uint8_t>& quarter) {
  std::vector<std::uint8_t> cm;
  corner_matchings_into(mesh, quarter, nullptr, cm);
  return cm;
}


/// Working state of one solve (initialisation or local update), handed from
/// stage to stage of PeriodicGlobalParameterization::Impl::solve.
struct PgpSolve {
  const PgpTopology* t = nullptr;
  const std::vector<char>* free_face = nullptr;  // update: the faces whose field may have changed
  bool global = false;                           // initialisation (spanning-tree start)
  PgpResult res;
  Timer lap;  // the stage times of res.breakdown
  int n = 0;                                      // free vertices (4 real unknowns each)
  std::vector<int> natural;                       // unknown per vertex in vertex order (the free set)
  const std::vector<int>* order_known = nullptr;  // its fill-reducing order, when computed before
  bool partial = false;   // field quantities refreshed only next to the free faces
  bool split_st = false;  // s and t uncoupled (the paper's simplified PGP, no swapping)
  bool separate = false;  // ... and solved as two complex systems (PgpOptions::separate_halves)
  std::vector<char> face_mask, edge_mask;     // partial: faces and edges whose field may have changed
  std::vector<int> var;                       // unknown per vertex in the fill-reducing order, -1 locked
  std::vector<std::array<double, 2>> ealpha;  // per live edge: alpha along halfedge(e, 0)
  std::vector<std::array<int, 2>> turns;      // per live edge: reference face -> (source, target) frames
  std::vector<Mat4> maps;                     // per live edge: edge map (where read)
  bool same_pattern = false;                  // the symbolic analysis is reused
  double shift = 0;                           // mu of the unit-modulus pull
  SpMat A;                                    // F_PGP + mu M, lower triangle
  Eigen::VectorXd b, mass;                    // locked neighbours' terms; free vertices' masses
  std::string failure;                        // why the solver failed ("" = it did not)

  /// Adds the time since the last split to `into`.
  void split(double& into) {
    into += lap.seconds();
    lap.reset();
  }
  int unknown(int v, int r) const { return unknown_index(v, r, n, split_st); }
};

/// One half's relaxation of the separate-halves solve (its failure, times, steps).
struct PgpHalfRun {
  std::string why;
  double factor_seconds = 0, solve_seconds = 0;
  int steps = 0;
};

/// Reference scale of the shift: mean diagonal of F_PGP over mean mass.
double shift_unit(const PgpTopology& t) {
  double trace_w = 0, trace_m = 0;
  for (std::size_t k = 0; k < t.ends.size(); ++k) trace_w += 2 * t.weight[k];
  for (double m : t.mass) trace_m += m;
  return trace_m > 0 ? trace_w / trace_m : 1.0;
}

}  // namespace

struct PeriodicGlobalParameterization::Impl {
  Mesh& mesh;
  PgpOptions opt;
  std::vector<Cplx> zs, zt;
  bool initialized = false;
  std::unique_ptr<PgpTopology> topo;
  std::unique_ptr<PgpPattern> pattern;
  /// Order of the initial free set computed ahead by prepare(): (natural, var).
  std::unique_ptr<std::pair<std::vector<int>, std::vector<int>>> prepared;
  Cholesky solver;
  /// The s and t systems' own factors (swap_coordinates false with
  /// separate_halves; each with its own cholmod_common).
  std::array<SupernodalHalf, 2> halves;
  std::array<double, 2> factor_size{0, 0};  // flops and nonzeros of the analysed factor
  bool analyzed = false;
  std::string blas_core;  // OpenBLAS kernel set behind CHOLMOD ("" = another BLAS)
  // Field-dependent values of the last solve; a local update recomputes them
  // only next to the free faces (the only faces whose direction or scale
  // may have changed).
  std::vector<FaceGrad> grad;
  std::vector<std::array<double, 2>> alpha;         // per halfedge
  std::vector<std::uint8_t> quarter;                // per halfedge: edge matching (turns)
  std::vector<std::uint8_t> corner;                 // per halfedge: face -> vertex frame turns
  std::vector<std::array<double, 2>> edge_energy;  // per live edge
  bool cache_valid = false;
  std::unique_ptr<PgpCurlCorrector> curl;  // keeps its factorisation (opt.curl_correction)
  /// The face -> vertex frame turns: the accumulated matchings (coupled
  /// form), or none at all in the paper's simplified PGP (swap_coordinates
  /// false: each vertex's s is the s of every face around it, so across a
  /// cut of the combed field s meets t's direction; the faces there become
  /// singular, handled at rendering time, Ray et al. 2009 section 2.3).
  void vertex_matchings(const std::vector<char>* vertex_mask) {
    if (!opt.swap_coordinates) {
      corner.assign(mesh.num_halfedges(), 0);
      return;
    }
    corner_matchings_into(mesh, quarter, vertex_mask, corner);
  }
  PgpCurlCorrector* corrector() {
    if (!curl) curl = std::make_unique<PgpCurlCorrector>(curl_options(opt));
    return curl.get();
  }

  Impl(Mesh& m, PgpOptions o) : mesh(m), opt(std::move(o)) {
    blas_core = configure_blas();
    solver.cholmod().print = 0;  // failures are thrown as SolverError, not printed
    // The unknowns come in nested-dissection order (nested_dissection_order):
    // CHOLMOD keeps it (then postorders the elimination tree).
    solver.cholmod().nmethods = 1;
    solver.cholmod().method[0].ordering = CHOLMOD_NATURAL;
  }

  const PgpTopology& topology() {
    if (!topo || !topo->matches(mesh)) {
      topo = std::make_unique<PgpTopology>(make_topology(mesh));
      pattern.reset();
      prepared.reset();
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
  /// alpha along h in face(h)'s frame (alpha[] is in the frame of the edge's
  /// reference face, face(halfedge(e, 0)) unless that is the border).
  St face_alpha(HalfedgeIndex h) const {
    const HalfedgeIndex h0 = mesh.halfedge(mesh.edge(h), 0);
    const bool reference = h == h0 ? true : mesh.is_border(h0);
    // Without swapping (the paper's form) every face reads the edge's alpha
    // as the solve did, in the edge's reference frame.
    return reference || !opt.swap_coordinates ? St{alpha[h.idx()][0], alpha[h.idx()][1]}
                     : turn_st({alpha[h.idx()][0], alpha[h.idx()][1]}, quarter[h.idx()]);
  }
  /// Turns from the reference face of live edge k to its (source, target) frames.
  std::array<int, 2> edge_turns(std::size_t k) const {
    const HalfedgeIndex h = mesh.halfedge(EdgeIndex(topo->edges[k]), 0), o = mesh.opposite(h);
    if (!mesh.is_border(h)) return {corner[mesh.prev(h).idx()], corner[h.idx()]};
    return {corner[o.idx()], corner[mesh.prev(o).idx()]};
  }
  PgpResult solve(const std::vector<char>& free_vertex, const std::vector<char>* free_face, bool global);
  /// The order of this free set (unknown index per vertex in vertex order)
  /// computed before (last solve or prepare()), nullptr if none.
  const std::vector<int>* known_order(const std::vector<int>& natural) const {
    if (pattern && pattern->natural == natural) return &pattern->var;
    if (prepared && prepared->first == natural) return &prepared->second;
    return nullptr;
  }
  /// Free vertices of the initialisation: every vertex with an edge but one
  /// reference vertex per component.
  std::vector<char> initial_free_set();
  /// Unknown index per vertex in vertex order, -1 if not free, and the count.
  static std::vector<int> natural_numbering(const Mesh& mesh, const std::vector<char>& free_vertex, int& count) {
    std::vector<int> natural(mesh.num_vertices(), -1);
    count = 0;
    for (VertexIndex v : mesh.vertices())
      if (free_vertex[v.idx()]) natural[v.idx()] = count++;
    return natural;
  }
  void write_corners(const std::vector<std::array<double, 2>>& alpha, const std::vector<char>* free_face);

  // Stages of solve(), in order.
  void number_free_vertices(PgpSolve& s, const std::vector<char>& free_vertex);
  void order_and_field(PgpSolve& s);
  void mark_changed_field(PgpSolve& s);
  void field_quantities(PgpSolve& s);
  void compute_edge_maps(PgpSolve& s, const std::vector<int>* order);
  void integrate_start(PgpSolve& s);
  void build_pattern(PgpSolve& s);
  void analyze_and_assemble(PgpSolve& s);
  void assemble(PgpSolve& s);
  void relax(PgpSolve& s);
  void relax_halves(PgpSolve& s, Eigen::VectorXd& x, int iterations);
  void relax_half(PgpSolve& s, int h, Eigen::VectorXd& x, int iterations, PgpHalfRun& run);
  void relax_coupled(PgpSolve& s, Eigen::VectorXd& x, int iterations);
  void normalize_solution(PgpSolve& s, const Eigen::VectorXd& x);
  void edge_energies(PgpSolve& s);
  /// (Re z_s, Im z_s, Re z_t, Im z_t) of vertex v.
  Vec4 state(std::size_t v) const { return {zs[v].real(), zs[v].imag(), zt[v].real(), zt[v].imag()}; }
  /// Half h of the split system as a complex Hermitian CHOLMOD matrix (lower triangle given).
  cholmod_sparse half_matrix(int h);
};

void PeriodicGlobalParameterization::Impl::write_corners(const std::vector<std::array<double, 2>>& alpha,
                                                        const std::vector<char>* free_face) {
  // Corner coordinates, equation (4): from corner 0 (i = target(halfedge(f)))
  // along the two edges (i,j) and (i,k), the integer jump chosen so that the
  // difference is nearest to the edge's alpha_ij, which both faces of the edge
  // share: two faces whose three edge differences close (no zero of z inside)
  // then agree on their common edge exactly.
  auto stm = get_or_add(mesh, opt.stm_map, STM{0, 0, 0});
  auto mat = find(mesh, opt.material_map);
  const std::vector<std::uint32_t>& faces = topology().faces;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, faces.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t q = r.begin(); q != r.end(); ++q) {
      const FaceIndex f(faces[q]);
      if (free_face && !(*free_face)[f.idx()]) continue;
      const HalfedgeIndex h0 = mesh.halfedge(f);
      const HalfedgeIndex hs[3] = {h0, mesh.next(h0), mesh.next(mesh.next(h0))};
      // Each vertex's (s,t) is in its own frame: seen from f's frame
      // through the corner's matching.
      auto local = [&](HalfedgeIndex h) {
        const VertexIndex v = mesh.target(h);
        return turn_st({std::arg(zs[v.idx()]) / (2 * M_PI), std::arg(zt[v.idx()]) / (2 * M_PI)},
                       -int(corner[h.idx()]));
      };
      const St sti = local(h0);
      const double si = sti[0], ti = sti[1];
      // alpha along i -> corner c: c = 1 via hs[1] (i -> j); c = 2 against hs[0] (k -> i).
      const St a1 = face_alpha(hs[1]);
      const St a0 = face_alpha(hs[0]);
      const St a2{-a0[0], -a0[1]};
      for (int c = 0; c < 3; ++c) {
        const VertexIndex v = mesh.target(hs[c]);
        const double m = mat.second ? mat.first[v] : 0.0;
        if (c == 0) {
          stm[hs[c]] = {si, ti, m};
          continue;
        }
        const St& a = c == 1 ? a1 : a2;
        const St stj = local(hs[c]);
        const double sj = stj[0], tj = stj[1];
        stm[hs[c]] = {sj + std::round(si + a[0] - sj), tj + std::round(ti + a[1] - tj), m};
      }
    }
  });
}

/// One solve of F_PGP over the free vertices (Ray et al. 2009 s.2.2; the
/// coupled real form of Ray et al. 2006 when swapping): the field's alphas
/// (equation 3), the system's order, pattern and values, the Ginzburg-Landau
/// relaxation, the energies and the corner coordinates (equation 4).
PgpResult PeriodicGlobalParameterization::Impl::solve(const std::vector<char>& free_vertex,
                                                      const std::vector<char>* free_face, bool global) {
  Timer timer;
  PgpSolve s;
  s.free_face = free_face;
  s.global = global;
  s.res.blas_core = blas_core;
  s.res.concurrent_blas = blas_allows_concurrent_calls();
  PgpResult::Breakdown& bd = s.res.breakdown;
  check_options(opt);
  require_triangle_mesh(mesh, "periodic_global_parameterization");
  s.t = &topology();
  s.split(bd.topology);
  number_free_vertices(s, free_vertex);
  s.split(bd.topology);
  order_and_field(s);
  s.lap.reset();
  build_pattern(s);
  analyze_and_assemble(s);
  s.lap.reset();
  relax(s);
  if (!s.failure.empty())
    throw SolverError(std::string("periodic_global_parameterization: ") +
                      (s.split_st ? "s and t systems " : "coupled (s,t) system ") + s.failure + " (" +
                      std::to_string(s.n) + " free vertices)");
  analyzed = s.n > 0;
  // The reference vertices were locked at (1, 1) at initialisation: s = t = 0 there.
  edge_energies(s);
  cache_valid = true;
  s.split(bd.energy);
  write_corners(alpha, free_face);
  s.split(bd.corners);
  s.res.seconds = timer.seconds();
  return std::move(s.res);
}

/// The free unknowns in vertex order (identifies the free set), its order if
/// known, and which form of the system this solve takes.
void PeriodicGlobalParameterization::Impl::number_free_vertices(PgpSolve& s,
                                                                const std::vector<char>& free_vertex) {
  s.natural = natural_numbering(mesh, free_vertex, s.n);
  s.res.free_vertices = static_cast<std::size_t>(s.n);
  s.order_known = known_order(s.natural);
  // The curl correction is global (its factor changes a little everywhere
  // when the field changes in the area): all gradients are then refreshed,
  // so that an update equals a full rewrite from the same state.
  s.partial = s.free_face && cache_valid && !opt.curl_correction;
  s.split_st = !opt.swap_coordinates;
  // The two halves as two systems on two tasks (see PgpOptions::separate_halves).
  s.separate = s.split_st && opt.separate_halves;
}

/// Two independent pieces of work side by side: the fill-reducing order
/// (one serial METIS call; it depends on the free set and the connectivity
/// only, and is redone only when the free set changed) and the field's
/// quantities (parallel loops over the faces and edges). Neither reads what
/// the other writes, so the bytes do not depend on which thread runs what.
void PeriodicGlobalParameterization::Impl::order_and_field(PgpSolve& s) {
  const PgpTopology& t = *s.t;
  s.turns.resize(t.ends.size());
  // Edge maps where they are read: edges touching a free vertex, and the
  // edges whose energy is recomputed.
  s.maps.resize(t.ends.size());
  tbb::parallel_invoke(
      [&] {
        Timer tt;
        s.var = s.order_known ? *s.order_known : nested_dissection_order(s.natural, s.n, t.ends);
        s.res.breakdown.ordering = tt.seconds();
      },
      [&] { field_quantities(s); });
}

/// Faces whose gradient may have changed (free faces) and edges whose alpha
/// may have (edges of free faces), for a partial refresh.
void PeriodicGlobalParameterization::Impl::mark_changed_field(PgpSolve& s) {
  const PgpTopology& t = *s.t;
  s.face_mask.assign(t.nf, 0);
  s.edge_mask.assign(t.ne, 0);
  for (std::uint32_t f : t.faces) {
    if (!(*s.free_face)[f]) continue;
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(FaceIndex(f)), mesh)) {
      s.edge_mask[mesh.edge(h).idx()] = 1;
      s.face_mask[f] = 1;
      // the opposite face's gradient enters the edge's alpha: unchanged
      // unless free, so it is read from the cache
    }
  }
}

/// The field's quantities (Ray et al. 2009 s.2.2): face gradients, halfedge
/// alphas (equation 3), matchings, the edges' alphas and turns; on a full
/// refresh also every edge map and the spanning-tree start. Everything when
/// no valid cache, else only next to the free faces.
void PeriodicGlobalParameterization::Impl::field_quantities(PgpSolve& s) {
  const PgpTopology& t = *s.t;
  PgpResult::Breakdown& bd = s.res.breakdown;
  Timer tt;
  if (s.partial) mark_changed_field(s);
  // (the corrector solves with Eigen's own ordering: no METIS, no rand(),
  // safe beside the ordering)
  face_gradients_into(mesh, opt, t.frames, s.partial ? &s.face_mask : nullptr, grad, corrector());
  halfedge_alphas_into(mesh, opt, grad, t.frames, s.partial ? &s.edge_mask : nullptr, alpha, &quarter);
  if (s.partial) {
    // Only the vertices of edges whose matching may have changed.
    std::vector<char> vertex_mask(t.nv, 0);
    for (std::size_t k = 0; k < t.ends.size(); ++k)
      if (s.edge_mask[t.edges[k]]) vertex_mask[t.ends[k][0]] = vertex_mask[t.ends[k][1]] = 1;
    vertex_matchings(&vertex_mask);
  } else {
    vertex_matchings(nullptr);
  }
  s.ealpha = edge_alphas(alpha);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, t.ends.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) s.turns[k] = edge_turns(k);
  });
  if (!s.partial) {
    // Every edge map is read (no locked region): computed here, beside
    // the ordering, with the spanning-tree start.
    compute_edge_maps(s, nullptr);
    bd.field = tt.seconds();
    tt.reset();
    integrate_start(s);
    bd.start = tt.seconds();
  } else {
    bd.field = tt.seconds();
  }
}

/// Edge maps (edge_map) of every live edge, or with `order` only of those
/// touching a free vertex or whose energy is recomputed.
void PeriodicGlobalParameterization::Impl::compute_edge_maps(PgpSolve& s, const std::vector<int>* order) {
  const PgpTopology& t = *s.t;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, t.ends.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      if (!order || s.edge_mask[t.edges[k]] || (*order)[t.ends[k][0]] >= 0 || (*order)[t.ends[k][1]] >= 0)
        s.maps[k] = edge_map(s.turns[k][0], s.turns[k][1], {s.ealpha[k][0], s.ealpha[k][1]});
  });
}

/// Initialisation only: integrate the alphas along a breadth-first spanning
/// tree from each component's reference vertex (locked_vertex, else the
/// lowest), through the frames: exact on the tree edges, the holonomy of the
/// field (what forces singularities) piles up where the tree's branches
/// meet; the relaxation spreads it into vortices.
void PeriodicGlobalParameterization::Impl::integrate_start(PgpSolve& s) {
  if (!s.global) return;
  const PgpTopology& t = *s.t;
  std::vector<std::vector<std::pair<std::uint32_t, std::size_t>>> adj(t.nv);
  for (std::size_t k = 0; k < t.ends.size(); ++k) {
    adj[t.ends[k][0]].push_back({t.ends[k][1], k});
    adj[t.ends[k][1]].push_back({t.ends[k][0], k});
  }
  std::vector<char> seen(t.nv, 0);
  std::vector<St> st(t.nv, St{0, 0});
  std::vector<std::uint32_t> q;
  std::vector<std::uint32_t> roots{opt.locked_vertex};
  for (VertexIndex v : mesh.vertices()) roots.push_back(static_cast<std::uint32_t>(v.idx()));
  for (std::uint32_t v0 : roots) {
    if (seen[v0]) continue;
    seen[v0] = 1;
    q.assign(1, v0);
    for (std::size_t qi = 0; qi < q.size(); ++qi) {
      const std::uint32_t i = q[qi];
      for (auto [j, k] : adj[i]) {
        if (seen[j]) continue;
        seen[j] = 1;
        const int ma = s.turns[k][0], mb = s.turns[k][1];
        if (t.ends[k][0] == i) {
          const St c = turn_st(st[i], -ma);
          st[j] = turn_st({c[0] + s.ealpha[k][0], c[1] + s.ealpha[k][1]}, mb);
        } else {
          const St c = turn_st(st[i], -mb);
          st[j] = turn_st({c[0] - s.ealpha[k][0], c[1] - s.ealpha[k][1]}, ma);
        }
        q.push_back(j);
      }
    }
  }
  for (std::size_t v = 0; v < t.nv; ++v) {
    zs[v] = std::polar(1.0, 2 * M_PI * st[v][0]);
    zt[v] = std::polar(1.0, 2 * M_PI * st[v][1]);
  }
}

/// The sparsity pattern (it depends on the order and the cut parities only;
/// rebuilt only when those changed) beside the edge maps of a local update
/// (only those next to its free vertices).
void PeriodicGlobalParameterization::Impl::build_pattern(PgpSolve& s) {
  const PgpTopology& t = *s.t;
  PgpResult::Breakdown& bd = s.res.breakdown;
  std::vector<std::uint8_t> parity(t.ends.size());
  for (std::size_t k = 0; k < t.ends.size(); ++k)
    parity[k] = static_cast<std::uint8_t>((s.turns[k][0] + s.turns[k][1]) % 2);
  const bool rebuild =
      !pattern || pattern->var != s.var || pattern->parity != parity || pattern->split_st != s.split_st;
  s.same_pattern = analyzed && !rebuild;
  s.res.reused_analysis = s.same_pattern;
  analyzed = s.same_pattern;
  s.shift = opt.stiffness * shift_unit(t);
  tbb::parallel_invoke(
      [&] {
        Timer tt;
        if (rebuild) {
          pattern = std::make_unique<PgpPattern>(make_pattern(t, s.var, s.n, parity, s.split_st));
          pattern->natural = s.natural;
        }
        bd.pattern = tt.seconds();
      },
      [&] {
        if (!s.partial) return;
        Timer tt;
        compute_edge_maps(s, &s.var);
        bd.field += tt.seconds();
      });
}

cholmod_sparse PeriodicGlobalParameterization::Impl::half_matrix(int h) {
  PgpPattern::ComplexHalf& C = pattern->half[static_cast<std::size_t>(h)];
  cholmod_sparse a{};
  a.nrow = a.ncol = static_cast<std::size_t>(pattern->n);
  a.nzmax = C.row.size();
  a.p = C.col.data();
  a.i = C.row.data();
  a.x = C.x.data();
  a.stype = -1;
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_COMPLEX;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;
  return a;
}

/// The pattern's symbolic analysis (skipped when reused) beside the assembly
/// of the values.
void PeriodicGlobalParameterization::Impl::analyze_and_assemble(PgpSolve& s) {
  PgpResult::Breakdown& bd = s.res.breakdown;
  tbb::parallel_invoke(
      [&] {
        Timer tt;
        if (s.n > 0 && !s.same_pattern && s.separate) {
          // The s and t halves' own analyses (no BLAS: beside the assembly).
          std::array<std::string, 2> why;
          for (int h = 0; h < 2; ++h)
            why[static_cast<std::size_t>(h)] = halves[static_cast<std::size_t>(h)].analyze(half_matrix(h))
                                                   ? std::string()
                                                   : std::string("symbolic analysis failed");
          s.failure = !why[0].empty() ? why[0] : why[1];
          factor_size = {halves[0].flops() + halves[1].flops(), halves[0].nonzeros() + halves[1].nonzeros()};
        } else if (s.n > 0 && !s.same_pattern) {
          // Symbolic analysis of the pattern alone (the values come beside).
          solver.analyzePattern(pattern->A);
          if (solver.info() != Eigen::Success) s.failure = "symbolic analysis failed";
          factor_size = {solver.cholmod().fl, solver.cholmod().lnz};
        }
        bd.analysis = tt.seconds();
      },
      [&] {
        Timer tt;
        if (s.n > 0) assemble(s);
        bd.assembly = tt.seconds();
      });
  bd.factor_flops = factor_size[0];
  bd.factor_nonzeros = factor_size[1];
}

/// Real form of F_PGP with s and t coupled (Ray et al. 2006): per vertex
/// x = (Re z_s, Im z_s, Re z_t, Im z_t) in the vertex's own frame; per edge
/// the residual x_j - M x_i with M = P_mj Rot(alpha) P_-mi orthogonal
/// (edge_map): A(i,i) += w I, A(j,j) += w I, A(j,i) = -w M, A(i,j) = -w M^T;
/// lower triangle stored, plus shift * mass on the diagonal. `b` collects
/// the locked neighbours' terms.
void PeriodicGlobalParameterization::Impl::assemble(PgpSolve& s) {
  const PgpTopology& t = *s.t;
  const PgpPattern& P = *pattern;
  const int n = s.n;
  SpMat& A = s.A;
  Eigen::VectorXd &b = s.b, &mass = s.mass;
  A = P.A;
  double* val = A.valuePtr();
  std::fill(val, val + A.nonZeros(), 0.0);
  b = Eigen::VectorXd::Zero(4 * n);
  mass.resize(n);
  for (std::size_t v = 0; v < t.nv; ++v)
    if (P.var[v] >= 0) mass[P.var[v]] = t.mass[v];
  for (std::size_t k = 0; k < t.ends.size(); ++k) {
    const std::uint32_t i = t.ends[k][0], j = t.ends[k][1];
    const int vi = P.var[i], vj = P.var[j];
    if (vi < 0 && vj < 0) continue;
    const double w = t.weight[k];
    const Mat4& M = s.maps[k];
    for (int r = 0; r < 4; ++r) {
      if (vi >= 0) val[P.diag[s.unknown(vi, r)]] += w;
      if (vj >= 0) val[P.diag[s.unknown(vj, r)]] += w;
    }
    if (vi >= 0 && vj >= 0) {
      // Only the parity's entries: the others of M are exact zeros (signed
      // permutations around block-diagonal rotations).
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) {
          const std::ptrdiff_t pos = P.off[k][4 * r + c];
          if (pos >= 0) val[pos] += vj > vi ? -w * M[r][c] : -w * M[c][r];
        }
    } else if (vj >= 0) {
      const Vec4 xi = state(i);
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) b[s.unknown(vj, r)] += w * M[r][c] * xi[c];
    } else {
      const Vec4 xj = state(j);
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) b[s.unknown(vi, r)] += w * M[c][r] * xj[c];
    }
  }
  for (int v = 0; v < n; ++v)
    for (int r = 0; r < 4; ++r) val[P.diag[s.unknown(v, r)]] += s.shift * mass[v];
}

/// Ginzburg-Landau relaxation with one factorisation of F_PGP + mu M:
/// min F + mu sum_i M_i |z_i - u_i|^2, u = z/|z| of the previous iterate
/// (per complex pair), from the tree-integrated start at initialisation,
/// from the previous solution in a local update, locked vertices entering
/// through b. The unit-modulus pull matters: F alone with one locked
/// vertex has a solution decaying away from it (median |z| ~ 3e-3 on
/// fandisk), and F's smallest eigenvector localises where the field's curl
/// is low, its tail not following the field (80% distorted faces on a torus).
void PeriodicGlobalParameterization::Impl::relax(PgpSolve& s) {
  if (s.n <= 0 || !s.failure.empty()) return;
  const PgpTopology& t = *s.t;
  const PgpPattern& P = *pattern;
  Eigen::VectorXd x(4 * s.n);
  for (std::size_t v = 0; v < t.nv; ++v)
    if (P.var[v] >= 0) {
      const Vec4 xv = state(v);
      for (int r = 0; r < 4; ++r) x[s.unknown(P.var[v], r)] = xv[r];
    }
  const int iterations = s.global ? opt.init_iterations : opt.update_iterations;
  if (s.separate)
    relax_halves(s, x, iterations);
  else
    relax_coupled(s, x, iterations);
  if (s.failure.empty()) normalize_solution(s, x);
  s.split(s.res.breakdown.solves);  // (the halves' own times were set before; this adds the write-back)
}

/// The paper's simplified PGP: the s and t systems are independent, and so
/// are their relaxations (each step normalises s pairs and t pairs
/// separately), so each half is factored and relaxed on its own, as the
/// complex Hermitian system its real form stands for (half the real flops of
/// the 2x2 blocks, half the factor's bytes per solve).
void PeriodicGlobalParameterization::Impl::relax_halves(PgpSolve& s, Eigen::VectorXd& x, int iterations) {
  PgpResult::Breakdown& bd = s.res.breakdown;
  std::array<PgpHalfRun, 2> run;
  // Side by side on two tasks where the BLAS allows concurrent calls, in
  // turn otherwise (BlasGuard); independent, so the same bytes either way.
  if (blas_allows_concurrent_calls())
    tbb::parallel_invoke([&] { relax_half(s, 0, x, iterations, run[0]); },
                         [&] { relax_half(s, 1, x, iterations, run[1]); });
  else
    for (int h = 0; h < 2 && run[0].why.empty(); ++h)
      relax_half(s, h, x, iterations, run[static_cast<std::size_t>(h)]);
  s.failure = !run[0].why.empty() ? run[0].why : run[1].why;
  if (blas_allows_concurrent_calls()) {
    bd.factorization = std::max(run[0].factor_seconds, run[1].factor_seconds);
    bd.solves = std::max(run[0].solve_seconds, run[1].solve_seconds);
  } else {
    bd.factorization = run[0].factor_seconds + run[1].factor_seconds;
    bd.solves = run[0].solve_seconds + run[1].solve_seconds;
  }
  bd.steps = std::min(run[0].steps, run[1].steps);
  s.lap.reset();
}

/// Half h (s: 0, t: 1) of the separate-halves relaxation: its values into
/// the complex matrix, its factorisation, then the relaxation steps on its
/// segment of x ((re, im) pairs: the complex right-hand side and solution).
void PeriodicGlobalParameterization::Impl::relax_half(PgpSolve& s, int h, Eigen::VectorXd& x, int iterations,
                                                      PgpHalfRun& run) {
  const int n = s.n;
  Timer th;
  SupernodalHalf& S = halves[static_cast<std::size_t>(h)];
  PgpPattern::ComplexHalf& C = pattern->half[static_cast<std::size_t>(h)];
  const double* val = s.A.valuePtr();
  for (std::size_t q = 0; q < C.re.size(); ++q) {
    C.x[2 * q] = val[C.re[q]];
    C.x[2 * q + 1] = C.im[q] >= 0 ? val[C.im[q]] : 0.0;
  }
  if (!S.factorize(half_matrix(h))) run.why = "factorisation failed (not positive definite?)";
  run.factor_seconds = th.seconds();
  th.reset();
  const int m = 2 * n, off = h * m;
  Eigen::VectorXd xh = x.segment(off, m), rh(m);
  for (int it = 0; it < iterations && run.why.empty(); ++it) {
    for (int v = 0; v < n; ++v) {
      const double re = xh[2 * v], im = xh[2 * v + 1];
      const double a = std::hypot(re, im);
      const bool ok = a > 1e-300 && std::isfinite(a);
      rh[2 * v] = s.b[off + 2 * v] + s.shift * s.mass[v] * (ok ? re / a : 1.0);
      rh[2 * v + 1] = s.b[off + 2 * v + 1] + s.shift * s.mass[v] * (ok ? im / a : 0.0);
    }
    // (re, im) pairs: the complex right-hand side and solution as they are
    if (!S.solve(rh.data(), static_cast<std::size_t>(n), CHOLMOD_COMPLEX, xh.data())) run.why = "solve failed";
    ++run.steps;
  }
  x.segment(off, m) = xh;
  run.solve_seconds = th.seconds();
}

/// The coupled (or split, not separate) system: one factorisation, then the
/// relaxation steps, each normalising every complex pair of x.
void PeriodicGlobalParameterization::Impl::relax_coupled(PgpSolve& s, Eigen::VectorXd& x, int iterations) {
  PgpResult::Breakdown& bd = s.res.breakdown;
  {
    BlasGuard blas_guard;
    solver.factorize(s.A);
  }
  if (solver.info() != Eigen::Success) s.failure = "factorisation failed (not positive definite?)";
  s.split(bd.factorization);
  Eigen::VectorXd rhs(4 * s.n);
  for (int it = 0; it < iterations && s.failure.empty(); ++it) {
    for (int v = 0; v < s.n; ++v)
      for (int p = 0; p < 2; ++p) {
        const int ire = s.unknown(v, 2 * p), iim = s.unknown(v, 2 * p + 1);
        const double re = x[ire], im = x[iim];
        const double a = std::hypot(re, im);
        const bool ok = a > 1e-300 && std::isfinite(a);
        rhs[ire] = s.b[ire] + s.shift * s.mass[v] * (ok ? re / a : 1.0);
        rhs[iim] = s.b[iim] + s.shift * s.mass[v] * (ok ? im / a : 0.0);
      }
    {
      BlasGuard blas_guard;
      x = solver.solve(rhs);
    }
    if (solver.info() != Eigen::Success) s.failure = "solve failed";
    ++bd.steps;
  }
}

/// z_s and z_t of every free vertex from x, normalised to unit modulus.
void PeriodicGlobalParameterization::Impl::normalize_solution(PgpSolve& s, const Eigen::VectorXd& x) {
  const PgpPattern& P = *pattern;
  for (std::size_t v = 0; v < s.t->nv; ++v) {
    if (P.var[v] < 0) continue;
    const int o = P.var[v];
    const Cplx a(x[s.unknown(o, 0)], x[s.unknown(o, 1)]), c(x[s.unknown(o, 2)], x[s.unknown(o, 3)]);
    const double la = std::abs(a), lc = std::abs(c);
    zs[v] = (la > 1e-300 && std::isfinite(la)) ? a / la : Cplx(1, 0);
    zt[v] = (lc > 1e-300 && std::isfinite(lc)) ? c / lc : Cplx(1, 0);
  }
}

/// Energies at the (normalised) solution, in the edge's reference frame:
/// per edge (only edges of free faces change in an update), then a serial
/// sum (deterministic).
void PeriodicGlobalParameterization::Impl::edge_energies(PgpSolve& s) {
  const PgpTopology& t = *s.t;
  edge_energy.resize(t.ends.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, t.ends.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) {
      if (s.partial && !s.edge_mask[t.edges[k]]) continue;
      const std::uint32_t i = t.ends[k][0], j = t.ends[k][1];
      const double w = t.weight[k];
      const Vec4 xi = state(i), xj = state(j);
      Vec4 d{};
      for (int a = 0; a < 4; ++a) {
        d[a] = xj[a];
        for (int c = 0; c < 4; ++c) d[a] -= s.maps[k][a][c] * xi[c];
      }
      d = turn_z(d, -s.turns[k][1]);  // s and t of the edge's reference frame
      edge_energy[k] = {w * (d[0] * d[0] + d[1] * d[1]), w * (d[2] * d[2] + d[3] * d[3])};
    }
  });
  for (const auto& en : edge_energy) {
    s.res.energy_s += en[0];
    s.res.energy_t += en[1];
  }
}

std::vector<char> PeriodicGlobalParameterization::Impl::initial_free_set() {
  const std::size_t nv = mesh.num_vertices();
  // Every vertex with an edge is free; the phase is fixed afterwards.
  const PgpTopology& t = topology();
  std::vector<char> free_vertex(nv, 0);
  for (const auto& ij : t.ends) free_vertex[ij[0]] = free_vertex[ij[1]] = 1;
  // One locked vertex per component (the paper's): locked_vertex for its
  // component, the lowest index otherwise. With s and t coupled through the
  // frames a constant shift of (s,t) is no symmetry any more, so the phase is
  // fixed in the solve instead of afterwards.
  {
    std::vector<char> has(static_cast<std::size_t>(t.components), 0);
    auto lock = [&](std::size_t v) {
      const int c = t.component[v];
      if (c < 0 || has[c]) return;
      has[c] = 1;
      free_vertex[v] = 0;
    };
    lock(opt.locked_vertex);
    for (VertexIndex v : mesh.vertices()) lock(v.idx());
  }
  return free_vertex;
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
  Timer before;
  impl_->zs.assign(nv, Cplx(1, 0));
  impl_->zt.assign(nv, Cplx(1, 0));
  const std::vector<char> free_vertex = impl_->initial_free_set();  // builds the topology on a first call
  const double topology_seconds = before.seconds();
  PgpResult r = impl_->solve(free_vertex, nullptr, true);
  r.breakdown.topology += topology_seconds;
  r.seconds += topology_seconds;
  impl_->initialized = true;
  return r;
}

void PeriodicGlobalParameterization::prepare() {
  Mesh& mesh = impl_->mesh;
  require_triangle_mesh(mesh, "periodic_global_parameterization");
  if (impl_->opt.locked_vertex >= mesh.num_vertices() || mesh.is_removed(VertexIndex(impl_->opt.locked_vertex)))
    return;  // initialize() reports it
  int count = 0;
  std::vector<int> natural = Impl::natural_numbering(mesh, impl_->initial_free_set(), count);
  if (impl_->known_order(natural)) return;  // ordered already
  std::vector<int> var = nested_dissection_order(natural, count, impl_->topology().ends);
  impl_->prepared = std::make_unique<std::pair<std::vector<int>, std::vector<int>>>(std::move(natural), std::move(var));
}

void PeriodicGlobalParameterization::prepare(const EffectArea& area) {
  Mesh& mesh = impl_->mesh;
  if (area.vertex_free.size() != mesh.num_vertices()) return;  // update() reports it
  int count = 0;
  std::vector<int> natural = Impl::natural_numbering(mesh, area.vertex_free, count);
  const PgpTopology& t = impl_->topology();
  if (impl_->known_order(natural)) return;  // same free set as before: ordered already
  std::vector<int> var = nested_dissection_order(natural, count, t.ends);
  impl_->prepared = std::make_unique<std::pair<std::vector<int>, std::vector<int>>>(std::move(natural), std::move(var));
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

std::array<double, 2> PeriodicGlobalParameterization::energies() {
  if (!impl_->initialized)
    throw InvalidInputError("PeriodicGlobalParameterization::energies called before initialize()/set_state()");
  check_options(impl_->opt);
  require_triangle_mesh(impl_->mesh, "periodic_global_parameterization");
  Impl& im = *impl_;
  const PgpTopology& t = im.topology();
  std::vector<FaceGrad> g;
  std::vector<std::array<double, 2>> alpha;
  std::vector<std::uint8_t> quarter;
  face_gradients_into(im.mesh, im.opt, t.frames, nullptr, g, im.corrector());
  halfedge_alphas_into(im.mesh, im.opt, g, t.frames, nullptr, alpha, &quarter);
  const std::vector<std::uint8_t> corner =
      im.opt.swap_coordinates ? corner_matchings(im.mesh, quarter) : std::vector<std::uint8_t>(im.mesh.num_halfedges(), 0);
  std::array<double, 2> out{0, 0};
  for (std::size_t k = 0; k < t.ends.size(); ++k) {
    const HalfedgeIndex h = im.mesh.halfedge(EdgeIndex(t.edges[k]), 0), o = im.mesh.opposite(h);
    const int mi = im.mesh.is_border(h) ? corner[o.idx()] : corner[im.mesh.prev(h).idx()];
    const int mj = im.mesh.is_border(h) ? corner[im.mesh.prev(o).idx()] : corner[h.idx()];
    const std::uint32_t i = t.ends[k][0], j = t.ends[k][1];
    // Residual in the edge's reference frame: P_-mj x_j - R P_-mi x_i.
    const Vec4 xi = turn_z({im.zs[i].real(), im.zs[i].imag(), im.zt[i].real(), im.zt[i].imag()}, -mi);
    const Vec4 xj = turn_z({im.zs[j].real(), im.zs[j].imag(), im.zt[j].real(), im.zt[j].imag()}, -mj);
    const Cplx rs = std::polar(1.0, 2 * M_PI * alpha[h.idx()][0]), rt = std::polar(1.0, 2 * M_PI * alpha[h.idx()][1]);
    out[0] += t.weight[k] * std::norm(Cplx(xj[0], xj[1]) - rs * Cplx(xi[0], xi[1]));
    out[1] += t.weight[k] * std::norm(Cplx(xj[2], xj[3]) - rt * Cplx(xi[2], xi[3]));
  }
  return out;
}

void PeriodicGlobalParameterization::write_corners() {
  if (!impl_->initialized)
    throw InvalidInputError("PeriodicGlobalParameterization::write_corners called before initialize()/set_state()");
  check_options(impl_->opt);
  require_triangle_mesh(impl_->mesh, "periodic_global_parameterization");
  Impl& im = *impl_;
  const PgpTopology& t = im.topology();
  face_gradients_into(im.mesh, im.opt, t.frames, nullptr, im.grad, im.corrector());
  halfedge_alphas_into(im.mesh, im.opt, im.grad, t.frames, nullptr, im.alpha, &im.quarter);
  im.vertex_matchings(nullptr);
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
