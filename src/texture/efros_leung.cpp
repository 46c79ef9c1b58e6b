// SPDX-License-Identifier: AGPL-3.0-or-later
// Two-pass Efros-Leung synthesis (Gorla et al. 2003, 3.3, 3.3.2, 5).
#include "texture/efros_leung.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <queue>
#include <random>
#include <string>
#include <utility>

#include "geometry/errors.h"
#include "geometry/timer.h"
#include "texture/rotated_exemplars.h"

namespace surftex {
namespace {

using Scored = std::pair<float, int>;  // (error, candidate position); compared lexicographically
constexpr int kLanes = 8;
constexpr std::size_t kPad = 4 * kLanes;

// Pass-1 kernel: unweighted SSD of `len` consecutive candidate positions
// starting at buffer index `row`, over `nk` known neighbours (buffer offsets
// delta[k], values tv[k * C + c]). Candidates are processed 8 at a time in one
// vector register (GCC vector extension), so the accumulator never leaves the
// register; every lane performs the same operations in the same order, so
// the result does not depend on the instruction set picked at run time.
// Early abandon: every 4 neighbours, if all 8 partial sums exceed `limit`
// (the current n-th best) the group stops; its outputs are then partial
// sums, already > limit, which the caller discards as it would the full ones.
typedef float V8 __attribute__((vector_size(kLanes * sizeof(float))));
typedef int I8 __attribute__((vector_size(kLanes * sizeof(int))));

template <int C>
__attribute__((always_inline)) inline void span_ssd_impl(const float* planes, std::size_t plane_size,
                                                         const int* delta, const float* tv, int nk,
                                                         int len, std::size_t row, float limit,
                                                         float* out) {
  for (int i = 0; i < len; i += kLanes) {
    V8 acc = {};
    V8 lim;
    for (int l = 0; l < kLanes; ++l) lim[l] = limit;
    for (int k = 0; k < nk; ++k) {
      const float* base = planes + row + i + delta[k];
      for (int c = 0; c < C; ++c) {
        V8 v;
        std::memcpy(&v, base + c * plane_size, sizeof(V8));
        const V8 d = v - tv[k * C + c];
        acc += d * d;
      }
      if ((k & 3) == 3) {
        const I8 over = acc > lim;
        int all = -1;
        for (int l = 0; l < kLanes; ++l) all &= over[l];
        if (all) break;
      }
    }
    std::memcpy(out + i, &acc, sizeof(V8));  // out has room for a full group
  }
}

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define SURFTEX_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define SURFTEX_SIMD_CLONES
#endif

SURFTEX_SIMD_CLONES void span_ssd_c1(const float* p, std::size_t ps, const int* d, const float* t,
                                     int nk, int len, std::size_t row, float lim, float* out) {
  span_ssd_impl<1>(p, ps, d, t, nk, len, row, lim, out);
}
SURFTEX_SIMD_CLONES void span_ssd_c3(const float* p, std::size_t ps, const int* d, const float* t,
                                     int nk, int len, std::size_t row, float lim, float* out) {
  span_ssd_impl<3>(p, ps, d, t, nk, len, row, lim, out);
}
SURFTEX_SIMD_CLONES void span_ssd_c4(const float* p, std::size_t ps, const int* d, const float* t,
                                     int nk, int len, std::size_t row, float lim, float* out) {
  span_ssd_impl<4>(p, ps, d, t, nk, len, row, lim, out);
}
// Pass-2 kernel: Gaussian-weighted SSD of one candidate `id`. The window is
// stored per active row as nv groups of 8 offsets starting at buffer offset
// roff[r]; weights are 0 at unknown offsets (and past the window), so they
// contribute exactly 0. Lanes are summed in a fixed order at the end.
template <int C>
__attribute__((always_inline)) inline float weighted_ssd_impl(const float* planes,
                                                              std::size_t plane_size, int Cr,
                                                              const int* roff, const float* w,
                                                              const float* t, int nrows, int nv,
                                                              int id) {
  const int ch = C > 0 ? C : Cr;
  V8 acc = {};
  for (int r = 0; r < nrows; ++r)
    for (int g = 0; g < nv; ++g) {
      const std::size_t o = static_cast<std::size_t>(r) * nv + g;
      V8 wv;
      std::memcpy(&wv, w + o * kLanes, sizeof(V8));
      V8 sq = {};
      for (int c = 0; c < ch; ++c) {
        V8 v, tv;
        std::memcpy(&v, planes + c * plane_size + id + roff[r] + g * kLanes, sizeof(V8));
        std::memcpy(&tv, t + ((static_cast<std::size_t>(r) * ch + c) * nv + g) * kLanes, sizeof(V8));
        const V8 d = v - tv;
        sq += d * d;
      }
      acc += wv * sq;
    }
  float e = 0.f;
  for (int l = 0; l < kLanes; ++l) e += acc[l];
  return e;
}
SURFTEX_SIMD_CLONES float weighted_ssd_c1(const float* p, std::size_t ps, const int* ro,
                                          const float* w, const float* t, int nr, int nv, int id) {
  return weighted_ssd_impl<1>(p, ps, 1, ro, w, t, nr, nv, id);
}
SURFTEX_SIMD_CLONES float weighted_ssd_c3(const float* p, std::size_t ps, const int* ro,
                                          const float* w, const float* t, int nr, int nv, int id) {
  return weighted_ssd_impl<3>(p, ps, 3, ro, w, t, nr, nv, id);
}
SURFTEX_SIMD_CLONES float weighted_ssd_c4(const float* p, std::size_t ps, const int* ro,
                                          const float* w, const float* t, int nr, int nv, int id) {
  return weighted_ssd_impl<4>(p, ps, 4, ro, w, t, nr, nv, id);
}
float weighted_ssd_any(const float* p, std::size_t ps, int C, const int* ro, const float* w,
                       const float* t, int nr, int nv, int id) {
  return weighted_ssd_impl<0>(p, ps, C, ro, w, t, nr, nv, id);
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
  std::vector<int> ids;  // every candidate position y*pw+x, increasing
  // Span blocks of roughly equal size for the parallel pass 1.
  std::vector<std::pair<int, int>> blocks;
  int max_span = 0;

  const float* plane(int c) const { return planes.data() + static_cast<std::size_t>(c) * pw * ph; }
};

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
        sum[(y + 1) * (s.pw + 1) + x + 1] = (r.valid.at(x, y) > 0.5f ? 0 : 1) +
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
    s.max_span = std::max(s.max_span, sp.x1 - sp.x0);
    for (int x = sp.x0; x < sp.x1; ++x) s.ids.push_back(sp.y * s.pw + x);
  }
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
  return s;
}

// A known neighbour of the pixel being synthesised.
struct KnownOffset {
  int dx, dy;
  float weight;
  bool in_first;
};

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
  void score_full(const SearchImage& s, const std::vector<int>& ids, std::vector<Scored>& out);
  void synthesize_pixel(int p);
  void seed_patch(int p);
  void mark_filled(int p);

  const ElInput& in_;
  const ElOptions& opt_;
  int W = 0, H = 0, C = 0, window_ = 0, first_ = 0;
  double sigma_ = 0;
  std::vector<PixelState> state_;
  std::vector<std::uint8_t> known_;
  Image out_;
  std::vector<int> key_;                 // per pixel: index into search_ (or -1)
  std::vector<SearchImage> search_;
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
  std::vector<int> first_idx_;           // known neighbours inside the first-pass window
  std::vector<int> p2_roff_;
  std::vector<float> p2_w_, p2_t_;
  int p2_row_dy_ = 0;
  std::vector<int> p1_delta_;
  std::vector<float> p1_value_;
  std::vector<std::vector<Scored>> block_heaps_;
  std::vector<std::vector<float>> block_acc_;
  std::vector<int> pre_;
  std::vector<Scored> scored_;
  std::size_t synthesized_ = 0, seeded_ = 0;
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
  if (!(opt_.gaussian_sigma >= 0.0) || !std::isfinite(opt_.gaussian_sigma))
    bad("gaussian_sigma " + std::to_string(opt_.gaussian_sigma) + " must be finite and >= 0");
  if (!(opt_.pick_fraction >= 0.0 && opt_.pick_fraction <= 1.0))
    bad("pick_fraction " + std::to_string(opt_.pick_fraction) + " outside [0,1]");
  if (opt_.pick_min < 1) bad("pick_min " + std::to_string(opt_.pick_min) + " < 1");
  if (!std::isfinite(opt_.error_tolerance))
    bad("error_tolerance " + std::to_string(opt_.error_tolerance) + " is not finite");
  if (opt_.rotations < 1 || opt_.rotations > 128)
    bad("rotations " + std::to_string(opt_.rotations) + " outside 1..128");
  if (opt_.order == FillOrder::Direction &&
      (!std::isfinite(opt_.direction_x) || !std::isfinite(opt_.direction_y) ||
       (opt_.direction_x == 0.0 && opt_.direction_y == 0.0)))
    bad("direction (" + std::to_string(opt_.direction_x) + ", " +
        std::to_string(opt_.direction_y) + ") must be finite and non-zero");
  if (in_.exemplars.empty()) bad("exemplars: none given");
  for (std::size_t e = 0; e < in_.exemplars.size(); ++e) {
    const Image& ex = in_.exemplars[e];
    if (ex.empty() || ex.data.size() != static_cast<std::size_t>(ex.width) * ex.height * ex.channels)
      bad("exemplar " + std::to_string(e) + " is empty");
    if (ex.channels != in_.exemplars[0].channels)
      bad("exemplar " + std::to_string(e) + " has " + std::to_string(ex.channels) +
          " channels, exemplar 0 has " + std::to_string(in_.exemplars[0].channels));
    if (!opt_.periodic_exemplar && (ex.width < opt_.window || ex.height < opt_.window))
      bad("exemplar " + std::to_string(e) + " (" + std::to_string(ex.width) + "x" +
          std::to_string(ex.height) + ") is smaller than the window " +
          std::to_string(opt_.window));
    for (float v : ex.data)
      if (!std::isfinite(v)) bad("exemplar " + std::to_string(e) + " holds a non-finite value");
  }
  const Image& t = in_.target;
  if (t.width <= 0 || t.height <= 0)
    bad("target size " + std::to_string(t.width) + "x" + std::to_string(t.height) +
        " must be positive");
  if (t.channels != in_.exemplars[0].channels)
    bad("target has " + std::to_string(t.channels) + " channels, the exemplars " +
        std::to_string(in_.exemplars[0].channels));
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
}

void Synthesizer::prepare_search_images() {
  const std::size_t n = static_cast<std::size_t>(W) * H;
  const bool oriented = !in_.angle.empty() || static_cast<bool>(in_.angle_fn);
  const int K = oriented ? opt_.rotations : 1;
  const int E = static_cast<int>(in_.exemplars.size());
  std::vector<int> pair_of(n, -1);
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
    needed[pair_of[p]] = 1;
  }
  std::vector<int> slot(needed.size(), -1);
  const int margin = std::max(-lo_of(window_), hi_of(window_));
  for (int e = 0; e < E; ++e)
    for (int k = 0; k < K; ++k) {
      if (!needed[e * K + k]) continue;
      const Image& ex = in_.exemplars[e];
      RotatedExemplar r = rotate_exemplar(ex, 2.0 * M_PI * k / K, opt_.periodic_exemplar, margin);
      SearchImage s = make_search_image(r, window_, opt_.periodic_exemplar, margin, ex.width, ex.height);
      if (s.ids.empty())
        throw InvalidInputError("efros_leung: exemplar " + std::to_string(e) + " rotated by " +
                                std::to_string(360.0 * k / K) +
                                " degrees has no position where the whole window " +
                                std::to_string(window_) +
                                " fits; use a larger exemplar, a smaller window or "
                                "periodic_exemplar");
      slot[e * K + k] = static_cast<int>(search_.size());
      search_.push_back(std::move(s));
    }
  key_.assign(n, -1);
  for (std::size_t p = 0; p < n; ++p)
    if (pair_of[p] >= 0) key_[p] = slot[pair_of[p]];
}

void Synthesizer::gather_known(int p, const SearchImage& s) {
  delta_.clear();
  value_.clear();
  weight_.clear();
  first_idx_.clear();
  const int px = p % W, py = p / W;
  const int lo = lo_of(window_), hi = hi_of(window_);
  const int flo = lo_of(first_), fhi = hi_of(first_);
  const int nv = (window_ + kLanes - 1) / kLanes, rowlen = nv * kLanes;
  p2_roff_.clear();
  p2_w_.clear();
  p2_t_.clear();
  int g = 0;
  for (int dy = lo; dy <= hi; ++dy)
    for (int dx = lo; dx <= hi; ++dx, ++g) {
      const int x = px + dx, y = py + dy;
      if (x < 0 || y < 0 || x >= W || y >= H) continue;
      const int q = y * W + x;
      if (!known_[q]) continue;
      if (dx >= flo && dx <= fhi && dy >= flo && dy <= fhi)
        first_idx_.push_back(static_cast<int>(delta_.size()));
      delta_.push_back(dy * s.pw + dx);
      weight_.push_back(gauss_[g]);
      const float* v = out_.pixel(x, y);
      value_.insert(value_.end(), v, v + C);
      // Row-grouped copy for the pass-2 kernel.
      if (p2_roff_.empty() || p2_row_dy_ != dy) {
        p2_row_dy_ = dy;
        p2_roff_.push_back(dy * s.pw + lo);
        p2_w_.resize(p2_w_.size() + rowlen, 0.f);
        p2_t_.resize(p2_t_.size() + static_cast<std::size_t>(rowlen) * C, 0.f);
      }
      const std::size_t r = p2_roff_.size() - 1;
      p2_w_[r * rowlen + (dx - lo)] = gauss_[g];
      for (int c = 0; c < C; ++c) p2_t_[(r * C + c) * rowlen + (dx - lo)] = v[c];
    }
}

// Pass 1: the n best candidates by unweighted SSD over the known neighbours
// listed in first_idx_ (or all known neighbours if none is in the small
// window). Writes pre_ (ids, increasing error). Returns the count.
int Synthesizer::pass1(const SearchImage& s, std::size_t n) {
  std::vector<int> use = first_idx_;
  if (use.empty())
    for (int k = 0; k < static_cast<int>(delta_.size()); ++k) use.push_back(k);
  const int nb = static_cast<int>(s.blocks.size());
  if (static_cast<int>(block_heaps_.size()) < nb) {
    block_heaps_.resize(nb);
    block_acc_.resize(nb);
  }
  // Offsets and values of the neighbours pass 1 compares, contiguous.
  p1_delta_.clear();
  p1_value_.clear();
  for (int k : use) {
    p1_delta_.push_back(delta_[k]);
    p1_value_.insert(p1_value_.end(), value_.begin() + static_cast<std::ptrdiff_t>(k) * C,
                     value_.begin() + static_cast<std::ptrdiff_t>(k + 1) * C);
  }
  const int nk = static_cast<int>(p1_delta_.size());
  const std::size_t ps = static_cast<std::size_t>(s.pw) * s.ph;
  // Each block keeps a buffer of candidates that may still be among the n
  // best: those with error <= limit, the n-th smallest error seen so far
  // (re-established by nth_element whenever the buffer reaches 8n). Exact:
  // anything above the limit has n better candidates in the same block.
  auto run_block = [&](int b) {
    std::vector<Scored>& buf = block_heaps_[b];
    std::vector<float>& acc = block_acc_[b];
    buf.clear();
    acc.resize(s.max_span + kLanes);
    float* a = acc.data();
    float limit = std::numeric_limits<float>::infinity();
    const std::size_t cap = std::max<std::size_t>(8 * n, 64);
    for (int si = s.blocks[b].first; si < s.blocks[b].second; ++si) {
      const auto& sp = s.spans[si];
      const int len = sp.x1 - sp.x0;
      const std::size_t row = static_cast<std::size_t>(sp.y) * s.pw + sp.x0;
      switch (C) {
        case 1: span_ssd_c1(s.planes.data(), ps, p1_delta_.data(), p1_value_.data(), nk, len, row, limit, a); break;
        case 3: span_ssd_c3(s.planes.data(), ps, p1_delta_.data(), p1_value_.data(), nk, len, row, limit, a); break;
        case 4: span_ssd_c4(s.planes.data(), ps, p1_delta_.data(), p1_value_.data(), nk, len, row, limit, a); break;
        default: span_ssd_any(s.planes.data(), ps, C, p1_delta_.data(), p1_value_.data(), nk, len, row, a);
      }
      const int id0 = sp.y * s.pw + sp.x0;
      for (int i = 0; i < len; ++i)
        if (a[i] <= limit) buf.push_back({a[i], id0 + i});
      if (buf.size() >= cap) {
        std::nth_element(buf.begin(), buf.begin() + (n - 1), buf.end());
        buf.resize(n);
        limit = buf[n - 1].first;  // the n-th smallest error
      }
    }
  };
  const std::size_t work = s.ids.size() * use.size() * static_cast<std::size_t>(C);
  if (nb > 1 && work > 40000)
    tbb::parallel_for(0, nb, run_block);
  else
    for (int b = 0; b < nb; ++b) run_block(b);
  scored_.clear();
  for (int b = 0; b < nb; ++b)
    scored_.insert(scored_.end(), block_heaps_[b].begin(), block_heaps_[b].end());
  if (scored_.size() > n) {
    std::nth_element(scored_.begin(), scored_.begin() + n, scored_.end());
    scored_.resize(n);
  }
  std::sort(scored_.begin(), scored_.end());
  pre_.clear();
  for (const auto& v : scored_) pre_.push_back(v.second);
  return static_cast<int>(pre_.size());
}

// Pass 2: Gaussian-weighted SSD over every known neighbour, renormalised by
// the sum of the known weights; sorted by (error, id).
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
  auto score = [&](std::size_t i) {
    const int id = ids[i];
    float e;
    switch (C) {
      case 1: e = weighted_ssd_c1(P, ps, p2_roff_.data(), p2_w_.data(), p2_t_.data(), nr, nv, id); break;
      case 3: e = weighted_ssd_c3(P, ps, p2_roff_.data(), p2_w_.data(), p2_t_.data(), nr, nv, id); break;
      case 4: e = weighted_ssd_c4(P, ps, p2_roff_.data(), p2_w_.data(), p2_t_.data(), nr, nv, id); break;
      default: e = weighted_ssd_any(P, ps, C, p2_roff_.data(), p2_w_.data(), p2_t_.data(), nr, nv, id);
    }
    out[i] = {e * inv, id};
  };
  const std::size_t work = ids.size() * nk * static_cast<std::size_t>(C);
  if (work > 200000)
    tbb::parallel_for(std::size_t(0), ids.size(), score);
  else
    for (std::size_t i = 0; i < ids.size(); ++i) score(i);
  std::sort(out.begin(), out.end());
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
  const SearchImage& s = search_[search_key(p)];
  const int id = s.ids[rng_() % s.ids.size()];
  const int px = p % W, py = p / W;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = px + dx, y = py + dy;
      if (x < 0 || y < 0 || x >= W || y >= H) continue;
      const int q = y * W + x;
      // Only Fill pixels that search the same exemplar and orientation, so
      // a seed never puts texture k where the index map asks for another.
      if (state_[q] != PixelState::Fill || known_[q] || key_[q] != key_[p]) continue;
      for (int c = 0; c < C; ++c) out_.at(x, y, c) = s.plane(c)[id + dy * s.pw + dx];
      mark_filled(q);
      ++seeded_;
    }
}

void Synthesizer::synthesize_pixel(int p) {
  const SearchImage& s = search_[search_key(p)];
  gather_known(p, s);
  if (delta_.empty()) {
    seed_patch(p);
    return;
  }
  const std::size_t total = s.ids.size();
  if (opt_.single_pass) {
    score_full(s, s.ids, scored_);
  } else {
    std::size_t n = opt_.preselect > 0 ? static_cast<std::size_t>(opt_.preselect)
                                       : static_cast<std::size_t>(in_.exemplars[0].width);
    if (!in_.exemplar_index.empty())
      n = opt_.preselect > 0 ? n : static_cast<std::size_t>(in_.exemplars[in_.exemplar_index[p]].width);
    n = std::min(n, total);
    pass1(s, n);
    score_full(s, pre_, scored_);
  }
  const std::size_t m = scored_.size();
  std::size_t k = std::max<std::size_t>(static_cast<std::size_t>(opt_.pick_min),
                                        static_cast<std::size_t>(std::ceil(opt_.pick_fraction * m)));
  k = std::min(k, m);
  if (opt_.error_tolerance >= 0) {
    const double limit = scored_[0].first * (1.0 + opt_.error_tolerance);
    std::size_t within = 1;
    while (within < k && scored_[within].first <= limit) ++within;
    k = within;
  }
  const int id = scored_[k > 1 ? rng_() % k : 0].second;
  const int px = p % W, py = p / W;
  for (int c = 0; c < C; ++c) out_.at(px, py, c) = s.plane(c)[id];
  mark_filled(p);
  ++synthesized_;
}

ElResult Synthesizer::run() {
  Timer timer;
  validate();
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
  std::size_t any_known = 0, to_fill = 0;
  for (std::size_t p = 0; p < n; ++p) {
    if (state_[p] == PixelState::Known) {
      known_[p] = 1;
      ++any_known;
      for (int c = 0; c < C; ++c)
        if (!std::isfinite(out_.data[p * C + c]))
          throw InvalidInputError("efros_leung: target holds a non-finite value at Known pixel (" +
                                  std::to_string(p % W) + ", " + std::to_string(p / W) + ")");
    }
    if (state_[p] == PixelState::Fill) ++to_fill;
  }
  const int lo = lo_of(window_), hi = hi_of(window_);
  for (int dy = lo; dy <= hi; ++dy)
    for (int dx = lo; dx <= hi; ++dx)
      gauss_.push_back(static_cast<float>(std::exp(-(dx * dx + dy * dy) / (2.0 * sigma_ * sigma_))));
  rng_.seed(opt_.seed);
  prepare_search_images();

  ElResult res;
  res.window = window_;
  res.first_pass_window = first_;
  res.rotations_used = static_cast<int>(search_.size());
  if (to_fill == 0) {
    res.image = std::move(out_);
    res.seconds = timer.seconds();
    return res;
  }
  // Onion peel on an empty target: the first seed goes to the Fill pixel
  // nearest the centre of the Fill pixels' bounding box. (A direction sweep
  // seeds at its first pixel instead.)
  if (any_known == 0 && opt_.order == FillOrder::OnionPeel) {
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
    onion_ = false;  // counts are initialised below, after the seed
    seed_patch(best);
  }
  onion_ = opt_.order == FillOrder::OnionPeel;
  std::size_t done = synthesized_ + seeded_;
  const std::size_t step = std::max<std::size_t>(1, to_fill / 100);
  auto progress = [&] {
    if (opt_.progress && (done % step == 0 || done == to_fill))
      opt_.progress("synthesis", static_cast<double>(done) / to_fill);
  };
  if (onion_) {
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
      done = synthesized_ + seeded_;
      progress();
    }
  } else {
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
      done = synthesized_ + seeded_;
      progress();
    }
  }
  res.image = std::move(out_);
  res.synthesized = synthesized_;
  res.seeded = seeded_;
  res.seconds = timer.seconds();
  return res;
}

}  // namespace

int el_first_pass_window(const ElOptions& opt) {
  if (opt.first_pass_window > 0) return opt.first_pass_window;
  return std::min(opt.window, std::max(3, static_cast<int>(std::lround(opt.window * 5.0 / 12.0))));
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
