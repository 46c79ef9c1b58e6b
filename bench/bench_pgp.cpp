// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark of the material-space mapping steps (Ray et al. 2009, Table 1):
// orientation interpolation, PGP initialisation and a local constraint update
// over ~25% of the triangles, on real meshes of ~11K, ~24K and ~50K triangles.
// Best of 3 runs (wall "seconds", and "cpu_seconds" of all threads of that
// run); one JSON line per mesh and step.
// The first two lines per mesh ("driver_map", "driver_update") time the
// pipeline through texture/material_space/material_mapping.h at the CLI's defaults; the
// step lines after them use the paper table's settings (see driver_figures).
// Usage: bench_pgp [--no-sweep] [--no-swap [--one-system]] [mesh ...]   (default: shared data fandisk,
// dragon_25k, armadillo_52k; --no-sweep skips the singular fraction against
// the period). The PGP steps carry the solver's own wall-time breakdown.
//
// Measured 2026-11-22 on the shared 2-core machine under load 10-13 (wall is
// ~2.5x CPU; quiet-machine figures are for the lead to re-measure),
// wall / CPU seconds (CPU = all threads of the best run):
//   faces                          12.9K           25.0K           52.0K
//   interpolate orientation        0.085 / 0.037   0.144 / 0.061   0.381 / 0.153
//   PGP initialisation             0.196 / 0.083   0.233 / 0.101   0.765 / 0.303
//   local update, total            0.023 / 0.015   0.058 / 0.031   0.220 / 0.087
//     of which orientation         0.009 / 0.005   0.025 / 0.013   0.084 / 0.036
//     of which PGP                 0.011 / 0.007   0.025 / 0.012   0.106 / 0.037
// (previous version, same load: local update 0.35 s wall / ~0.14 s CPU at
// 52K.) Goals: init <= 0.5 s, local update <= 0.1 s: met in CPU time, to be
// confirmed in wall time on a quiet machine. Paper (2009 hardware):
// 1.2/4.1/8.9 s, 1.3/3.7/7.4 s, 0.5-4 s.
// s and t coupled across the field's cuts (vertex frames, real 4x4-block
// system), 2026-11-22, load 4-10, wall / CPU seconds:
//   PGP initialisation   fandisk 1.28 / 0.39 (was 0.083 CPU), dragon_25k
//                        0.82 / 0.45 and armadillo_52k 4.9 / 1.69 with dense
//                        4x4 blocks (before the parity pattern, which halved
//                        fandisk's); armadillo with the parity pattern
//                        15.4 / 1.77 (load ~5, a build alongside): goal of
//                        0.5 s CPU missed, 6x the uncoupled complex solves
//   local update PGP     fandisk 0.028 / 0.016, dragon 0.055 / 0.047 (dense
//                        blocks), armadillo 0.97 / 0.14 (parity pattern)
// Singular fraction at the default period (8 mean edges), curvature field /
// strokes field: fandisk 9.6% / 11.6% (before the coupling 23% / 20%),
// dragon_25k 58% (unchanged: ~800 field-singular vertices), armadillo_52k
// 30% (was 33%). Printed with each figure: field_singular_vertices, cut_edges
// (combed representatives differing by k != 0 quarter turns) and
// distorted_at_cut (distorted faces with a vertex on a cut edge; fandisk
// 157 of 391 after the coupling, 80% before).
// CHOLMOD (issue 5, 2026-11-22, load 7-9 on the shared 2-core machine: wall
// ~1.5-2x CPU; the lead re-measures quietly). armadillo_52k, wall / CPU s:
//   PGP initialisation, best of 3    2.27 / 1.29   (Eigen SimplicialLDLT,
//                                                  same load: 3.35 / 1.61)
//     first call (ordering+analysis)  2.12 / 1.50
//     breakdown (best run, wall): factorisation 1.16 (1.83e9 flops; AMD on
//     the 4n scalar graph: 2.32e9), 16 solves 0.99, field 0.05, corners 0.04
//   local update PGP (25% area)      0.29 / 0.16   (LDLT: 0.40 / 0.16);
//     factorisation 0.19 of it (2.2e8 flops)
// fandisk init 0.29 / 0.27, update 0.025 / 0.026; dragon_25k init
// 0.59 / 0.46, update 0.091 / 0.055. The goals (0.5 s init, 0.1 s update at
// 52K) are not met: the factorisation runs on Debian's netlib BLAS (no
// optimised BLAS installed) at ~1.5 GFlop/s; fewer relaxation steps raise
// the singular fraction (4 steps: armadillo 33.6%, 8: fandisk 9.9%, dragon
// 60.0%; 32: armadillo 28.5%).
// Issue #5 speed goals, session 4 (2026-11-22, load 6-8 on the shared 2-core
// machine throughout: wall figures are noise-dominated, the lead re-measures
// quietly). armadillo_52k, wall / CPU s, before (b24afc5) -> after:
//   PGP init, first call      1.91 / 0.97 -> 1.07 / 0.71 (same bench run
//                             pair; alternating A/B runs spread 0.7-1.7 s
//                             wall for both binaries)
//   PGP init, analysis reused 1.39 / 0.69 -> 0.61 / 0.50
//   min of 8 inits in one process (load ~8): factorisation 0.30-0.41 s with
//   OpenBLAS's generic Prescott kernels -> 0.24 s with its SkylakeX kernels
//   (configure_blas), 16 solves unchanged (~0.23-0.33 s: dtrsv/dgemv,
//   memory-bound)
//   material-map pipeline (armadillo, --render-size 96): total 4.6-4.9 s ->
//   3.2-3.3 s, "pgp" 1.9-2.0 -> 1.0-1.1 s (prepare() beside the curvature
//   and direction field); singular fraction 0.282 both
// What changed: (1) OpenBLAS 0.3.21 does not know this Xeon (AVX-512) and
// ran its generic SSE3 kernels (dgemm 12 GFlop/s; 63 with SkylakeX):
// switched once per process; (2) the METIS order runs beside the field's
// gradients/alphas/matchings, edge maps and spanning-tree start, the
// symbolic analysis beside the assembly, corner matchings in parallel (only
// near the area in an update); (3) prepare()/prepare(area) for callers that
// can start the order earlier (material-map, local_update_whole_*). Same bytes before and
// after (2) and (3); (1) changes the rounding of the factor (the kernels).
// Singular fraction unchanged: fandisk 9.58%, dragon_25k 58.43%,
// armadillo_52k 29.59%.
// Measured and dropped: a threaded OpenBLAS (pthread build, private copy):
// 1, 2, 3, 4 BLAS threads gave four different solutions, no gain under load;
// METIS on the (s,t) double-cover graph (1.49e9 flops, 1.39e9 with 3
// separators per level, vs 1.83e9) costs 2.5-5x the ordering time and
// depends on the field; full 4x4 blocks 2.25e9 flops; CHOLMOD nrelax/zrelax
// variants: no measurable change; METIS NITER 1-10: 0.09-0.11 s either way;
// the two halves of the top separator ordered in parallel: not
// deterministic (METIS draws from libc rand()); stopping the Ginzburg-Landau
// steps early: after 16 steps the mean change of z/|z| per step is still
// 0.019 (0.36 after the first) and |z| is far from 1 for 97% of the
// vertices (stiffness 0.01), so no tolerance stops before 16 without
// changing the result (fewer steps raise the singular fraction, see above).
// Singular faces on armadillo (--field-sweep, diagnosis in the
// detect_singularities line): 55% lie within 3 edges of a field-singular
// vertex; distorted faces are 9.4% of all and their rings triple that.
// Curl correction (issue #5, pgp_curl_correction.h; --curl-only prints one
// line per mesh, period and setting; --curl-correction turns it on for
// the main runs). 2026-11-22, shared machine, load 6.5-7.7 (uptime before /
// after), one --curl-only run 61 s wall / 32 s user. Singular fraction
// (faces with a singular vertex = three-lookup faces) off -> on, curvature
// field, by mean edges per period; in brackets the same with the distortion
// measured against the user's uncorrected g (default max factor 2; the
// second row with max factor 4):
//                   4                    8                    16
//   fandisk         7.4 -> 4.9 (5.6)     9.6 -> 6.8 (8.4)     17.6 -> 14.5 (16.6)
//   dragon_25k     49.1 -> 44.8 (50.6)  58.4 -> 54.3 (58.8)   75.4 -> 72.1 (74.4)
//       max 4            44.6 (50.9)          54.0 (58.9)           71.6 (74.3)
//   armadillo_52k  23.8 -> 16.7 (25.6)  29.6 -> 24.0 (33.2)   47.3 -> 39.7 (50.9)
//       max 4            15.3 (24.5)          23.1 (33.9)           39.6 (51.7)
// Distorted faces alone at 8 edges: fandisk 391 -> 237, dragon 5800 -> 5130,
// armadillo 4899 -> 3978 (of 12.9K, 25.0K, 52.0K). Factor range: fandisk
// 0.52..1.48 (1 vertex clamped), dragon 0.5..2 (417), armadillo 0.5..2
// (1222); with max 4: dragon 0.40..4 (6), armadillo 0.32..4 (99).
// Total |circulation| of the target (periods): fandisk 29.3 -> 22.5,
// armadillo 300.8 -> 283.5, dragon 193.5 -> 201.8 (its ~800 field
// singularities dominate; the per-face curl of the factor's steps adds).
// Cost: the correction with its factorisation reused 0.007 / 0.019 / 0.038-
// 0.047 s CPU (fandisk / dragon / armadillo), one-shot (with the
// factorisation) 0.04 / 0.04-0.16 / 0.15-0.22 s wall; PGP initialisation
// (best of 3) armadillo 0.54-0.57 -> 0.61-0.67 s CPU (about +8%, noisy),
// fandisk 0.122-0.128 -> 0.130. With the correction a local update refreshes
// every face's gradient (the factor is global): local_update_pgp armadillo
// 0.083 -> 0.150 s CPU, dragon 0.032 -> 0.067, fandisk 0.017 -> 0.026
// (--no-sweep runs, load 6).
// Paper's simplified PGP (issue #5, PgpOptions::swap_coordinates false,
// --no-swap: s and t never swapped across the field's cuts, two independent
// systems numbered s half then t half in one METIS order). 2026-11-22,
// shared 2-core machine, load 3.0-3.3 (uptime before/after each run),
// --no-sweep, coupled (default) -> no-swap, wall / CPU s:
//                          fandisk (12.9K)     dragon_25k (25.0K)  armadillo_52k (52.0K)
//   init, first call       0.152/0.150 ->      0.284/0.282 ->      0.651/0.661, 0.697/0.693 ->
//                          0.135/0.136         0.252/0.252         0.565/0.564, 0.578/0.578
//   init, analysis reused  0.103 -> 0.087      0.196 -> 0.154      0.427-0.445 -> 0.364-0.377
//   local update PGP       0.014 -> 0.012      0.028 -> 0.023      0.063-0.066 -> 0.058-0.061
//   factor flops (init)    4.59e8 -> 1.52e8    5.46e8 -> 1.59e8    1.83e9 -> 5.66e8
//   factor nonzeros        2.01e6 -> 1.40e6    3.06e6 -> 1.94e6    7.19e6 -> 4.92e6
//   singular fraction      9.6% -> 22.9%       58.4% -> 58.0%      29.6% -> 33.1%
// (fandisk/dragon from one pair of full runs, armadillo from two pairs of
// armadillo-only runs, CPU = wall there). Armadillo's breakdown, first call:
// factorisation 0.26-0.28 -> 0.19-0.20 s (a third of the flops but smaller
// supernodes: 7 -> 3 GFlop/s), 16 solves 0.17 -> 0.14 s (the factor keeps
// 68% of its nonzeros: the coupled parity pattern was already sparse, and
// the solves are memory-bound), ordering 0.13-0.14 s (unchanged, beside the
// field). The 0.5 s first-call goal at 52K is still missed by ~0.07 s at
// this load, at the price of the coupling's gain on fandisk.
// Issue #5 session 5 (2026-11-22 12:38-13:21 UTC, shared 2-core machine at
// load 6-10 throughout: the process mostly gets one core (CPU ~ wall); CPU
// seconds are the reliable figure, wall for the lead to re-measure
// quietly). --no-swap: the s and t halves now run as two complex Hermitian
// n x n systems (each 2x2 block of a half is a scaled rotation), one after
// the other (PgpOptions::separate_halves; --one-system = the previous
// single real block-diagonal system). Side by side on two TBB tasks they
// would be independent, but Debian's libopenblas0-serial 0.3.21 is not
// safe for concurrent calls (config "OpenBLAS 0.3.21 NO_LAPACKE
// DYNAMIC_ARCH NO_AFFINITY SkylakeX SINGLE_THREADED"; no pthread import;
// blas_memory_alloc claims buffer slots with an unlocked test-and-set,
// blas_memory_free takes no lock: built without USE_LOCKING): the two
// halves factored side by side failed with "not positive definite" in 3 of
// 4 two-thread armadillo runs. Tried and dropped: CHOLMOD's simplicial LL'
// (no BLAS) for one half, 0.16-0.19 s thread CPU against 0.07-0.08 for a
// supernodal half (no gain); a private libcholmod + OpenBLAS copy per half
// (dlmopen): same bytes and safe BLAS, but the second libgomp/libc share the
// threads' pthread-key slots with the first, and a std::thread that ran both
// aborted at exit (libgomp goacc_destroy_thread assertion). Best of 3 per
// bench run, wall / CPU seconds, one real system (--one-system) -> two
// complex halves, final version (halves in turn), 13:19-13:21 UTC, load
// 7.9-10.1 (wall ~2x CPU):
//                          fandisk (12.9K)     dragon_25k (25.0K)  armadillo_52k (52.0K)
//   init, first call       0.25/0.14 ->        0.49/0.26 ->        1.16-1.30/0.64 ->
//                          0.18/0.09           0.41/0.20           0.65-0.84/0.40-0.43
//   init, analysis reused  0.18/0.09 ->        0.33/0.16 ->        0.48-0.81/0.38-0.41 ->
//                          0.09/0.05           0.20/0.10           0.26-0.47/0.23-0.24
//   local update PGP       0.021/0.013 ->      0.052/0.025 ->      0.067-0.14/0.059-0.069 ->
//                          0.013/0.007         0.032/0.016         0.048-0.075/0.034-0.042
//   armadillo breakdown (analysis reused, wall): factorisation 0.19-0.37 ->
//   0.08-0.16, 16 solves 0.19-0.32 -> 0.11-0.19; CHOLMOD's pattern
//   flop count 5.66e8 (real 4n) -> 7.14e7 (two n x n complex patterns, ~4
//   real flops per complex operation: about half the real work). Earlier
//   runs (13:00-13:06, load 6-8, the halves then side by side on the
//   dlmopen'ed copy, effectively one core): armadillo reused 0.30-0.36 /
//   0.23-0.25, first call 0.61-0.66 / 0.44-0.45, update 0.035-0.052 / 0.035.
// Results equal the one-system ones to 7e-14 (fandisk init + update);
// singular fraction unchanged: fandisk 22.90%, dragon_25k 57.96%,
// armadillo_52k 33.08% (--no-swap). The coupled default is unchanged (same
// bytes; this session at load 6-10: armadillo init first call 0.67-1.11 /
// 0.66-0.68, reused 0.44-0.82 / 0.44-0.52, update 0.087-0.15 / 0.077-0.095;
// fandisk 9.58%, dragon 58.43%, armadillo 29.59%). CHOLMOD nrelax/zrelax for the
// no-swap halves ({16,64,256}/{.8,.4,.2}, {8,32,128}/{.8,.2,.1} against the
// default {4,16,48}/{.8,.1,.05}): 0.073-0.079 s thread CPU per half either
// way, within the noise, kept at the defaults.
// Lead, session 5, after the switch to Debian's pthread OpenBLAS (pinned to
// one BLAS thread; safe for concurrent calls, so the no-swap halves run side
// by side: "concurrent_blas": true), quiet machine (load 1.4), 2 threads,
// --no-sweep, best of 3, wall / CPU s:
//                          fandisk (12.9K)     dragon_25k (25.0K)  armadillo_52k (52.0K)
//   coupled (default)
//     init, first call     0.197/0.207         0.359/0.386         0.80-1.00/0.85-1.05 (3 runs)
//     init, reused         0.147/0.149         0.262/0.267         0.58-0.64/0.59-0.66
//     local update total   0.030/0.030         0.057/0.060         0.130/0.134 (PGP 0.091)
//   no-swap (the paper's simplified PGP, section 2.3)
//     init, first call     0.085/0.113         0.170/0.261         0.390/0.588
//     init, reused         0.047/0.089         0.092/0.169         0.200/0.374
//     local update total   0.013/0.018         0.029/0.039         0.068/0.089 (PGP 0.028)
//   interpolate orientation 0.031              0.051               0.127-0.131
// The serial OpenBLAS (LD_LIBRARY_PATH=.../openblas-serial) on the coupled
// armadillo: first call 0.82 s, reused 0.58 s, same bytes (material-map's
// mesh.obj identical). Goals (0.5 s, 0.1 s at 52K): met by the paper's
// simplified PGP (0.39 s, 0.068 s); the coupled default misses both.
#include <nlohmann/json.hpp>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <cstdint>
#include <functional>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "geometry/direction_field.h"
#include "geometry/direction_field_singularities.h"
#include "geometry/mesh_util.h"
#include "geometry/effect_area.h"
#include "geometry/mesh.h"
#include "texture/material_space/periodic_global_parameterization.h"
#include "texture/material_space/pgp_curl_correction.h"
#include "texture/material_space/pgp_singularities.h"
#include "geometry/principal_curvatures.h"
#include "geometry/read_mesh.h"
#include "geometry/scalar_field_interpolation.h"
#include "geometry/timer.h"
#include "texture/material_space/material_mapping.h"

using namespace surftex;

namespace {

// CPU seconds (all threads) of the run with the best wall time.
double g_last_cpu = 0;

double best_of_3(const std::function<void()>& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    Timer t;
    const std::clock_t c0 = std::clock();
    f();
    const double wall = t.seconds();
    if (wall < best) {
      best = wall;
      g_last_cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
    }
  }
  return best;
}

void emit(const std::string& mesh, std::size_t faces, const std::string& step, double s,
          nlohmann::json extra = nlohmann::json::object()) {
  extra["bench"] = "pgp";
  extra["mesh"] = mesh;
  extra["faces"] = faces;
  extra["step"] = step;
  extra["seconds"] = s;
  if (s > 0) extra["cpu_seconds"] = g_last_cpu;
  std::cout << extra.dump() << std::endl;
}

// The PGP's own breakdown of one run (wall seconds per step).
bool g_swap_coordinates = true;  // PgpOptions::swap_coordinates of the run (--no-swap)
bool g_separate_halves = false;  // no-swap solved as two complex systems (not --one-system)

nlohmann::json breakdown(const PgpResult& r) {
  const PgpResult::Breakdown& b = r.breakdown;
  return {{"pgp_seconds", r.seconds},         {"swap_coordinates", g_swap_coordinates}, {"separate_halves", g_separate_halves},         {"topology", b.topology},
          {"field", b.field},                 {"ordering", b.ordering},
          {"pattern", b.pattern},
          {"start", b.start},                 {"assembly", b.assembly},
          {"analysis", b.analysis},           {"factorization", b.factorization},
          {"factor_flops", b.factor_flops},   {"factor_nonzeros", b.factor_nonzeros},
          {"solves", b.solves},               {"steps", b.steps},
          {"energy", b.energy},               {"corners", b.corners},
          {"reused_analysis", r.reused_analysis}, {"free_vertices", r.free_vertices},
          {"blas_core", r.blas_core}, {"concurrent_blas", r.concurrent_blas}};
}

/// Keeps the result of the fastest run (for its breakdown).
void keep_fastest(PgpResult& best, const PgpResult& r) {
  if (best.seconds == 0 || r.seconds < best.seconds) best = r;
}

nlohmann::json singularity_figures(const Mesh& mesh, const PgpSingularities& s) {
  std::size_t distorted = 0, mismatched = 0, sv = 0;
  for (char x : s.distorted_face) distorted += x;
  for (char x : s.mismatched_edge) mismatched += x;
  for (char x : s.singular_vertex) sv += x;
  // The 4-field itself: singular vertices (nonzero index) and cut edges
  // (combed representatives differing by k != 0 quarter turns), and the
  // distorted faces with a vertex on a cut edge.
  std::size_t field_singular = 0, cuts = 0, distorted_at_cut = 0;
  for (int i : direction_field_indices(mesh)) field_singular += i != 0;
  auto dir = mesh.property_map<FaceIndex, Vector3>("f:dir").first;
  std::vector<char> on_cut(mesh.num_vertices(), 0);
  for (EdgeIndex e : mesh.edges()) {
    if (mesh.is_border(e)) continue;
    const HalfedgeIndex h = mesh.halfedge(e, 0), o = mesh.opposite(h);
    const FaceFrame fT = face_frame(mesh, mesh.face(h)), fU = face_frame(mesh, mesh.face(o));
    const Vector3 ev = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
    const double tr = fT.angle_of(dir[mesh.face(h)]) - fT.angle_of(ev) + fU.angle_of(ev);
    const long k = ((long(std::lround((tr - fU.angle_of(dir[mesh.face(o)])) / (M_PI / 2))) % 4) + 4) % 4;
    if (k == 0) continue;
    ++cuts;
    on_cut[mesh.source(h).idx()] = on_cut[mesh.target(h).idx()] = 1;
  }
  for (FaceIndex f : mesh.faces()) {
    if (!s.distorted_face[f.idx()]) continue;
    bool at = false;
    for (VertexIndex v : face_vertices(mesh, f)) at = at || on_cut[v.idx()];
    distorted_at_cut += at;
  }
  return {{"singular_fraction", s.singular_fraction},
          {"distorted_faces", distorted},
          {"distorted_at_cut", distorted_at_cut},
          {"mismatched_edges", mismatched},
          {"singular_vertices", sv},
          {"field_singular_vertices", field_singular},
          {"cut_edges", cuts},
          {"faces", s.singular_face.size()}};
}

/// Where the singular faces are: per distance (in edges, breadth-first over
/// the vertex graph) of a face's nearest vertex to a field-singular vertex,
/// the faces and the singular faces at that distance; and how many singular
/// faces are singular only through mismatched spokes (no distorted face in
/// their vertices' rings).
nlohmann::json singular_face_diagnosis(const Mesh& mesh, const PgpSingularities& s) {
  const std::vector<int> index = direction_field_indices(mesh);
  std::vector<int> dist(mesh.num_vertices(), -1);
  std::vector<std::uint32_t> q;
  for (VertexIndex v : mesh.vertices())
    if (index[v.idx()] != 0) {
      dist[v.idx()] = 0;
      q.push_back(static_cast<std::uint32_t>(v.idx()));
    }
  for (std::size_t i = 0; i < q.size(); ++i) {
    const VertexIndex v(q[i]);
    for (VertexIndex w : CGAL::vertices_around_target(mesh.halfedge(v), mesh))
      if (dist[w.idx()] < 0) {
        dist[w.idx()] = dist[v.idx()] + 1;
        q.push_back(static_cast<std::uint32_t>(w.idx()));
      }
  }
  const int bounds[] = {1, 2, 4, 8, 16, 1 << 30};
  std::vector<std::size_t> faces(6, 0), singular(6, 0), distorted(6, 0);
  std::vector<char> ring_distorted(mesh.num_vertices(), 0);
  for (FaceIndex f : mesh.faces())
    if (s.distorted_face[f.idx()])
      for (VertexIndex v : face_vertices(mesh, f)) ring_distorted[v.idx()] = 1;
  std::size_t mismatch_only = 0;
  for (FaceIndex f : mesh.faces()) {
    int d = 1 << 30;
    bool any_ring_distorted = false;
    for (VertexIndex v : face_vertices(mesh, f)) {
      if (dist[v.idx()] >= 0) d = std::min(d, dist[v.idx()]);
      any_ring_distorted = any_ring_distorted || (s.singular_vertex[v.idx()] && ring_distorted[v.idx()]);
    }
    int b = 0;
    while (d >= bounds[b]) ++b;
    ++faces[b];
    singular[b] += s.singular_face[f.idx()];
    distorted[b] += s.distorted_face[f.idx()];
    mismatch_only += s.singular_face[f.idx()] && !any_ring_distorted;
  }
  nlohmann::json rows = nlohmann::json::array();
  const char* names[] = {"0", "1", "2-3", "4-7", "8-15", ">=16"};
  for (int b = 0; b < 6; ++b)
    rows.push_back({{"distance", names[b]}, {"faces", faces[b]}, {"singular", singular[b]},
                    {"distorted", distorted[b]}});
  return {{"by_distance_to_field_singularity", rows}, {"singular_by_mismatch_only", mismatch_only}};
}

/// Sum over faces of |circulation| of the target gradients (s and t), in
/// periods: the misfit the PGP must absorb (0 for a gradient field).
double total_circulation(const Mesh& mesh, const PgpOptions& o) {
  double sum = 0;
  for (const auto& c : pgp_face_circulation(mesh, o)) sum += std::abs(c[0]) + std::abs(c[1]);
  return sum;
}

/// Singular fraction, curl and PGP initialisation time without and with the
/// curl correction (Ray et al. 2006), at `edges_per_period`, on the field in
/// place. The distortion test of section 3 is run against the target the PGP
/// followed ("singular_fraction", charts consistent with the solve) and
/// against the user's uncorrected g ("vs_user_field").
void curl_correction_figures(Mesh& mesh, const std::string& name, double edges_per_period) {
  const std::size_t nf = mesh.number_of_faces();
  interpolate_scalar_field(mesh, {{0, pgp_default_scale(mesh, edges_per_period)}}, scale_field_options());
  for (int on = 0; on < 2; ++on) {
    PgpOptions o;
    o.curl_correction = on != 0;
    nlohmann::json pre = nlohmann::json::object();
    if (on) {
      Timer tc;
      PgpCurlCorrectionOptions co;
      co.stiffness = o.curl_stiffness;
      co.max_factor = o.curl_max_factor;
      const PgpCurlCorrection c = pgp_curl_correction(mesh, co);
      pre["correction_seconds_one_shot"] = tc.seconds();
      PgpCurlCorrector reused(co);
      reused.compute(mesh);
      pre["correction_seconds_reused"] = best_of_3([&] { reused.compute(mesh); });
      pre["correction_cpu_seconds_reused"] = g_last_cpu;
      pre["factor_min"] = c.min_factor;
      pre["factor_max"] = c.max_factor;
      pre["clamped_vertices"] = c.clamped_vertices;
    }
    PeriodicGlobalParameterization p(mesh, o);
    p.initialize();  // ordering and analysis paid once, as in the best of 3 above
    PgpResult best;
    const double t = best_of_3([&] { keep_fastest(best, p.initialize()); });
    PgpSingularityOptions so;
    so.pgp = o;
    nlohmann::json fig = singularity_figures(mesh, detect_pgp_singularities(mesh, so));
    fig["diagnosis"] = singular_face_diagnosis(mesh, detect_pgp_singularities(mesh, so));
    PgpSingularityOptions user;
    user.pgp.curl_correction = false;
    const PgpSingularities su = detect_pgp_singularities(mesh, user);
    std::size_t du = 0;
    for (char x : su.distorted_face) du += x;
    fig["vs_user_field"] = {{"singular_fraction", su.singular_fraction}, {"distorted_faces", du}};
    fig["circulation"] = total_circulation(mesh, o);
    PgpOptions uncorrected;
    uncorrected.curl_correction = false;
    fig["circulation_uncorrected"] = total_circulation(mesh, uncorrected);
    fig.update(pre);
    fig["curl_correction"] = on != 0;
    fig["edges_per_period"] = edges_per_period;
    fig["breakdown"] = breakdown(best);
    emit(name, nf, "curl_correction", t, fig);
  }
}

/// The material-map pipeline as the CLI and the demo run it (texture/
/// material_mapping.h at its defaults: curvature field from the 10% most
/// anisotropic faces smoothed, 8 mean edges per period, coupled PGP), beside
/// the paper-table steps above (their own settings: 5% of the faces, no
/// smoothing, as Table 1 times the steps separately). The update re-solves
/// a material constraint's effect area of a quarter of the bounding-box
/// diagonal around vertex n/3.
void driver_figures(const std::string& path, const std::string& name) {
  Mesh mesh;
  read_mesh(path, mesh);
  const std::size_t nf = mesh.number_of_faces();
  MaterialMappingResult map_result;
  const double t_map = best_of_3([&] {
    MaterialMapping m(mesh);
    map_result = m.map({});
  });
  nlohmann::json fig = to_json(map_result);
  fig["settings"] = "cli_defaults";
  emit(name, nf, "driver_map", t_map, fig);
  MaterialMapping m(mesh);
  m.map({});
  Point3 lo = mesh.point(*mesh.vertices().begin()), hi = lo;
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    lo = Point3(std::min(lo.x(), p.x()), std::min(lo.y(), p.y()), std::min(lo.z(), p.z()));
    hi = Point3(std::max(hi.x(), p.x()), std::max(hi.y(), p.y()), std::max(hi.z(), p.z()));
  }
  MaterialConstraints c;
  const auto seed = static_cast<std::uint32_t>(mesh.number_of_vertices() / 3);
  c.material = {{seed, 1.0}};
  c.seed_vertices = {seed};
  c.effect_radius = 0.25 * std::sqrt(CGAL::squared_distance(lo, hi));
  MaterialMappingResult up;
  const double t_up = best_of_3([&] { up = m.update(c); });
  fig = to_json(up);
  fig["settings"] = "cli_defaults";
  emit(name, nf, "driver_update", t_up, fig);
}

// The command line: flags, then the meshes (default: fandisk, dragon_25k,
// armadillo_52k of the shared data).
struct BenchArgs {
  std::vector<std::string> meshes;
  bool sweep = true, field_sweep = false, curl_only = false;
  PgpOptions pgp_options;  // the defaults (curl correction off) unless --curl-correction
};

BenchArgs parse_args(int argc, char** argv) {
  BenchArgs a;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--no-sweep")
      a.sweep = false;
    else if (std::string(argv[i]) == "--curl-only")
      a.curl_only = true;
    else if (std::string(argv[i]) == "--curl-correction")
      a.pgp_options.curl_correction = true;
    else if (std::string(argv[i]) == "--no-swap")
      a.pgp_options.swap_coordinates = false;  // the paper's simplified PGP (section 2.3)
    else if (std::string(argv[i]) == "--one-system")
      a.pgp_options.separate_halves = false;  // with --no-swap: one block-diagonal CHOLMOD system
    else if (std::string(argv[i]) == "--field-sweep")
      a.field_sweep = true;
    else
      a.meshes.push_back(argv[i]);
  }
  if (a.meshes.empty()) {
    const std::string d = std::string(SURFTEX_SHARED_DATA_DIR) + "/meshes/";
    a.meshes = {d + "fandisk.off", d + "dragon_25k.off", d + "armadillo_52k.off"};
  }
  return a;
}

// One mesh's runs: its name and face count for every line, and the PGP
// options of the run.
struct MeshRun {
  std::string name;
  std::size_t nf = 0;
  PgpOptions pgp_options;
  PgpSingularityOptions sing_options;
};

// Principal curvatures, then the orientation field interpolated from sparse
// strokes and from the principal directions `curv` returns (5% of faces).
std::vector<DirectionConstraint> orientation_figures(Mesh& mesh, const MeshRun& run,
                                                     const std::vector<DirectionConstraint>& strokes) {
  emit(run.name, run.nf, "principal_curvatures", best_of_3([&] { compute_principal_curvatures(mesh); }));
  std::vector<DirectionConstraint> curv = constraints_from_principal_directions(mesh, 0.05);
  emit(run.name, run.nf, "interpolate_orientation",
       best_of_3([&] { interpolate_direction_field(mesh, strokes, {}); }), {{"constraints", strokes.size()}});
  emit(run.name, run.nf, "interpolate_orientation_from_curvature",
       best_of_3([&] { interpolate_direction_field(mesh, curv, {}); }), {{"constraints", curv.size()}});
  return curv;
}

// PGP initialisation: the first call pays the ordering and the symbolic
// analysis (one-shot runs such as the CLI's); the best of 3 reuses them.
// Then the singularity detection on the result.
void initialization_figures(Mesh& mesh, const MeshRun& run, PeriodicGlobalParameterization& pgp) {
  PgpResult init;
  Timer t_first;
  const std::clock_t c_first = std::clock();
  const PgpResult first = pgp.initialize();
  g_last_cpu = double(std::clock() - c_first) / CLOCKS_PER_SEC;
  emit(run.name, run.nf, "pgp_initialize_first_call", t_first.seconds(), {{"breakdown", breakdown(first)}});
  const double t_init = best_of_3([&] { keep_fastest(init, pgp.initialize()); });
  emit(run.name, run.nf, "pgp_initialize", t_init, {{"breakdown", breakdown(init)}});
  PgpSingularities sing;
  const double t_sing = best_of_3([&] { sing = detect_pgp_singularities(mesh, run.sing_options); });
  nlohmann::json fig = singularity_figures(mesh, sing);
  fig["diagnosis"] = singular_face_diagnosis(mesh, sing);
  emit(run.name, run.nf, "detect_singularities", t_sing, fig);
}

// Local update (Ray et al. 2009, Table 1): an effect area of 25% of the
// faces around vertex `seed`; orientation, scale and PGP re-solved there,
// each timed, and their total.
void local_update_figures(Mesh& mesh, const MeshRun& run, PeriodicGlobalParameterization& pgp, double period,
                          const EffectAreaOptions& eo, std::uint32_t seed) {
  const std::string& name = run.name;
  const std::size_t nf = run.nf;
  EffectArea area;
  const double t_area = best_of_3([&] { area = compute_effect_area(mesh, {seed}, eo); });
  emit(name, nf, "effect_area", t_area, {{"area_faces", area.free_faces}});
  const std::uint32_t cf = static_cast<std::uint32_t>(mesh.face(mesh.halfedge(VertexIndex(seed))).idx());
  DirectionFieldOptions dopt;
  dopt.area = &area;
  ScalarFieldOptions sopt = scale_field_options();
  sopt.area = &area;
  double t_dir = 0, t_scale = 0, t_pgp = 0;
  PgpResult last;
  double cpu_total = 0;
  t_dir = best_of_3([&] { interpolate_direction_field(mesh, {{cf, {0.0, 1.0, 1.0}}}, dopt); });
  emit(name, nf, "local_update_orientation", t_dir, {{"area_faces", area.free_faces}});
  cpu_total += g_last_cpu;
  t_scale = best_of_3([&] { interpolate_scalar_field(mesh, {{seed, 0.7 * period}}, sopt); });
  emit(name, nf, "local_update_scale", t_scale, {{"area_faces", area.free_faces}});
  cpu_total += g_last_cpu;
  {
    Timer t_first;
    const std::clock_t c_first = std::clock();
    const PgpResult first = pgp.update(area);
    g_last_cpu = double(std::clock() - c_first) / CLOCKS_PER_SEC;
    emit(name, nf, "local_update_pgp_first_call", t_first.seconds(), {{"breakdown", breakdown(first)}});
  }
  t_pgp = best_of_3([&] { keep_fastest(last, pgp.update(area)); });
  emit(name, nf, "local_update_pgp", t_pgp,
       {{"area_faces", area.free_faces}, {"breakdown", breakdown(last)}});
  cpu_total += g_last_cpu;
  g_last_cpu = cpu_total;
  emit(name, nf, "local_update_total", t_dir + t_scale + t_pgp, {{"area_faces", area.free_faces}});
}

// The whole update as one timed run, as the pipeline (material-map
// --update) does it: orientation, scale and the PGP's order of the area's
// free vertices (PeriodicGlobalParameterization::prepare(area)) side by side
// (independent), then the PGP. "new_area": each of the 3 runs a new
// constraint at another seed vertex, hence another effect area (ordering,
// pattern and symbolic analysis redone: the PGP's first-call path);
// "same_area": the area of the first run again (analysis reused).
void whole_update_figures(Mesh& mesh, const MeshRun& run, PeriodicGlobalParameterization& pgp, double period,
                          const EffectAreaOptions& eo, std::uint32_t seed) {
  PgpResult last_whole;
  auto whole = [&](std::uint32_t s) {
    const EffectArea a2 = compute_effect_area(mesh, {s}, eo);
    DirectionFieldOptions d2;
    d2.area = &a2;
    ScalarFieldOptions s2 = scale_field_options();
    s2.area = &a2;
    const std::uint32_t f2 = static_cast<std::uint32_t>(mesh.face(mesh.halfedge(VertexIndex(s))).idx());
    tbb::parallel_invoke(
        [&] {
          interpolate_direction_field(mesh, {{f2, {0.0, 1.0, 1.0}}}, d2);
        },
        [&] {
          interpolate_scalar_field(mesh, {{s, 0.7 * period}}, s2);
        },
        [&] { pgp.prepare(a2); });
    last_whole = pgp.update(a2);
  };
  int k = 0;
  const std::uint32_t nvtx = static_cast<std::uint32_t>(mesh.number_of_vertices());
  const double t_new = best_of_3([&] { whole((seed + (++k) * (nvtx / 7)) % nvtx); });
  emit(run.name, run.nf, "local_update_whole_new_area", t_new,
       {{"note", "effect area inside the timer; orientation || scale || PGP order, then PGP"},
        {"breakdown", breakdown(last_whole)}});
  whole(seed);
  const double t_same = best_of_3([&] { whole(seed); });
  emit(run.name, run.nf, "local_update_whole_same_area", t_same, {{"breakdown", breakdown(last_whole)}});
}

// Singular fraction against the curvature field's smoothness: jet-fitting
// rings and the fraction of faces constrained (8 edges per period).
void field_sweep_figures(Mesh& mesh, const MeshRun& run) {
  for (int rings : {2, 4})
    for (double fraction : {0.05, 0.1})
      for (double smoothing : {0.0, 4.0, 16.0, 64.0}) {
        PrincipalCurvatureOptions co;
        co.rings = rings;
        co.max_rings = std::max(co.max_rings, rings);
        compute_principal_curvatures(mesh, co);
        DirectionFieldOptions fo;
        fo.smoothing = smoothing;
        interpolate_direction_field(mesh, constraints_from_principal_directions(mesh, fraction), fo);
        interpolate_scalar_field(mesh, {{0, pgp_default_scale(mesh, 8.0)}}, scale_field_options());
        PeriodicGlobalParameterization p2(mesh, run.pgp_options);
        p2.initialize();
        nlohmann::json fig = singularity_figures(mesh, detect_pgp_singularities(mesh, run.sing_options));
        fig["rings"] = rings;
        fig["constrained_fraction"] = fraction;
        fig["smoothing"] = smoothing;
        emit(run.name, run.nf, "singular_fraction_vs_curvature_field", 0.0, fig);
      }
}

// Singular fraction against the period (in mean edge lengths), the field
// interpolated from the strokes and from the 5% most anisotropic faces'
// principal directions.
void period_sweep_figures(Mesh& mesh, const MeshRun& run, const std::vector<DirectionConstraint>& strokes,
                          const std::vector<DirectionConstraint>& curv) {
  for (int field = 0; field < 2; ++field)
    for (double k : {4.0, 8.0, 16.0}) {
      interpolate_direction_field(mesh, field ? curv : strokes, {});
      interpolate_scalar_field(mesh, {{0, pgp_default_scale(mesh, k)}}, scale_field_options());
      PeriodicGlobalParameterization p2(mesh, run.pgp_options);
      p2.initialize();
      nlohmann::json fig = singularity_figures(mesh, detect_pgp_singularities(mesh, run.sing_options));
      fig["edges_per_period"] = k;
      fig["field"] = field ? "curvature" : "strokes";
      emit(run.name, run.nf, "singular_fraction_vs_period", 0.0, fig);
    }
}

// Every figure of one mesh: the pipeline at the CLI's defaults, then the
// paper table's steps (or only the curl-correction figures).
void bench_mesh(const std::string& path, const BenchArgs& args) {
  const std::string name = path.substr(path.find_last_of('/') + 1);
  driver_figures(path, name);
  Mesh mesh;
  read_mesh(path, mesh);
  MeshRun run;
  run.name = name;
  run.nf = mesh.number_of_faces();
  run.pgp_options = args.pgp_options;
  run.sing_options.pgp = args.pgp_options;
  // Sparse strokes: 20 faces spread over the mesh with a projected direction.
  std::vector<DirectionConstraint> strokes;
  for (std::size_t i = 0; i < 20; ++i)
    strokes.push_back({static_cast<std::uint32_t>(i * run.nf / 20), {1.0, 0.3, 0.2}});
  if (args.curl_only) {
    // The curvature field of the runs below, then only the curl figures.
    compute_principal_curvatures(mesh);
    interpolate_direction_field(mesh, constraints_from_principal_directions(mesh, 0.05), {});
    for (double k : {4.0, 8.0, 16.0}) curl_correction_figures(mesh, name, k);
    return;
  }
  const std::vector<DirectionConstraint> curv = orientation_figures(mesh, run, strokes);
  interpolate_scalar_field(mesh, {{0, 1.0}}, scale_field_options());
  // Scale: the default period, 8 mean edge lengths (pgp_default_scale).
  const double period = pgp_default_scale(mesh, 8.0);
  interpolate_scalar_field(mesh, {{0, period}}, scale_field_options());
  interpolate_scalar_field(mesh, {{0, 0.0}, {static_cast<std::uint32_t>(mesh.number_of_vertices() / 2), 1.0}},
                           material_field_options());
  PeriodicGlobalParameterization pgp(mesh, args.pgp_options);
  initialization_figures(mesh, run, pgp);
  EffectAreaOptions eo;
  eo.max_faces = run.nf / 4;
  const std::uint32_t seed = static_cast<std::uint32_t>(mesh.number_of_vertices() / 3);
  local_update_figures(mesh, run, pgp, period, eo, seed);
  whole_update_figures(mesh, run, pgp, period, eo, seed);
  if (args.field_sweep) field_sweep_figures(mesh, run);
  if (args.sweep) period_sweep_figures(mesh, run, strokes, curv);
}

}  // namespace

int main(int argc, char** argv) {
  const BenchArgs args = parse_args(argc, argv);
  g_swap_coordinates = args.pgp_options.swap_coordinates;
  g_separate_halves = !args.pgp_options.swap_coordinates && args.pgp_options.separate_halves;
  for (const std::string& path : args.meshes) bench_mesh(path, args);
  return 0;
}
