// SPDX-License-Identifier: AGPL-3.0-or-later
// Two-pass Efros-Leung synthesis (Gorla et al. 2003, 3.3, 3.3.2, 5).
#include "texture/efros_leung.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <queue>
#include <random>
#include <string>
#include <utility>

#include "geometry/errors.h"
#include "geometry/timer.h"
#include "texture/partial_neighbourhood_index.h"
#include "texture/rotated_exemplars.h"

namespace surftex {
namespace {

using Scored = std::pair<float, int>;  // (error, candidate position); compared lexicographically
constexpr int kLanes = 8;
constexpr std::size_t kPad = 4 * kLanes;

// Pass-1 kernel: unweighted SSD of `len` consecutive candidate positions
// starting at buffer index `row`, over `nk` known neighbours (buffer offsets
// delta[k], values tv[k * C + c]), written to out[0..len). Candidates are
// processed 8 at a time in one vector register (GCC vector extension), so
// the accumulators never leave the registers; every lane performs the same
// operations in the same order, so the result does not depend on the
// instruction set picked at run time (no FMA contraction: the project builds
// with -std=c++17, i.e. -ffp-contract=off). Even and odd neighbours go to two
// accumulators, and the channels of one neighbour are summed as a tree, so
// that the loop is bound by throughput, not by the latency of one chain of
// additions.
typedef float V8 __attribute__((vector_size(kLanes * sizeof(float))));
typedef int I8 __attribute__((vector_size(kLanes * sizeof(int))));

// acc += sum over channels of (planes[c][base] - t[c])^2, 8 lanes.
template <int C>
__attribute__((always_inline)) inline void add_neighbour_sq(V8& acc, const float* base,
                                                            std::size_t plane_size, const float* t) {
  V8 v0;
  std::memcpy(&v0, base, sizeof(V8));
  const V8 d0 = v0 - t[0];
  if constexpr (C == 1) {
    acc += d0 * d0;
  } else {
    V8 v1;
    std::memcpy(&v1, base + plane_size, sizeof(V8));
    const V8 d1 = v1 - t[1];
    V8 s = d0 * d0 + d1 * d1;
    if constexpr (C >= 3) {
      V8 v2;
      std::memcpy(&v2, base + 2 * plane_size, sizeof(V8));
      const V8 d2 = v2 - t[2];
      V8 s2 = d2 * d2;
      if constexpr (C == 4) {
        V8 v3;
        std::memcpy(&v3, base + 3 * plane_size, sizeof(V8));
        const V8 d3 = v3 - t[3];
        s2 += d3 * d3;
      }
      s += s2;
    }
    acc += s;
  }
}

template <int C>
__attribute__((always_inline)) inline void span_ssd_impl(const float* planes, std::size_t plane_size,
                                                         const int* delta, const float* tv, int nk,
                                                         int len, std::size_t row, float* out) {
  for (int i = 0; i < len; i += kLanes) {
    const float* p = planes + row + i;
    V8 acc0 = {}, acc1 = {};
    int k = 0;
    for (; k + 2 <= nk; k += 2) {
      add_neighbour_sq<C>(acc0, p + delta[k], plane_size, tv + k * C);
      add_neighbour_sq<C>(acc1, p + delta[k + 1], plane_size, tv + (k + 1) * C);
    }
    if (k < nk) add_neighbour_sq<C>(acc0, p + delta[k], plane_size, tv + k * C);
    const V8 acc = acc0 + acc1;
    // Never past out[len): spans of different threads are adjacent in out.
    std::memcpy(out + i, &acc, sizeof(float) * std::min(kLanes, len - i));
  }
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define SURFTEX_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define SURFTEX_SIMD_CLONES
#endif

SURFTEX_SIMD_CLONES void span_ssd_c1(const float* p, std::size_t ps, const int* d, const float* t,
                                     int nk, int len, std::size_t row, float* out) {
  span_ssd_impl<1>(p, ps, d, t, nk, len, row, out);
}
SURFTEX_SIMD_CLONES void span_ssd_c3(const float* p, std::size_t ps, const int* d, const float* t,
                                     int nk, int len, std::size_t row, float* out) {
  span_ssd_impl<3>(p, ps, d, t, nk, len, row, out);
}
SURFTEX_SIMD_CLONES void span_ssd_c4(const float* p, std::size_t ps, const int* d, const float* t,
                                     int nk, int len, std::size_t row, float* out) {
  span_ssd_impl<4>(p, ps, d, t, nk, len, row, out);
}
// Short-list kernel: the unweighted SSD of one candidate `id` over the nk
// known first-pass neighbours, summed in the order (neighbour, channel) one
// term at a time (the value is the same float whichever C path runs). When
// the partial sum passes `stop` the candidate is abandoned and the partial
// sum, already > stop, is returned: partial sums of squares never decrease,
// so its full error would exceed stop too.
template <int C>
inline float short_list_ssd(const float* P, std::size_t ps, int Cr, const int* delta, const float* tv, int nk,
                            int id, float stop) {
  const int ch = C > 0 ? C : Cr;
  float e = 0;
  for (int k = 0; k < nk; ++k) {
    const float* base = P + id + delta[k];
    for (int c = 0; c < ch; ++c) {
      const float d = base[c * ps] - tv[k * ch + c];
      e += d * d;
    }
    if (e > stop) return e;
  }
  return e;
}

// The lanes of a summed in lane order.
__attribute__((always_inline)) inline float lane_sum(const V8& a) {
  float e = 0.f;
  for (int l = 0; l < kLanes; ++l) e += a[l];
  return e;
}

// Pass-2 kernel: Gaussian-weighted SSD of the candidates ids[0..count),
// into out. The window is stored per active row as nv groups of 8 offsets
// starting at buffer offset roff[r]; weights are 0 at unknown offsets (and
// past the window), so they contribute exactly 0, and groups without a known
// offset (bit g of gmask[r] clear) are skipped: adding +0 changes no sum.
// Even and odd rows go to two accumulators; lanes are summed in a fixed
// order at the end.
template <int C>
__attribute__((always_inline)) inline void weighted_ssd_impl(const float* planes,
                                                             std::size_t plane_size, int Cr,
                                                             const int* roff, const unsigned* gmask,
                                                             const float* w, const float* t, int nrows,
                                                             int nv, const int* ids, std::size_t count,
                                                             float* out) {
  const int ch = C > 0 ? C : Cr;
  // Two candidates at a time share the loads of the weights and the window;
  // each candidate's arithmetic is the same, in the same order, as alone (an
  // odd last one is scored as both of a pair, its copy's result dropped).
  for (std::size_t j = 0; j < count; j += 2) {
    const bool pair = j + 1 < count;
    const int ia = ids[j], ib = pair ? ids[j + 1] : ia;
    V8 acc_a[2] = {{}, {}}, acc_b[2] = {{}, {}};
    for (int r = 0; r < nrows; ++r)
      for (int g = 0; g < nv; ++g) {
        if (!((gmask[r] >> g) & 1u)) continue;
        const std::size_t o = static_cast<std::size_t>(r) * nv + g;
        V8 wv;
        std::memcpy(&wv, w + o * kLanes, sizeof(V8));
        V8 sa = {}, sb = {};
        for (int c = 0; c < ch; ++c) {
          V8 va, vb, tv;
          const float* plane = planes + c * plane_size;
          std::memcpy(&va, plane + ia + roff[r] + g * kLanes, sizeof(V8));
          std::memcpy(&vb, plane + ib + roff[r] + g * kLanes, sizeof(V8));
          std::memcpy(&tv, t + ((static_cast<std::size_t>(r) * ch + c) * nv + g) * kLanes,
                      sizeof(V8));
          const V8 da = va - tv, db = vb - tv;
          sa += da * da;
          sb += db * db;
        }
        acc_a[r & 1] += wv * sa;
        acc_b[r & 1] += wv * sb;
      }
    out[j] = lane_sum(acc_a[0] + acc_a[1]);
    if (pair) out[j + 1] = lane_sum(acc_b[0] + acc_b[1]);
  }
}
#define SURFTEX_WEIGHTED_ARGS                                                                 \
  const float *p, std::size_t ps, const int *ro, const unsigned *gm, const float *w, const float *t, int nr, int nv, \
      const int *ids, std::size_t count, float *out
SURFTEX_SIMD_CLONES void weighted_ssd_c1(SURFTEX_WEIGHTED_ARGS) {
  weighted_ssd_impl<1>(p, ps, 1, ro, gm, w, t, nr, nv, ids, count, out);
}
SURFTEX_SIMD_CLONES void weighted_ssd_c3(SURFTEX_WEIGHTED_ARGS) {
  weighted_ssd_impl<3>(p, ps, 3, ro, gm, w, t, nr, nv, ids, count, out);
}
SURFTEX_SIMD_CLONES void weighted_ssd_c4(SURFTEX_WEIGHTED_ARGS) {
  weighted_ssd_impl<4>(p, ps, 4, ro, gm, w, t, nr, nv, ids, count, out);
}
void weighted_ssd_any(int C, SURFTEX_WEIGHTED_ARGS) {
  weighted_ssd_impl<0>(p, ps, C, ro, gm, w, t, nr, nv, ids, count, out);
}
#undef SURFTEX_WEIGHTED_ARGS

// Appends (e[i], ids[i]) for every i < N with e[i] <= T to out (room for N
// entries); returns the new end. Tests 8 errors at a time and only looks at single lanes when one
// of the 8 passes (a few percent of the groups).
SURFTEX_SIMD_CLONES std::pair<float, int>* collect_at_most(const float* e, const int* ids,
                                                           std::size_t N, float T,
                                                           std::pair<float, int>* out) {
  V8 t;
  for (int l = 0; l < kLanes; ++l) t[l] = T;
  std::size_t i = 0;
  for (; i + kLanes <= N; i += kLanes) {
    V8 v;
    std::memcpy(&v, e + i, sizeof(V8));
    I8 m = v <= t;  // -1 in lanes <= T
    m |= __builtin_shuffle(m, I8{4, 5, 6, 7, 0, 1, 2, 3});
    m |= __builtin_shuffle(m, I8{2, 3, 0, 1, 6, 7, 4, 5});
    m |= __builtin_shuffle(m, I8{1, 0, 3, 2, 5, 4, 7, 6});
    if (!m[0]) continue;
    for (int l = 0; l < kLanes; ++l) {  // branch-free: write, keep if <= T
      *out = {e[i + l], ids[i + l]};
      out += e[i + l] <= T;
    }
  }
  for (; i < N; ++i)
    if (e[i] <= T) *out++ = {e[i], ids[i]};
  return out;
}

// Any channel count: accumulate channel by channel (C = 2 or > 4).
void span_ssd_any(const float* p, std::size_t ps, int C, const int* d, const float* t, int nk,
                  int len, std::size_t row, float* out) {
  std::fill(out, out + len, 0.f);
  for (int k = 0; k < nk; ++k)
    for (int c = 0; c < C; ++c) {
      const float* src = p + c * ps + row + d[k];
      const float tv = t[k * C + c];
      for (int i = 0; i < len; ++i) {
        const float x = src[i] - tv;
        out[i] += x * x;
      }
    }
}

int lo_of(int n) { return -(n / 2); }
int hi_of(int n) { return n - 1 - n / 2; }

// One (exemplar, orientation) pair prepared for searching: channel planes of
// the (rotated, padded) exemplar, and the candidate centres as row spans.
struct SearchImage {
  int pw = 0, ph = 0, channels = 0;
  std::vector<float> planes;  // channels planes of pw*ph
  struct Span {
    int y, x0, x1;  // centres (x0..x1-1, y)
  };
  std::vector<Span> spans;
  std::vector<int> span_first;  // per span: index in ids of its first candidate
  std::vector<int> ids;  // every candidate position y*pw+x, increasing
  // Span blocks of roughly equal size for the parallel pass 1.
  std::vector<std::pair<int, int>> blocks;
  int max_span = 0;
  std::vector<std::uint8_t> is_candidate;  // per buffer position: 1 = a candidate centre
  // Periodic exemplars: the candidate centres are one period, [margin,
  // margin + core_w) x [margin, margin + core_h); positions outside it are
  // the same neighbourhoods shifted by a period.
  bool periodic = false;
  int margin = 0, core_w = 0, core_h = 0;
  /// The candidate centre equivalent to buffer position c, or -1.
  int candidate_at(long long c) const {
    if (periodic) {
      if (c < 0 || c >= static_cast<long long>(pw) * ph) return -1;
      int x = static_cast<int>(c % pw) - margin, y = static_cast<int>(c / pw) - margin;
      x = ((x % core_w) + core_w) % core_w;
      y = ((y % core_h) + core_h) % core_h;
      return (y + margin) * pw + x + margin;
    }
    return c >= 0 && c < static_cast<long long>(is_candidate.size()) && is_candidate[c] ? static_cast<int>(c) : -1;
  }
  std::vector<std::uint8_t> valid;  // per buffer position: 1 = a usable sample
  // Approximate search only: the index of this image's first-pass windows.
  std::shared_ptr<const PartialNeighbourhoodIndex> ann;

  const float* plane(int c) const { return planes.data() + static_cast<std::size_t>(c) * pw * ph; }
};

// Candidate centres, spans and blocks of a search image whose size, planes
// and validity are set.
void index_candidates(SearchImage& s, int window, bool periodic, int margin, int core_w, int core_h);

SearchImage make_search_image(const RotatedExemplar& r, int window, bool periodic, int margin,
                              int core_w, int core_h) {
  SearchImage s;
  const Image& img = r.image;
  s.pw = img.width;
  s.ph = img.height;
  s.channels = img.channels;
  const std::size_t n = static_cast<std::size_t>(s.pw) * s.ph;
  s.planes.resize(n * s.channels + kPad, 0.f);  // padding: vector loads may overrun a row
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < s.channels; ++c) s.planes[c * n + i] = img.data[i * s.channels + c];
  s.valid.resize(n);
  for (std::size_t i = 0; i < n; ++i) s.valid[i] = r.valid.data[i] > 0.5f;
  index_candidates(s, window, periodic, margin, core_w, core_h);
  return s;
}

// `base` turned by q quarter turns (rotated_exemplars.h): its planes and
// validity permuted, its candidates indexed anew. Only for windows of even
// size: with odd windows a turned orientation is searched in its base
// through the turn, never built (ElPreparedExemplars::searched_through_turn).
SearchImage turned_search_image(const SearchImage& base, int q, int window) {
  SearchImage s;
  const bool odd = q % 2 == 1;
  s.pw = odd ? base.ph : base.pw;
  s.ph = odd ? base.pw : base.ph;
  s.channels = base.channels;
  const std::size_t n = static_cast<std::size_t>(s.pw) * s.ph;
  s.planes.resize(n * s.channels + kPad, 0.f);
  s.valid.resize(n);
  // Our pixel (x, y) is base pixel a + x * sx + y * sy (the turn is affine;
  // 4 - q more turns bring ours back to base); written in our row order.
  auto source = [&](int x, int y) {
    quarter_turns_position(s.pw, s.ph, (4 - q) % 4, x, y);
    return static_cast<long long>(y) * base.pw + x;
  };
  const long long a = source(0, 0), sx = source(1, 0) - a, sy = source(0, 1) - a;
  for (int y = 0; y < s.ph; ++y) {
    const long long row = a + y * sy;
    for (int c = 0; c < s.channels; ++c) {
      const float* from = base.planes.data() + c * n;
      float* to = s.planes.data() + c * n + static_cast<std::size_t>(y) * s.pw;
      for (int x = 0; x < s.pw; ++x) to[x] = from[row + x * sx];
    }
    std::uint8_t* v = s.valid.data() + static_cast<std::size_t>(y) * s.pw;
    for (int x = 0; x < s.pw; ++x) v[x] = base.valid[row + x * sx];
  }
  index_candidates(s, window, false, 0, 0, 0);
  return s;
}

void index_candidates(SearchImage& s, int window, bool periodic, int margin, int core_w, int core_h) {
  const std::size_t n = static_cast<std::size_t>(s.pw) * s.ph;
  const int lo = lo_of(window), hi = hi_of(window);
  if (periodic) {
    // One period of centres: every exemplar pixel exactly once.
    for (int y = margin; y < margin + core_h; ++y) s.spans.push_back({y, margin, margin + core_w});
  } else {
    // Integral image of invalid samples; a centre is a candidate when its
    // whole window lies inside the buffer and is valid.
    std::vector<int> sum(static_cast<std::size_t>(s.pw + 1) * (s.ph + 1), 0);
    for (int y = 0; y < s.ph; ++y)
      for (int x = 0; x < s.pw; ++x)
        sum[(y + 1) * (s.pw + 1) + x + 1] = (s.valid[static_cast<std::size_t>(y) * s.pw + x] ? 0 : 1) +
                                            sum[y * (s.pw + 1) + x + 1] +
                                            sum[(y + 1) * (s.pw + 1) + x] -
                                            sum[y * (s.pw + 1) + x];
    auto bad = [&](int x0, int y0, int x1, int y1) {  // inclusive-exclusive box
      return sum[y1 * (s.pw + 1) + x1] - sum[y0 * (s.pw + 1) + x1] - sum[y1 * (s.pw + 1) + x0] +
             sum[y0 * (s.pw + 1) + x0];
    };
    for (int y = -lo; y < s.ph - hi; ++y) {
      int start = -1;
      for (int x = -lo; x <= s.pw - hi; ++x) {
        const bool ok = x < s.pw - hi && bad(x + lo, y + lo, x + hi + 1, y + hi + 1) == 0;
        if (ok && start < 0) start = x;
        if (!ok && start >= 0) {
          s.spans.push_back({y, start, x});
          start = -1;
        }
      }
    }
  }
  for (const auto& sp : s.spans) {
    s.span_first.push_back(static_cast<int>(s.ids.size()));
    s.max_span = std::max(s.max_span, sp.x1 - sp.x0);
    for (int x = sp.x0; x < sp.x1; ++x) s.ids.push_back(sp.y * s.pw + x);
  }
  s.is_candidate.assign(n, 0);
  for (int id : s.ids) s.is_candidate[id] = 1;
  s.periodic = periodic;
  s.margin = margin;
  s.core_w = core_w;
  s.core_h = core_h;
  // Blocks of spans for pass 1 (the partition does not affect the result).
  const int want = std::max(1, tbb::this_task_arena::max_concurrency());
  const int per = std::max<int>(1, (static_cast<int>(s.ids.size()) + want - 1) / want);
  int b0 = 0, acc = 0;
  for (int i = 0; i < static_cast<int>(s.spans.size()); ++i) {
    acc += s.spans[i].x1 - s.spans[i].x0;
    if (acc >= per) {
      s.blocks.emplace_back(b0, i + 1);
      b0 = i + 1;
      acc = 0;
    }
  }
  if (b0 < static_cast<int>(s.spans.size())) s.blocks.emplace_back(b0, static_cast<int>(s.spans.size()));
}

void validate_exemplars(const std::vector<Image>& exemplars, const ElOptions& opt) {
  auto bad = [](const std::string& m) { throw InvalidInputError("efros_leung: " + m); };
  if (opt.window < 3 || opt.window > 51)
    bad("window " + std::to_string(opt.window) + " outside 3..51");
  if (opt.rotations < 1 || opt.rotations > 128)
    bad("rotations " + std::to_string(opt.rotations) + " outside 1..128");
  if (opt.ann_stride < 1 || opt.ann_stride > 4)
    bad("ann_stride " + std::to_string(opt.ann_stride) + " outside 1..4");
  if (opt.ann_pca_dims < 0) bad("ann_pca_dims " + std::to_string(opt.ann_pca_dims) + " < 0");
  if (exemplars.empty()) bad("exemplars: none given");
  for (std::size_t e = 0; e < exemplars.size(); ++e) {
    const Image& ex = exemplars[e];
    if (ex.empty() || ex.data.size() != static_cast<std::size_t>(ex.width) * ex.height * ex.channels)
      bad("exemplar " + std::to_string(e) + " is empty");
    if (ex.channels != exemplars[0].channels)
      bad("exemplar " + std::to_string(e) + " has " + std::to_string(ex.channels) +
          " channels, exemplar 0 has " + std::to_string(exemplars[0].channels));
    if (!opt.periodic_exemplar && (ex.width < opt.window || ex.height < opt.window))
      bad("exemplar " + std::to_string(e) + " (" + std::to_string(ex.width) + "x" +
          std::to_string(ex.height) + ") is smaller than the window " +
          std::to_string(opt.window));
    for (float v : ex.data)
      if (!std::isfinite(v)) bad("exemplar " + std::to_string(e) + " holds a non-finite value");
  }
}

}  // namespace

// Search images built on first use: slot e * rotations + k holds exemplar e
// rotated by 2 pi k / rotations (rotate_exemplar_step). Each slot is built
// once (its own once_flag, so different slots build concurrently); a built
// slot never changes. Orientation k >= K/4 is q = k / (K/4) quarter turns of
// k mod K/4; with odd windows it is never built but searched in that base
// with the pixel's window read through the turn (searched_through_turn: a
// quarter turn maps an odd square window onto itself), so a 512 px exemplar
// costs 16 search images, not 64 (issue 19: building the other 48 was a
// third of the synthesis, decision 501). With even windows it is built as q
// turns of its base (turned_search_image).
struct ElPreparedExemplars {
  std::vector<Image> exemplars;
  int window = 0, first_window = 0, rotations = 1, ann_pca_dims = 0, ann_stride = 1;
  bool periodic = false;
  ElSearch search = ElSearch::Approximate;
  mutable std::unique_ptr<std::once_flag[]> once;
  mutable std::unique_ptr<std::unique_ptr<SearchImage>[]> slots;

  /// The quarter turns through which orientation k of exemplar e is searched
  /// in orientation k mod K/4 (quarter_turns_of), or 0: searched in its own.
  int searched_through_turn(int e, int k) const {
    return window % 2 == 1 && first_window % 2 == 1 ? quarter_turns_of(exemplars[e], k, rotations, periodic) : 0;
  }

  const SearchImage& get(int e, int k) const {
    const std::size_t i = static_cast<std::size_t>(e) * rotations + k;
    // Isolated: while the build's parallel_for waits, this thread must not
    // take another synthesis task that could ask for the same slot (a
    // recursive call_once on one flag deadlocks).
    std::call_once(once[i], [&] { tbb::this_task_arena::isolate([&] { slots[i] = build(e, k); }); });
    return *slots[i];
  }

  std::unique_ptr<SearchImage> build(int e, int k) const {
    const Image& ex = exemplars[e];
    const int margin = std::max(-lo_of(window), hi_of(window));
    std::unique_ptr<SearchImage> s;
    if (const int q = quarter_turns_of(ex, k, rotations, periodic); q > 0) {
      assert(searched_through_turn(e, k) == 0);
      s = std::make_unique<SearchImage>(turned_search_image(get(e, k % (rotations / 4)), q, window));
    } else {
      RotatedExemplar r = rotate_exemplar(ex, 2.0 * M_PI * k / rotations, periodic, margin);
      s = std::make_unique<SearchImage>(make_search_image(r, window, periodic, margin, ex.width, ex.height));
    }
    if (s->ids.empty())
      throw InvalidInputError("efros_leung: exemplar " + std::to_string(e) + " rotated by " +
                              std::to_string(360.0 * k / rotations) +
                              " degrees has no position where the whole window " + std::to_string(window) +
                              " fits; use a larger exemplar, a smaller window or "
                              "periodic_exemplar");
    if (search == ElSearch::Approximate)
      s->ann = std::make_shared<const PartialNeighbourhoodIndex>(s->planes.data(), static_cast<std::size_t>(s->pw) * s->ph,
                                                           s->pw, s->channels, s->ids, first_window, ann_pca_dims,
                                                           ann_stride);
    return s;
  }
};

namespace {

std::shared_ptr<ElPreparedExemplars> prepare(const std::vector<Image>& exemplars,
                                             const ElOptions& opt) {
  validate_exemplars(exemplars, opt);
  auto p = std::make_shared<ElPreparedExemplars>();
  p->exemplars = exemplars;
  p->window = opt.window;
  p->first_window = el_first_pass_window(opt);
  p->rotations = opt.rotations;
  p->periodic = opt.periodic_exemplar;
  p->search = opt.search;
  p->ann_pca_dims = el_ann_pca_dims(opt, exemplars[0].channels);
  p->ann_stride = opt.ann_stride;
  const std::size_t n = exemplars.size() * static_cast<std::size_t>(opt.rotations);
  p->once = std::make_unique<std::once_flag[]>(n);
  p->slots = std::make_unique<std::unique_ptr<SearchImage>[]>(n);
  return p;
}

class Synthesizer {
 public:
  Synthesizer(const ElInput& in, const ElOptions& opt) : in_(in), opt_(opt) {}
  ElResult run();

 private:
  void validate();
  void prepare_search_images();
  int search_key(int p) const { return key_[p]; }
  void gather_known(int p, const SearchImage& s);
  int pass1(const SearchImage& s, std::size_t n);
  void short_list_passes(const SearchImage& s, std::size_t n, int p);
  bool short_list_ties(const SearchImage& s);
  void rank_short_list(const SearchImage& s, std::size_t n, int p, bool widen);
  float first_pass_ssd(const SearchImage& s, int nk, int id, float stop) const;
  void select_smallest(const SearchImage& s, std::size_t n);
  void score_full(const SearchImage& s, const std::vector<int>& ids, std::vector<Scored>& out);
  void synthesize_pixel(int p);
  void seed_patch(int p);
  void mark_filled(int p);
  struct PixelCounts {
    std::size_t known = 0, to_fill = 0;
  };
  PixelCounts init_canvas();
  void seed_at_centre();
  void report_fill_progress(std::size_t to_fill) const;
  void fill_onion_peel(std::size_t to_fill);
  void fill_direction_sweep(std::size_t to_fill);

  const ElInput& in_;
  const ElOptions& opt_;
  std::shared_ptr<const ElPreparedExemplars> prep_;
  int W = 0, H = 0, C = 0, window_ = 0, first_ = 0;
  double sigma_ = 0;
  std::vector<PixelState> state_;
  std::vector<std::uint8_t> known_;
  Image out_;
  std::vector<int> key_;                 // per pixel: index into search_ (or -1)
  std::vector<const SearchImage*> search_;
  std::vector<float> gauss_;             // per full-window offset
  std::mt19937_64 rng_;
  // Onion-peel bookkeeping.
  std::vector<std::uint8_t> count_;
  std::priority_queue<std::pair<int, int>> queue_;  // (count, -index)
  bool onion_ = true;
  // Per-pixel scratch.
  std::vector<int> delta_;               // buffer offset per known neighbour
  std::vector<float> value_;             // known values, [k * C + c]
  std::vector<float> weight_;            // Gaussian weight per known neighbour
  std::vector<int> p2_roff_;
  std::vector<unsigned> p2_gmask_;  // per row: bit g = group g holds a known offset
  std::vector<float> p2_w_, p2_t_;
  int p2_row_dy_ = 0;
  std::vector<int> p1_delta_;
  std::vector<float> p1_value_;
  std::vector<float> err_, sample_, p2_err_;
  std::vector<int> pre_;
  std::vector<Scored> scored_, collect_;
  // The short list's first-pass errors, their tie bound, and whether any
  // was abandoned past it (short_list_ties).
  std::vector<Scored> p1_scored_;
  float p1_tie_ = 0;
  bool p1_abandoned_ = false;
  bool last_widened_ = false;  // the previous short list was widened
  std::size_t synthesized_ = 0, seeded_ = 0, pass1_candidates_ = 0, widened_ = 0;
  std::vector<int> pair_of_;             // per pixel: e * rotations + k (or -1)
  // Per pixel: quarter turns from its search image to its orientation
  // (ElPreparedExemplars::searched_through_turn), and per turn q the window
  // offset (dx, dy) of the target that search-image offset g (row-major
  // over the full window) reads: (dx, dy) = q quarter turns of g's (a, b).
  std::vector<std::uint8_t> turn_;
  std::array<std::vector<std::array<int, 2>>, 4> turned_offset_;
  std::vector<ElSource> source_;         // per pixel: where its value came from
  // Per search image: its exemplar, that exemplar's size and the cosine and
  // sine of its rotation (rotated_point / exemplar_point).
  struct Frame {
    int e = 0, w = 0, h = 0;
    double c = 1, s = 0;
  };
  std::vector<Frame> frame_;
  void record_source(int q, int p, int id, const SearchImage& s) {
    const Frame& f = frame_[key_[p]];
    const int bx = id % s.pw, by = id / s.pw;
    const auto u = exemplar_point(f.w, f.h, s.pw, s.ph, f.c, f.s, bx, by);
    int x = bx, y = by;  // in the pixel's own orientation (rotate_exemplar_step)
    quarter_turns_position(s.pw, s.ph, turn_[p], x, y);
    source_[q] = {f.e, pair_of_[p] % opt_.rotations, x, y, static_cast<float>(u[0]), static_cast<float>(u[1])};
  }
  int continuing(const ElExemplarPoint& g, int p, int dx, int dy, const SearchImage& s) const;
  // Approximate search: source position (buffer offset in the pixel's own
  // search image) of every synthesised pixel, -1 for the others; the known
  // first-pass neighbours' window slots; the short list.
  std::vector<int> src_;
  std::vector<int> p1_slot_;
  std::vector<int> short_;
  // Coherent candidates of the current pixel (sorted, unique); see
  // ElOptions::coherence.
  std::vector<int> coh_;
  // Those that continue a given pixel's source (ElInput::known_source).
  std::vector<int> coh_given_;
  bool given_in_window_ = false;  // a Known (given) pixel lies in the current window
  void add_coherent_to_preselect();
  bool pick_coherent(int& id);
  std::vector<int>& coherent_pool();
  bool coherent_tie();
  int ann_k_ = 16;  // kd-tree neighbours asked for the current pixel
  int orientations_used_ = 0;  // distinct (exemplar, orientation) pairs
  PartialNeighbourhoodIndex::Scratch ann_scratch_;
};

void Synthesizer::validate() {
  auto bad = [](const std::string& m) { throw InvalidInputError("efros_leung: " + m); };
  if (opt_.window < 3 || opt_.window > 51)
    bad("window " + std::to_string(opt_.window) + " outside 3..51");
  if (opt_.first_pass_window != 0 &&
      (opt_.first_pass_window < 3 || opt_.first_pass_window > opt_.window))
    bad("first_pass_window " + std::to_string(opt_.first_pass_window) + " outside 3..window (" +
        std::to_string(opt_.window) + ") or 0");
  if (opt_.preselect < 0) bad("preselect " + std::to_string(opt_.preselect) + " < 0");
  if (opt_.search != ElSearch::Approximate && opt_.search != ElSearch::Exhaustive)
    bad("search holds an unknown value " + std::to_string(static_cast<int>(opt_.search)));
  if (opt_.ann_candidates < 1 || opt_.ann_candidates > 256)
    bad("ann_candidates " + std::to_string(opt_.ann_candidates) + " outside 1..256");
  if (opt_.ann_coherent_candidates < 1 || opt_.ann_coherent_candidates > 256)
    bad("ann_coherent_candidates " + std::to_string(opt_.ann_coherent_candidates) + " outside 1..256");
  if (opt_.ann_pca_dims < 0) bad("ann_pca_dims " + std::to_string(opt_.ann_pca_dims) + " < 0");
  if (opt_.ann_stride < 1 || opt_.ann_stride > 4)
    bad("ann_stride " + std::to_string(opt_.ann_stride) + " outside 1..4");
  if (!(opt_.ann_eps >= 0.0) || !std::isfinite(opt_.ann_eps))
    bad("ann_eps " + std::to_string(opt_.ann_eps) + " must be finite and >= 0");
  if (!(opt_.coherence >= 0.0) || !std::isfinite(opt_.coherence))
    bad("coherence " + std::to_string(opt_.coherence) + " must be finite and >= 0");
  if (!(opt_.gaussian_sigma >= 0.0) || !std::isfinite(opt_.gaussian_sigma))
    bad("gaussian_sigma " + std::to_string(opt_.gaussian_sigma) + " must be finite and >= 0");
  if (!(opt_.pick_fraction >= 0.0 && opt_.pick_fraction <= 1.0))
    bad("pick_fraction " + std::to_string(opt_.pick_fraction) + " outside [0,1]");
  if (opt_.pick_min < 1) bad("pick_min " + std::to_string(opt_.pick_min) + " < 1");
  if (!std::isfinite(opt_.error_tolerance))
    bad("error_tolerance " + std::to_string(opt_.error_tolerance) + " is not finite");
  if (opt_.order == FillOrder::Direction &&
      (!std::isfinite(opt_.direction_x) || !std::isfinite(opt_.direction_y) ||
       (opt_.direction_x == 0.0 && opt_.direction_y == 0.0)))
    bad("direction (" + std::to_string(opt_.direction_x) + ", " +
        std::to_string(opt_.direction_y) + ") must be finite and non-zero");
  if (in_.prepared) {
    if (!in_.exemplars.empty()) bad("exemplars and prepared are both given; give one");
    const ElPreparedExemplars& p = *in_.prepared;
    if (p.window != opt_.window)
      bad("window " + std::to_string(opt_.window) + " differs from the prepared exemplars' " +
          std::to_string(p.window));
    if (p.rotations != opt_.rotations)
      bad("rotations " + std::to_string(opt_.rotations) +
          " differs from the prepared exemplars' " + std::to_string(p.rotations));
    if (p.periodic != opt_.periodic_exemplar)
      bad(std::string("periodic_exemplar ") + (opt_.periodic_exemplar ? "true" : "false") +
          " differs from the prepared exemplars'");
    if (p.search != opt_.search) bad("search differs from the prepared exemplars'");
    if (p.search == ElSearch::Approximate &&
        (p.first_window != el_first_pass_window(opt_) ||
         p.ann_pca_dims != el_ann_pca_dims(opt_, p.exemplars[0].channels) || p.ann_stride != opt_.ann_stride))
      bad("first_pass_window / ann_pca_dims / ann_stride differ from the prepared exemplars' (" +
          std::to_string(p.first_window) + " / " + std::to_string(p.ann_pca_dims) + " / " +
          std::to_string(p.ann_stride) + ")");
    prep_ = in_.prepared;
  } else {
    prep_ = prepare(in_.exemplars, opt_);
  }
  const std::vector<Image>& exemplars = prep_->exemplars;
  const Image& t = in_.target;
  if (t.width <= 0 || t.height <= 0)
    bad("target size " + std::to_string(t.width) + "x" + std::to_string(t.height) +
        " must be positive");
  if (t.channels != exemplars[0].channels)
    bad("target has " + std::to_string(t.channels) + " channels, the exemplars " +
        std::to_string(exemplars[0].channels));
  const std::size_t n = static_cast<std::size_t>(t.width) * t.height;
  if (t.data.size() != n * t.channels) bad("target data size does not match its dimensions");
  if (!in_.state.empty() && in_.state.size() != n)
    bad("state has " + std::to_string(in_.state.size()) + " entries, target has " +
        std::to_string(n) + " pixels");
  for (PixelState s : in_.state)
    if (s != PixelState::Fill && s != PixelState::Known && s != PixelState::Outside)
      bad("state holds an unknown value " + std::to_string(static_cast<int>(s)));
  if (!in_.angle.empty() &&
      (in_.angle.width != t.width || in_.angle.height != t.height || in_.angle.channels != 1))
    bad("angle field must be a 1-channel " + std::to_string(t.width) + "x" +
        std::to_string(t.height) + " image, got " + std::to_string(in_.angle.width) + "x" +
        std::to_string(in_.angle.height) + "x" + std::to_string(in_.angle.channels));
  if (!in_.exemplar_index.empty() && in_.exemplar_index.size() != n)
    bad("exemplar_index has " + std::to_string(in_.exemplar_index.size()) +
        " entries, target has " + std::to_string(n) + " pixels");
  if (!in_.known_source.empty() && in_.known_source.size() != n)
    bad("known_source has " + std::to_string(in_.known_source.size()) + " entries, target has " +
        std::to_string(n) + " pixels");
  for (const ElExemplarPoint& g : in_.known_source)
    if (g.exemplar >= 0 && (!std::isfinite(g.x) || !std::isfinite(g.y)))
      bad("known_source holds a non-finite point");
}

void Synthesizer::prepare_search_images() {
  const std::size_t n = static_cast<std::size_t>(W) * H;
  const bool oriented = !in_.angle.empty() || static_cast<bool>(in_.angle_fn);
  const int K = opt_.rotations;
  const int E = static_cast<int>(prep_->exemplars.size());
  std::vector<int> pair_of(n, -1), searched(n, -1);
  turn_.assign(n, 0);
  std::vector<std::uint8_t> needed(static_cast<std::size_t>(E) * K, 0);
  for (std::size_t p = 0; p < n; ++p) {
    if (state_[p] != PixelState::Fill) continue;
    int e = 0;
    if (!in_.exemplar_index.empty()) {
      e = in_.exemplar_index[p];
      if (e < 0 || e >= E)
        throw InvalidInputError("efros_leung: exemplar_index " + std::to_string(e) +
                                " at pixel (" + std::to_string(p % W) + ", " +
                                std::to_string(p / W) + ") outside 0.." + std::to_string(E - 1));
    }
    int k = 0;
    if (oriented) {
      const int x = static_cast<int>(p % W), y = static_cast<int>(p / W);
      const double a = !in_.angle.empty() ? in_.angle.at(x, y) : in_.angle_fn(x, y);
      if (!std::isfinite(a))
        throw InvalidInputError("efros_leung: angle at pixel (" + std::to_string(x) + ", " +
                                std::to_string(y) + ") is not finite");
      k = rotation_index(a, K);
    }
    pair_of[p] = e * K + k;
    if (const int q = prep_->searched_through_turn(e, k); q > 0) {
      turn_[p] = static_cast<std::uint8_t>(q);
      k %= K / 4;
    }
    searched[p] = e * K + k;
    needed[searched[p]] = 1;
  }
  // The needed rotations not built yet are built side by side (each build's
  // own parallel part is small; isolated, see ElPreparedExemplars::get).
  std::vector<int> slot(needed.size(), -1), pairs;
  for (int i = 0; i < E * K; ++i)
    if (needed[i]) pairs.push_back(i);
  search_.resize(pairs.size());
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(0, static_cast<int>(pairs.size()), [&](int j) {
      search_[j] = &prep_->get(pairs[j] / K, pairs[j] % K);
    });
  });
  frame_.resize(pairs.size());
  for (std::size_t j = 0; j < pairs.size(); ++j) {
    slot[pairs[j]] = static_cast<int>(j);
    const int e = pairs[j] / K;
    const double a = 2.0 * M_PI * (pairs[j] % K) / K;
    frame_[j] = {e, prep_->exemplars[e].width, prep_->exemplars[e].height, std::cos(a), std::sin(a)};
  }
  key_.assign(n, -1);
  for (std::size_t p = 0; p < n; ++p)
    if (searched[p] >= 0) key_[p] = slot[searched[p]];
  std::vector<std::uint8_t> used(needed.size(), 0);
  for (int pr : pair_of)
    if (pr >= 0) used[pr] = 1;
  orientations_used_ = static_cast<int>(std::count(used.begin(), used.end(), 1));
  pair_of_ = std::move(pair_of);
  // Target offset read for each search-image offset, per quarter turn.
  const int lo = lo_of(window_), hi = hi_of(window_);
  for (int q = 0; q < 4; ++q) {
    turned_offset_[q].clear();
    for (int b = lo; b <= hi; ++b)
      for (int a = lo; a <= hi; ++a) {
        int dx = a, dy = b;
        quarter_turns_offset(q, dx, dy);
        turned_offset_[q].push_back({dx, dy});
      }
  }
  source_.assign(n, ElSource());
}

void Synthesizer::gather_known(int p, const SearchImage& s) {
  delta_.clear();
  value_.clear();
  weight_.clear();
  p1_delta_.clear();
  p1_value_.clear();
  p1_slot_.clear();
  short_.clear();
  coh_.clear();
  coh_given_.clear();
  given_in_window_ = false;
  const int px = p % W, py = p / W;
  const int lo = lo_of(window_), hi = hi_of(window_);
  const int flo = lo_of(first_), fhi = hi_of(first_);
  const int nv = (window_ + kLanes - 1) / kLanes, rowlen = nv * kLanes;
  p2_roff_.clear();
  p2_gmask_.clear();
  p2_w_.clear();
  p2_t_.clear();
  // Offsets (a, b) in the search image's frame, row by row; the target
  // pixel each reads is at the turned offset (dx, dy) (turned_offset_).
  const std::vector<std::array<int, 2>>& turned = turned_offset_[turn_[p]];
  int g = 0;
  for (int b = lo; b <= hi; ++b)
    for (int a = lo; a <= hi; ++a, ++g) {
      const int x = px + turned[g][0], y = py + turned[g][1];
      if (x < 0 || y < 0 || x >= W || y >= H) continue;
      const int q = y * W + x;
      if (!known_[q]) continue;
      const float* v = out_.pixel(x, y);
      const int offset = b * s.pw + a;
      given_in_window_ = given_in_window_ || state_[q] == PixelState::Known;
      if (a >= flo && a <= fhi && b >= flo && b <= fhi) {
        p1_delta_.push_back(offset);
        p1_value_.insert(p1_value_.end(), v, v + C);
        // Coherent candidate: q's source shifted back by q's offset (same
        // search image and turn only).
        int c = -1;
        if (src_[q] >= 0 && key_[q] == key_[p] && turn_[q] == turn_[p])
          c = s.candidate_at(static_cast<long long>(src_[q]) - offset);
        else if (src_[q] >= 0)  // another orientation: through the exemplar
          c = continuing(ElExemplarPoint{source_[q].exemplar, source_[q].ex, source_[q].ey}, p, a, b, s);
        else if (state_[q] == PixelState::Known && !in_.known_source.empty() && opt_.coherence > 0)
          if ((c = continuing(in_.known_source[q], p, a, b, s)) >= 0) coh_given_.push_back(c);
        if (s.ann) {
          p1_slot_.push_back((b - flo) * first_ + (a - flo));
          if (c >= 0) short_.push_back(c);
        }
        if (c >= 0 && opt_.coherence > 0) coh_.push_back(c);
      }
      delta_.push_back(offset);
      weight_.push_back(gauss_[g]);
      value_.insert(value_.end(), v, v + C);
      // Row-grouped copy for the pass-2 kernel.
      if (p2_roff_.empty() || p2_row_dy_ != b) {
        p2_row_dy_ = b;
        p2_roff_.push_back(b * s.pw + lo);
        p2_gmask_.push_back(0u);
        p2_w_.resize(p2_w_.size() + rowlen, 0.f);
        p2_t_.resize(p2_t_.size() + static_cast<std::size_t>(rowlen) * C, 0.f);
      }
      const std::size_t r = p2_roff_.size() - 1;
      p2_gmask_[r] |= 1u << ((a - lo) / kLanes);
      p2_w_[r * rowlen + (a - lo)] = gauss_[g];
      for (int c = 0; c < C; ++c) p2_t_[(r * C + c) * rowlen + (a - lo)] = v[c];
    }
}

// Pass 1: the n best candidates by unweighted SSD over the known neighbours
// inside the first-pass window (p1_delta_/p1_value_; all known neighbours if
// none is). Writes pre_ (ids, in no particular order). Returns the count.
int Synthesizer::pass1(const SearchImage& s, std::size_t n) {
  if (p1_delta_.empty()) {
    p1_delta_ = delta_;
    p1_value_ = value_;
  }
  const int nb = static_cast<int>(s.blocks.size());
  const int nk = static_cast<int>(p1_delta_.size());
  const std::size_t ps = static_cast<std::size_t>(s.pw) * s.ph;
  const std::size_t N = s.ids.size();
  // Every candidate's error, in candidate order (spans of a block are
  // consecutive in ids, so blocks write disjoint ranges).
  err_.resize(N);
  auto run_block = [&](int b) {
    for (int si = s.blocks[b].first; si < s.blocks[b].second; ++si) {
      const auto& sp = s.spans[si];
      const int len = sp.x1 - sp.x0;
      const std::size_t row = static_cast<std::size_t>(sp.y) * s.pw + sp.x0;
      float* a = err_.data() + s.span_first[si];
      switch (C) {
        case 1: span_ssd_c1(s.planes.data(), ps, p1_delta_.data(), p1_value_.data(), nk, len, row, a); break;
        case 3: span_ssd_c3(s.planes.data(), ps, p1_delta_.data(), p1_value_.data(), nk, len, row, a); break;
        case 4: span_ssd_c4(s.planes.data(), ps, p1_delta_.data(), p1_value_.data(), nk, len, row, a); break;
        default: span_ssd_any(s.planes.data(), ps, C, p1_delta_.data(), p1_value_.data(), nk, len, row, a);
      }
    }
  };
  pass1_candidates_ += N;
  const std::size_t work = N * static_cast<std::size_t>(nk) * C;
  if (nb > 1 && opt_.parallel_pixel_search && work > 40000)
    tbb::parallel_for(0, nb, run_block);
  else
    for (int b = 0; b < nb; ++b) run_block(b);
  select_smallest(s, n);
  pre_.clear();
  for (const auto& v : scored_) pre_.push_back(v.second);
  return static_cast<int>(pre_.size());
}

// Approximate pass 1 (ElSearch::Approximate): the short list -- the coherent
// candidates gathered with the known neighbours and the kd-tree's nearest
// first-pass neighbourhoods -- deduplicated and ranked exactly by the
// first-pass SSD; the n best (by (error, position)) go to pre_, then pass 2.
//
// Ties: when at least as many as the kd-tree neighbours asked for
// (ann_k_) of the short list are within the
// pick tolerance of its best (a flat or repeated region: many candidates
// share the query's known pixels, often with identical PCA coefficients),
// the kd-tree's hits are an arbitrary subset of a larger tie set -- the
// same leaf for the same query, typically deep inside one region -- and
// the synthesis can lock into it (issue 19: uniform blue from a stripes
// exemplar). Such a pixel also ranks a jittered stratified sample of n
// candidates over the whole exemplar (one in each run of N/n consecutive
// candidates, drawn from a hash of the seed and the pixel, so the
// synthesis's random stream is untouched), as the exhaustive pass would
// see them. Pixels without such ties are unchanged, and so are those with a
// coherent candidate among the ties (coherent_tie).
//
// Order of work: when the short list fits the preselect (the usual case, no
// ranking needed) pass 2 scores it first, and the first-pass errors of the
// tie rule are then read from the cache lines pass 2 has just loaded (read
// first, they were scattered misses: a third slower synthesis with a 512 px
// exemplar). Only a widened list is ranked and scored again. Pass 2 scores
// each candidate on its own, so the result is the same as ranking first
// (checked byte for byte on patches and synth outputs, decision 501).
void Synthesizer::short_list_passes(const SearchImage& s, std::size_t n, int p) {
  const int nk = static_cast<int>(p1_slot_.size());
  // Coherent candidates stand for part of the search (ElOptions::ann_coherent_candidates).
  ann_k_ = coh_.empty() ? opt_.ann_candidates : std::min(opt_.ann_candidates, opt_.ann_coherent_candidates);
  s.ann->query(p1_slot_.data(), p1_value_.data(), nk, static_cast<std::size_t>(ann_k_),
               static_cast<float>(opt_.ann_eps), short_, ann_scratch_);
  std::sort(short_.begin(), short_.end());
  short_.erase(std::unique(short_.begin(), short_.end()), short_.end());
  // Scored first unless the previous pixel widened (ties come in regions:
  // there the speculative pass 2 would mostly be thrown away).
  const bool first = short_.size() <= n && !last_widened_;
  if (first) {
    pre_ = short_;
    add_coherent_to_preselect();
    score_full(s, pre_, scored_);
  }
  const bool widen = short_list_ties(s) && !coherent_tie();
  last_widened_ = widen;
  if (first && !widen) {
    pass1_candidates_ += short_.size();
    return;
  }
  rank_short_list(s, n, p, widen);
  add_coherent_to_preselect();
  score_full(s, pre_, scored_);
}

// The short list's first-pass errors into p1_scored_ (short_'s order) and
// the tie rule's verdict. Exact errors only where they decide something: a
// candidate whose partial error passes the tie bound of the best so far
// (which only falls) is no tie and not the best, and is abandoned there
// (its entry holds that partial error, above p1_tie_).
bool Synthesizer::short_list_ties(const SearchImage& s) {
  const int nk = static_cast<int>(p1_slot_.size());
  const float tol = static_cast<float>(std::max(opt_.error_tolerance, 0.0));
  float best = std::numeric_limits<float>::infinity();
  p1_tie_ = best;
  p1_abandoned_ = false;
  p1_scored_.clear();
  for (int id : short_) {
    const float e = first_pass_ssd(s, nk, id, p1_tie_);
    p1_scored_.push_back({e, id});
    p1_abandoned_ = p1_abandoned_ || e > p1_tie_;
    if (e < best) best = e, p1_tie_ = best * (1.f + tol) + 1e-6f * static_cast<float>(nk * C);
  }
  std::size_t ties = 0;
  for (const auto& v : p1_scored_) ties += v.first <= p1_tie_;
  return ties >= static_cast<std::size_t>(ann_k_) && s.ids.size() > short_.size();
}

// Whether a candidate of the coherent pool (pick_coherent's) is among the
// short list's first-pass ties. The widening exists for pixels whose short
// list is an arbitrary part of a larger tie set (the kd-tree's leaf), where a
// random pick would lock into that part; a pixel continued by coherence has
// its pick from its neighbours instead, so it keeps its short list: stripes
// wider than the window cost a short list, not a sample of the whole
// exemplar (issue 19; decision 501, session 28).
bool Synthesizer::coherent_tie() {
  const std::vector<int>& pool = coherent_pool();
  for (const auto& v : p1_scored_)
    if (v.first <= p1_tie_ && std::find(pool.begin(), pool.end(), v.second) != pool.end()) return true;
  return false;
}

// The short list (widened by the stratified sample when `widen`) ranked by
// exact first-pass errors; its n best into pre_.
void Synthesizer::rank_short_list(const SearchImage& s, std::size_t n, int p, bool widen) {
  const int nk = static_cast<int>(p1_slot_.size());
  const float inf = std::numeric_limits<float>::infinity();
  if (p1_abandoned_)
    for (auto& v : p1_scored_)
      if (v.first > p1_tie_) v.first = first_pass_ssd(s, nk, v.second, inf);
  const std::size_t N = s.ids.size();
  if (widen) {
    const std::size_t m = std::min(n, N);
    const std::size_t step = N / m;
    std::uint64_t h = opt_.seed ^ (0x9e3779b97f4a7c15ull * (static_cast<std::uint64_t>(p) + 1));
    h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
    h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
    h ^= h >> 31;
    for (std::size_t j = 0; j < m; ++j) {
      h = h * 6364136223846793005ull + 1442695040888963407ull;  // one draw per stratum
      const int id = s.ids[j * step + static_cast<std::size_t>((h >> 33) % step)];
      if (std::binary_search(short_.begin(), short_.end(), id)) continue;
      p1_scored_.push_back({first_pass_ssd(s, nk, id, inf), id});
    }
    ++widened_;
  }
  pass1_candidates_ += p1_scored_.size();
  if (p1_scored_.size() > n) {
    std::nth_element(p1_scored_.begin(), p1_scored_.begin() + n, p1_scored_.end());
    p1_scored_.resize(n);
  }
  pre_.clear();
  for (const auto& v : p1_scored_) pre_.push_back(v.second);
}

// Unweighted SSD of candidate id over the known first-pass neighbours
// (short_list_ssd), abandoned past `stop`.
float Synthesizer::first_pass_ssd(const SearchImage& s, int nk, int id, float stop) const {
  const std::size_t ps = static_cast<std::size_t>(s.pw) * s.ph;
  const float* P = s.planes.data();
  const int* d = p1_delta_.data();
  const float* t = p1_value_.data();
  switch (C) {
    case 1: return short_list_ssd<1>(P, ps, C, d, t, nk, id, stop);
    case 3: return short_list_ssd<3>(P, ps, C, d, t, nk, id, stop);
    case 4: return short_list_ssd<4>(P, ps, C, d, t, nk, id, stop);
    default: return short_list_ssd<0>(P, ps, C, d, t, nk, id, stop);
  }
}

// The n smallest (err_[i], ids[i]) into scored_ (in no particular order:
// pass 2 ranks them again). A threshold T is guessed from every 8th error
// (the value of rank about 2n among all); if at least n errors are <= T,
// every member of the n smallest is among them (exact), else all candidates
// are ranked.
void Synthesizer::select_smallest(const SearchImage& s, std::size_t n) {
  const std::size_t N = err_.size();
  scored_.clear();
  const float* e = err_.data();
  if (N > 16 * n) {
    // The r+1 smallest of the sample, kept sorted; after the first r+1 an
    // element enters only if it beats the largest kept (rarely, and a
    // predictable branch, unlike a partition-based nth_element).
    const std::size_t r = (2 * n + 7) / 8;  // < N / 8: the sample is larger
    sample_.assign(r + 1, std::numeric_limits<float>::infinity());
    float* top = sample_.data();
    for (std::size_t i = 0; i < N; i += 8) {
      const float v = e[i];
      if (!(v < top[r])) continue;
      std::size_t j = r;
      for (; j > 0 && top[j - 1] > v; --j) top[j] = top[j - 1];
      top[j] = v;
    }
    const float T = top[r];
    if (collect_.size() < N) collect_.resize(N);
    Scored* const begin = collect_.data();
    Scored* const end = collect_at_most(e, s.ids.data(), N, T, begin);
    if (static_cast<std::size_t>(end - begin) >= n)
      scored_.assign(begin, end);
  }
  if (scored_.empty())
    for (std::size_t i = 0; i < N; ++i) scored_.push_back({e[i], s.ids[i]});
  if (scored_.size() > n) {
    std::nth_element(scored_.begin(), scored_.begin() + n, scored_.end());
    scored_.resize(n);
  }
}

// Pass 2: Gaussian-weighted SSD over every known neighbour, renormalised by
// the sum of the known weights; unsorted (the caller ranks what it needs).
void Synthesizer::score_full(const SearchImage& s, const std::vector<int>& ids,
                             std::vector<Scored>& out) {
  double wsum = 0;
  for (float w : weight_) wsum += w;
  const float inv = wsum > 0 ? static_cast<float>(1.0 / wsum) : 1.f;
  out.resize(ids.size());
  const int nk = static_cast<int>(delta_.size());
  const int nv = (window_ + kLanes - 1) / kLanes;
  const int nr = static_cast<int>(p2_roff_.size());
  const std::size_t ps = static_cast<std::size_t>(s.pw) * s.ph;
  const float* P = s.planes.data();
  p2_err_.resize(ids.size());
  auto score = [&](std::size_t i0, std::size_t i1) {
    const int* I = ids.data() + i0;
    float* o = p2_err_.data() + i0;
    const std::size_t m = i1 - i0;
    switch (C) {
      case 1: weighted_ssd_c1(P, ps, p2_roff_.data(), p2_gmask_.data(), p2_w_.data(), p2_t_.data(), nr, nv, I, m, o); break;
      case 3: weighted_ssd_c3(P, ps, p2_roff_.data(), p2_gmask_.data(), p2_w_.data(), p2_t_.data(), nr, nv, I, m, o); break;
      case 4: weighted_ssd_c4(P, ps, p2_roff_.data(), p2_gmask_.data(), p2_w_.data(), p2_t_.data(), nr, nv, I, m, o); break;
      default: weighted_ssd_any(C, P, ps, p2_roff_.data(), p2_gmask_.data(), p2_w_.data(), p2_t_.data(), nr, nv, I, m, o);
    }
  };
  const std::size_t work = ids.size() * nk * static_cast<std::size_t>(C);
  if (opt_.parallel_pixel_search && work > 200000)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ids.size(), 64),
                      [&](const tbb::blocked_range<std::size_t>& r) { score(r.begin(), r.end()); });
  else
    score(0, ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) out[i] = {p2_err_[i] * inv, ids[i]};
}

void Synthesizer::mark_filled(int p) {
  known_[p] = 1;
  if (!onion_) return;
  const int px = p % W, py = p / W;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = px + dx, y = py + dy;
      if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= W || y >= H) continue;
      const int q = y * W + x;
      if (state_[q] != PixelState::Fill || known_[q]) continue;
      ++count_[q];
      queue_.push({count_[q], -q});
    }
}

void Synthesizer::seed_patch(int p) {
  const SearchImage& s = *search_[search_key(p)];
  const int id = s.ids[rng_() % s.ids.size()];
  const int px = p % W, py = p / W;
  for (int b = -1; b <= 1; ++b)
    for (int a = -1; a <= 1; ++a) {
      // Search-image offset (a, b) lands on the target at its turned offset.
      int dx = a, dy = b;
      quarter_turns_offset(turn_[p], dx, dy);
      const int x = px + dx, y = py + dy;
      if (x < 0 || y < 0 || x >= W || y >= H) continue;
      const int q = y * W + x;
      // Only Fill pixels that search the same exemplar and orientation, so
      // a seed never puts texture k where the index map asks for another.
      if (state_[q] != PixelState::Fill || known_[q] || pair_of_[q] != pair_of_[p]) continue;
      const int at = id + b * s.pw + a;
      for (int c = 0; c < C; ++c) out_.at(x, y, c) = s.plane(c)[at];
      record_source(q, p, at, s);
      src_[q] = at;
      mark_filled(q);
      ++seeded_;
    }
}

void Synthesizer::synthesize_pixel(int p) {
  const SearchImage& s = *search_[search_key(p)];
  gather_known(p, s);
  if (delta_.empty()) {
    seed_patch(p);
    return;
  }
  const std::size_t total = s.ids.size();
  if (opt_.single_pass) {
    score_full(s, s.ids, scored_);
  } else {
    const std::vector<Image>& ex = prep_->exemplars;
    std::size_t n = opt_.preselect > 0 ? static_cast<std::size_t>(opt_.preselect)
                                       : static_cast<std::size_t>(ex[0].width);
    if (!in_.exemplar_index.empty())
      n = opt_.preselect > 0 ? n : static_cast<std::size_t>(ex[in_.exemplar_index[p]].width);
    n = std::min(n, total);
    if (s.ann && !p1_slot_.empty()) {
      short_list_passes(s, n, p);
    } else {
      pass1(s, n);
      add_coherent_to_preselect();
      score_full(s, pre_, scored_);
    }
  }
  const std::size_t m = scored_.size();
  std::size_t k = std::max<std::size_t>(static_cast<std::size_t>(opt_.pick_min),
                                        static_cast<std::size_t>(std::ceil(opt_.pick_fraction * m)));
  k = std::min(k, m);
  // Only the k best, in the total order (error, id), are needed.
  std::partial_sort(scored_.begin(), scored_.begin() + k, scored_.end());
  if (opt_.error_tolerance >= 0) {
    const double limit = scored_[0].first * (1.0 + opt_.error_tolerance);
    std::size_t within = 1;
    while (within < k && scored_[within].first <= limit) ++within;
    k = within;
  }
  int id = scored_[k > 1 ? rng_() % k : 0].second;
  pick_coherent(id);
  const int px = p % W, py = p / W;
  for (int c = 0; c < C; ++c) out_.at(px, py, c) = s.plane(c)[id];
  record_source(p, p, id, s);
  src_[p] = id;
  mark_filled(p);
  ++synthesized_;
}

// The candidate of pixel p that continues a neighbour whose value was read
// at exemplar point g (a given pixel's ElInput::known_source, or a
// synthesised pixel of another orientation or turn), the neighbour at offset
// (dx, dy) in the frame of p's search image: g in that image, moved back by
// the offset; -1 if g is in another exemplar or that is no candidate.
// Periodic canvases: the copy of g that lies on the canvas.
int Synthesizer::continuing(const ElExemplarPoint& g, int p, int dx, int dy, const SearchImage& s) const {
  const Frame& f = frame_[key_[p]];
  if (g.exemplar != f.e) return -1;
  const int shift[3] = {0, -1, 1}, tiles = s.periodic ? 3 : 1;
  for (int ty = 0; ty < tiles; ++ty)
    for (int tx = 0; tx < tiles; ++tx) {
      const auto c = rotated_point(f.w, f.h, s.pw, s.ph, f.c, f.s, g.x + shift[tx] * f.w, g.y + shift[ty] * f.h);
      const long long i = std::llround(c[0]) - dx, j = std::llround(c[1]) - dy;
      if (i < 0 || j < 0 || i >= s.pw || j >= s.ph) continue;
      return s.candidate_at(j * s.pw + i);
    }
  return -1;
}

// Coherent candidates join pass 2 even when pass 1 ranked them out.
void Synthesizer::add_coherent_to_preselect() {
  if (coh_.empty()) return;
  std::sort(coh_.begin(), coh_.end());
  coh_.erase(std::unique(coh_.begin(), coh_.end()), coh_.end());
  const std::size_t n0 = pre_.size();
  if (!std::is_sorted(pre_.begin(), pre_.end())) std::sort(pre_.begin(), pre_.end());
  for (int c : coh_)
    if (!std::binary_search(pre_.begin(), pre_.begin() + static_cast<std::ptrdiff_t>(n0), c)) pre_.push_back(c);
}

// ElOptions::coherence: the best coherent candidate of pass 2 replaces the
// random pick when its error is within (1 + coherence) of the best error
// (scored_ holds every pass-2 candidate, its best first). Next to given
// (Known) pixels, those that continue a given pixel's source
// (ElInput::known_source) come first; without such sources the boundary
// condition decides there (a patch's seams, decision 506); with them, the
// synthesised pixels near the seam continue the given ones, and so may their
// neighbours. Returns whether it did.
std::vector<int>& Synthesizer::coherent_pool() {
  const bool given_only = given_in_window_ && (!coh_given_.empty() || in_.known_source.empty());
  return given_only ? coh_given_ : coh_;
}

bool Synthesizer::pick_coherent(int& id) {
  std::vector<int>& pool = coherent_pool();
  if (pool.empty() || scored_.empty()) return false;
  std::sort(pool.begin(), pool.end());
  const Scored* best = nullptr;
  for (const Scored& v : scored_)
    if (std::binary_search(pool.begin(), pool.end(), v.second) && (!best || v < *best)) best = &v;
  if (!best || best->first > scored_[0].first * (1.0 + opt_.coherence) + 1e-12) return false;
  id = best->second;
  return true;
}

// The canvas from the input: sizes, windows, pixel states, the target's
// values, the Known pixels (values checked finite). Returns the counts of
// Known and Fill pixels.
Synthesizer::PixelCounts Synthesizer::init_canvas() {
  W = in_.target.width;
  H = in_.target.height;
  C = in_.target.channels;
  window_ = opt_.window;
  first_ = el_first_pass_window(opt_);
  sigma_ = opt_.gaussian_sigma > 0 ? opt_.gaussian_sigma : window_ / 6.4;
  const std::size_t n = static_cast<std::size_t>(W) * H;
  state_ = in_.state.empty() ? std::vector<PixelState>(n, PixelState::Fill) : in_.state;
  out_ = in_.target;
  known_.assign(n, 0);
  src_.assign(n, -1);
  PixelCounts counts;
  for (std::size_t p = 0; p < n; ++p) {
    if (state_[p] == PixelState::Known) {
      known_[p] = 1;
      ++counts.known;
      for (int c = 0; c < C; ++c)
        if (!std::isfinite(out_.data[p * C + c]))
          throw InvalidInputError("efros_leung: target holds a non-finite value at Known pixel (" +
                                  std::to_string(p % W) + ", " + std::to_string(p / W) + ")");
    }
    if (state_[p] == PixelState::Fill) ++counts.to_fill;
  }
  // The second pass's Gaussian weight per full-window offset.
  const int lo = lo_of(window_), hi = hi_of(window_);
  for (int dy = lo; dy <= hi; ++dy)
    for (int dx = lo; dx <= hi; ++dx)
      gauss_.push_back(static_cast<float>(std::exp(-(dx * dx + dy * dy) / (2.0 * sigma_ * sigma_))));
  return counts;
}

// Onion peel on an empty target: the first seed goes to the Fill pixel
// nearest the centre of the Fill pixels' bounding box. (A direction sweep
// seeds at its first pixel instead.)
void Synthesizer::seed_at_centre() {
  const std::size_t n = static_cast<std::size_t>(W) * H;
  int x0 = W, y0 = H, x1 = -1, y1 = -1;
  for (std::size_t p = 0; p < n; ++p)
    if (state_[p] == PixelState::Fill) {
      x0 = std::min<int>(x0, p % W);
      x1 = std::max<int>(x1, p % W);
      y0 = std::min<int>(y0, p / W);
      y1 = std::max<int>(y1, p / W);
    }
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  int best = -1;
  double bd = std::numeric_limits<double>::infinity();
  for (std::size_t p = 0; p < n; ++p) {
    if (state_[p] != PixelState::Fill) continue;
    const double d = (p % W - cx) * (p % W - cx) + (p / W - cy) * (p / W - cy);
    if (d < bd) {
      bd = d;
      best = static_cast<int>(p);
    }
  }
  onion_ = false;  // counts are initialised by fill_onion_peel, after the seed
  seed_patch(best);
}

// Progress after a pixel: every percent of the Fill pixels, and at the end.
void Synthesizer::report_fill_progress(std::size_t to_fill) const {
  const std::size_t done = synthesized_ + seeded_;
  const std::size_t step = std::max<std::size_t>(1, to_fill / 100);
  if (opt_.progress && (done % step == 0 || done == to_fill))
    opt_.progress("synthesis", static_cast<double>(done) / to_fill);
}

// Onion-peel order (Efros & Leung): the unfilled Fill pixel with the most
// known 8-neighbours first (ties: the lowest index), counts kept current as
// pixels are filled (stale queue entries skipped).
void Synthesizer::fill_onion_peel(std::size_t to_fill) {
  const std::size_t n = static_cast<std::size_t>(W) * H;
  count_.assign(n, 0);
  for (std::size_t p = 0; p < n; ++p) {
    if (state_[p] != PixelState::Fill || known_[p]) continue;
    const int px = p % W, py = p / W;
    int cnt = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = px + dx, y = py + dy;
        if ((dx || dy) && x >= 0 && y >= 0 && x < W && y < H && known_[y * W + x]) ++cnt;
      }
    count_[p] = static_cast<std::uint8_t>(cnt);
    queue_.push({cnt, -static_cast<int>(p)});
  }
  while (!queue_.empty()) {
    const auto [cnt, negp] = queue_.top();
    queue_.pop();
    const int p = -negp;
    if (known_[p] || cnt != count_[p]) continue;  // stale entry
    synthesize_pixel(p);
    report_fill_progress(to_fill);
  }
}

// Direction sweep (ElOptions::direction_x/y; Gorla 2003 section 4): Fill
// pixels in increasing position along the direction, then across it.
void Synthesizer::fill_direction_sweep(std::size_t to_fill) {
  const std::size_t n = static_cast<std::size_t>(W) * H;
  std::vector<int> order;
  for (std::size_t p = 0; p < n; ++p)
    if (state_[p] == PixelState::Fill && !known_[p]) order.push_back(static_cast<int>(p));
  const double dx = opt_.direction_x, dy = opt_.direction_y;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    const double ka = (a % W) * dx + (a / W) * dy, kb = (b % W) * dx + (b / W) * dy;
    if (ka != kb) return ka < kb;
    const double pa = -(a % W) * dy + (a / W) * dx, pb = -(b % W) * dy + (b / W) * dx;
    return pa < pb;
  });
  for (int p : order) {
    if (known_[p]) continue;  // filled by a seed patch
    synthesize_pixel(p);
    report_fill_progress(to_fill);
  }
}

ElResult Synthesizer::run() {
  Timer timer;
  validate();
  const PixelCounts counts = init_canvas();
  rng_.seed(opt_.seed);
  prepare_search_images();
  ElResult res;
  res.window = window_;
  res.first_pass_window = first_;
  res.rotations_used = orientations_used_;
  res.search_images = static_cast<int>(search_.size());
  if (counts.to_fill > 0) {
    if (counts.known == 0 && opt_.order == FillOrder::OnionPeel) seed_at_centre();
    onion_ = opt_.order == FillOrder::OnionPeel;
    if (onion_)
      fill_onion_peel(counts.to_fill);
    else
      fill_direction_sweep(counts.to_fill);
    res.synthesized = synthesized_;
    res.seeded = seeded_;
    res.pass1_candidates = pass1_candidates_;
    res.pass1_widened = widened_;
  }
  res.image = std::move(out_);
  res.source = std::move(source_);
  res.seconds = timer.seconds();
  return res;
}

}  // namespace

std::shared_ptr<const ElPreparedExemplars> el_prepare_exemplars(const std::vector<Image>& exemplars,
                                                                const ElOptions& opt) {
  return prepare(exemplars, opt);
}

int el_first_pass_window(const ElOptions& opt) {
  if (opt.first_pass_window > 0) return opt.first_pass_window;
  return std::min(opt.window, std::max(3, static_cast<int>(std::lround(opt.window * 5.0 / 12.0))));
}

// An alpha channel's 0/1 edges hold most of a 4-channel window's variance:
// with 4 coefficients the kd-tree matches the holes' layout and little of
// the colour, so such an exemplar keeps 6 (decision 501, session 31).
int el_ann_pca_dims(const ElOptions& opt, int channels) {
  if (opt.ann_pca_dims > 0) return opt.ann_pca_dims;
  return channels == 4 ? 6 : 4;
}

ElResult efros_leung_synthesize(const ElInput& input, const ElOptions& opt) {
  Synthesizer s(input, opt);
  return s.run();
}

Image efros_leung_synthesize(const Image& exemplar, int width, int height, const ElOptions& opt) {
  if (width <= 0 || height <= 0)
    throw InvalidInputError("efros_leung: size " + std::to_string(width) + "x" +
                            std::to_string(height) + " must be positive");
  if (exemplar.empty()) throw InvalidInputError("efros_leung: exemplar 0 is empty");
  ElInput in;
  in.exemplars = {exemplar};
  in.target = Image(width, height, exemplar.channels);
  return efros_leung_synthesize(in, opt).image;
}

}  // namespace surftex
