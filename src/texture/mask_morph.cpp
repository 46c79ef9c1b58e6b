// SPDX-License-Identifier: AGPL-3.0-or-later
// Section 1.1 of Ray et al. 2009. Choices where the paper is vague:
//  - dt: the paper writes dt = min_s phi_N(s) / N; phi_N is negative there (the
//    farthest texel from every target), so we use its magnitude D / N.
//  - overlap: printed as sup(1-|s-s'|,0) + sup(1-|t-t'|,0); the overlap ratio of
//    two unit texels is the product (1-|ds|)(1-|dt|), which we use (bilinear
//    splatting, conservative: each texel's weights sum to 1).
//  - velocity: central differences of phi_N, clamped to unit length (phi_N is a
//    distance field, |grad| <= 1 except for discretisation), zero where
//    phi_N >= 0 (only texels outside F_M are advected).
//  - interior dilation: 4-neighbours, read from the advected field (Jacobi, one
//    texel per step); a receiving texel keeps the larger of its own value and
//    the neighbour's, so dilation never lowers phi.
//  - sweeping: the printed condition |phi_0(s)| > (1 - n/N) sup|phi_N| would
//    hollow out large source features from their centres; the purpose stated
//    (limitations 2 and 3: targets no source reaches, undefined sign at the
//    sources of the advection field, i.e. where |phi_N| is largest) is met by
//    |phi_N(s)| > (1 - n/N) sup|phi_N|, our default; the printed variant is
//    available as SweepReference::Source. Either way, at n = N every texel is
//    swept, so F_N == F_M exactly.
//  - H(m): start from equal cumulative sign changes (arc length), then
//    coordinate descent on the variance of the M counts between the chosen
//    masks (exact counts from bit masks), H strictly increasing.
#include "texture/mask_morph.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "geometry/errors.h"
#include "texture/signed_distance_field.h"

namespace surftex {

namespace {

using Bits = std::vector<std::uint64_t>;

Bits sign_bits(const std::vector<float>& phi) {
  Bits b((phi.size() + 63) / 64, 0);
  for (std::size_t i = 0; i < phi.size(); ++i)
    if (phi[i] > 0) b[i >> 6] |= std::uint64_t(1) << (i & 63);
  return b;
}

long long xor_count(const Bits& a, const Bits& b) {
  long long c = 0;
  for (std::size_t i = 0; i < a.size(); ++i) c += __builtin_popcountll(a[i] ^ b[i]);
  return c;
}

void check_mask(const Image& m, const char* what) {
  if (m.empty()) throw InvalidInputError(std::string("morph_feature_masks: ") + what + " is empty");
}

// Variance-like cost of the counts between consecutive chosen steps.
double subsampling_cost(const std::vector<Bits>& bits, const std::vector<int>& H) {
  double s = 0, s2 = 0;
  int M = static_cast<int>(H.size()) - 1;
  for (int m = 0; m < M; ++m) {
    double c = static_cast<double>(xor_count(bits[H[m]], bits[H[m + 1]]));
    s += c;
    s2 += c * c;
  }
  return s2 / M - (s / M) * (s / M);
}

void check_morph_inputs(const Image& source_mask, const Image& target_mask, int layers, const MaskMorphOptions& opt) {
  check_mask(source_mask, "source mask");
  check_mask(target_mask, "target mask");
  if (source_mask.width != target_mask.width || source_mask.height != target_mask.height)
    throw InvalidInputError("morph_feature_masks: source mask " + std::to_string(source_mask.width) +
                            "x" + std::to_string(source_mask.height) + " and target mask " +
                            std::to_string(target_mask.width) + "x" +
                            std::to_string(target_mask.height) + " differ in size");
  if (layers < 1)
    throw InvalidInputError("morph_feature_masks: layers " + std::to_string(layers) + " must be >= 1");
  if (opt.steps != 0 && opt.steps < layers)
    throw InvalidInputError("morph_feature_masks: steps " + std::to_string(opt.steps) +
                            " must be 0 (auto) or >= layers " + std::to_string(layers));
}

/// Sizes of one morph: the tile, the layers M, the steps N and their length dt.
struct MorphPlan {
  int w = 0, h = 0;
  std::size_t n_tex = 0;
  int M = 0, N = 0;
  double dt = 0;
  double sweep_scale = 0;  // sup |phi_N|
};

/// Oversampling: N steps (opt.steps, else enough for the farthest texel to
/// move at most half a texel per step, at least 16 per layer) of length
/// dt = D / N, D the largest distance outside the target's features.
void plan_steps(const std::vector<float>& phiN, const MaskMorphOptions& opt, MorphPlan& p) {
  double far = 0, sup_target = 0;
  for (std::size_t i = 0; i < p.n_tex; ++i) {
    far = std::max(far, -static_cast<double>(phiN[i]));
    sup_target = std::max(sup_target, std::abs(static_cast<double>(phiN[i])));
  }
  far = std::max(far, 1.0);
  p.N = opt.steps > 0 ? opt.steps : std::max(16 * p.M, static_cast<int>(std::ceil(2 * far)));
  p.dt = far / p.N;
  p.sweep_scale = sup_target;
}

/// Where one texel's value goes in an advection step: bilinear splat.
struct Splat {
  std::uint32_t dst[4];
  float wgt[4];
};

/// Advection weights (the velocity field is fixed: the splat is precomputed):
/// velocity = central differences of phi_N clamped to unit length, zero where
/// phi_N >= 0; each texel moved by v dt and splatted bilinearly (wrapped).
std::vector<Splat> advection_splat(const Image& phiN_img, const MorphPlan& p) {
  const int w = p.w, h = p.h;
  const std::vector<float>& phiN = phiN_img.data;
  std::vector<Splat> splat(p.n_tex);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::size_t i = std::size_t(y) * w + x;
      double vx = 0, vy = 0;
      if (phiN[i] < 0) {
        vx = 0.5 * (phiN_img.at_wrap(x + 1, y) - phiN_img.at_wrap(x - 1, y));
        vy = 0.5 * (phiN_img.at_wrap(x, y + 1) - phiN_img.at_wrap(x, y - 1));
        double len = std::hypot(vx, vy);
        if (len > 1) {
          vx /= len;
          vy /= len;
        }
      }
      double ax = x + vx * p.dt, ay = y + vy * p.dt;
      double fx0 = std::floor(ax), fy0 = std::floor(ay);
      double fx = ax - fx0, fy = ay - fy0;
      int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
      auto wrap = [](int v, int n) { return ((v % n) + n) % n; };
      int xs[2] = {wrap(x0, w), wrap(x0 + 1, w)}, ys[2] = {wrap(y0, h), wrap(y0 + 1, h)};
      double wx[2] = {1 - fx, fx}, wy[2] = {1 - fy, fy};
      Splat& s = splat[i];
      for (int b = 0; b < 4; ++b) {
        s.dst[b] = static_cast<std::uint32_t>(std::size_t(ys[b >> 1]) * w + xs[b & 1]);
        s.wgt[b] = static_cast<float>(wx[b & 1] * wy[b >> 1]);
      }
    }
  return splat;
}

/// Interior dilation inside F_M: from the advected field `adv` (Jacobi, one
/// texel per step), a texel inside the target keeps the larger of its own
/// value and its positive 4-neighbours'.
void dilate_interior(const std::vector<float>& phiN, const std::vector<float>& adv, std::vector<float>& next,
                     const MorphPlan& p) {
  const int w = p.w, h = p.h;
  next = adv;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::size_t i = std::size_t(y) * w + x;
      if (phiN[i] <= 0) continue;
      float best = next[i];
      const std::size_t nb[4] = {std::size_t(y) * w + (x + 1) % w, std::size_t(y) * w + (x + w - 1) % w,
                                 std::size_t((y + 1) % h) * w + x, std::size_t((y + h - 1) % h) * w + x};
      for (std::size_t j : nb)
        if (adv[j] > 0) best = std::max(best, adv[j]);
      next[i] = best;
    }
}

/// The N steps phi_0 -> phi_N: advection (conservative splat), interior
/// dilation, sweeping (texels whose reference |phi| exceeds (1 - n/N) sup|phi_N|
/// take phi_N; all at n = N). Returns the sign masks of the N + 1 fields.
std::vector<Bits> morph_steps(const std::vector<float>& phi0, const std::vector<float>& phiN,
                              const std::vector<Splat>& splat, const std::vector<float>& ref, const MorphPlan& p,
                              const MaskMorphOptions& opt) {
  const int N = p.N;
  std::vector<Bits> bits;
  bits.reserve(N + 1);
  std::vector<float> phi(phi0), adv(p.n_tex), next(p.n_tex);
  bits.push_back(sign_bits(phi));
  for (int n = 1; n <= N; ++n) {
    // Advection (conservative splat).
    std::fill(adv.begin(), adv.end(), 0.f);
    for (std::size_t i = 0; i < p.n_tex; ++i) {
      const Splat& s = splat[i];
      for (int b = 0; b < 4; ++b) adv[s.dst[b]] += s.wgt[b] * phi[i];
    }
    dilate_interior(phiN, adv, next, p);
    // Sweeping.
    const double thr = (1.0 - static_cast<double>(n) / N) * p.sweep_scale;
    for (std::size_t i = 0; i < p.n_tex; ++i)
      if (n == N || std::abs(static_cast<double>(ref[i])) > thr) next[i] = phiN[i];
    phi.swap(next);
    bits.push_back(sign_bits(phi));
    if (n % 16 == 0) report_progress(opt.progress, "mask morph", 0.9 * n / N);
  }
  return bits;
}

/// Speed-adaptive subsampling H(m) of the N steps into M layers: arc-length
/// start (equal cumulative sign changes `cum`), then coordinate descent on
/// the variance of the actual counts between the chosen masks.
std::vector<int> subsample_layers(const std::vector<Bits>& bits, const std::vector<double>& cum, int M, int N,
                                  int rounds) {
  std::vector<int> H(M + 1);
  H[0] = 0;
  H[M] = N;
  for (int m = 1; m < M; ++m) {
    double target = cum[N] * m / M;
    int n = static_cast<int>(std::lower_bound(cum.begin(), cum.end(), target) - cum.begin());
    H[m] = std::clamp(n, H[m - 1] + 1, N - (M - m));
  }
  double cost = subsampling_cost(bits, H);
  for (int round = 0; round < rounds && M > 1; ++round) {
    bool improved = false;
    for (int m = 1; m < M; ++m) {
      int best_n = H[m];
      for (int n = H[m - 1] + 1; n < H[m + 1]; ++n) {
        if (n == H[m]) continue;
        int keep = H[m];
        H[m] = n;
        double c = subsampling_cost(bits, H);
        H[m] = keep;
        if (c < cost - 1e-9) {
          cost = c;
          best_n = n;
        }
      }
      if (best_n != H[m]) {
        H[m] = best_n;
        improved = true;
      }
    }
    if (!improved) break;
  }
  return H;
}

}  // namespace

long long count_sign_changes(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height || a.empty())
    throw InvalidInputError("count_sign_changes: masks of different or empty size");
  long long c = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) c += (a.at(x, y, 0) > 0.5f) != (b.at(x, y, 0) > 0.5f);
  return c;
}

/// Ray et al. 2009 s.1.1: the signed distance fields of both masks, the
/// oversampled advection of phi_0 towards phi_N, and the M + 1 masks chosen
/// among the N + 1 steps.
MaskMorphResult morph_feature_masks(const Image& source_mask, const Image& target_mask, int layers,
                                    const MaskMorphOptions& opt) {
  check_morph_inputs(source_mask, target_mask, layers, opt);
  MorphPlan p;
  p.w = source_mask.width;
  p.h = source_mask.height;
  p.n_tex = static_cast<std::size_t>(p.w) * p.h;
  p.M = layers;
  const Image phi0_img = signed_distance_field(source_mask);
  const Image phiN_img = signed_distance_field(target_mask);
  const std::vector<float>& phi0 = phi0_img.data;
  const std::vector<float>& phiN = phiN_img.data;
  plan_steps(phiN, opt, p);
  const std::vector<Splat> splat = advection_splat(phiN_img, p);
  const std::vector<float>& ref = opt.sweep_reference == MaskMorphOptions::SweepReference::Target ? phiN : phi0;
  const std::vector<Bits> bits = morph_steps(phi0, phiN, splat, ref, p, opt);
  const int N = p.N, M = p.M;

  MaskMorphResult res;
  res.steps = N;
  res.step_length = p.dt;
  res.sweep_scale = p.sweep_scale;
  res.step_sign_changes.resize(N);
  std::vector<double> cum(N + 1, 0.0);
  for (int n = 0; n < N; ++n) {
    res.step_sign_changes[n] = xor_count(bits[n], bits[n + 1]);
    cum[n + 1] = cum[n] + static_cast<double>(res.step_sign_changes[n]);
  }
  const std::vector<int> H = subsample_layers(bits, cum, M, N, opt.subsampling_rounds);
  res.step_of_layer = H;
  res.masks.reserve(M + 1);
  for (int m = 0; m <= M; ++m) {
    Image mask(p.w, p.h, 1);
    const Bits& b = bits[H[m]];
    for (std::size_t i = 0; i < p.n_tex; ++i) mask.data[i] = (b[i >> 6] >> (i & 63)) & 1 ? 1.f : 0.f;
    res.masks.push_back(std::move(mask));
  }
  for (int m = 0; m < M; ++m) res.sign_changes.push_back(xor_count(bits[H[m]], bits[H[m + 1]]));
  report_progress(opt.progress, "mask morph", 1.0);
  return res;
}

}  // namespace surftex
