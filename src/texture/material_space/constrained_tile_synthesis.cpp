// SPDX-License-Identifier: AGPL-3.0-or-later
// Section 1.2 of Ray et al. 2009. Choices where the paper is vague:
//  - the pyramid: texture/gaussian_pyramid.h, toroidal (binomial (1 4 6 4 1)/16
//    blur, even pixels kept, odd sides round up); mask pyramids are blurred
//    too, so coarse masks are fractional coverages;
//  - the neighbourhood: the paper compares 3x3 neighbourhoods, the brief asks
//    for a 5x5 colour neighbourhood reduced by PCA plus the 3x3 mask; the PCA
//    is fitted per level on (a regular subsample of) the exemplar's own 5x5
//    neighbourhoods, colours in [0,1], mask entries in [0,1] times mask_weight;
//  - the ANN search returns a few candidates; with the paper's reuse penalty
//    one needs more than the single nearest. We add the current and the four
//    coherent candidates (as in Ashikhmin / LH06) and pick the candidate of
//    lowest distance^2 + penalty; the current one is always a candidate, so a
//    pass never makes a texel's own cost worse;
//  - the identity layer (layer 0 from its own tile) is not optimised: its
//    neighbourhoods already match exactly (the paper's I_0 = identity);
//  - the coarsest level runs layer after layer (each starts from the previous
//    one); the finer levels of different layers are independent and run in
//    parallel, each with its own seeded random stream; the exemplar's levels
//    (PCA, feature vectors, kd-tree) are built in parallel too;
//  - speed: at the finer levels only the first `fine_ann_passes` passes query
//    the kd-tree, and (fine_ann_only_mismatched) only for the texels whose
//    current exemplar pixel's 3x3 mask disagrees with the target's; other
//    texels and later passes choose among the current and coherent
//    candidates (the upsampled map follows the mask away from its edges).
#include "texture/material_space/constrained_tile_synthesis.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <numeric>
#include <random>
#include <string>

#include "geometry/errors.h"
#include "texture/gaussian_pyramid.h"
#include "texture/pca_kdtree.h"

namespace surftex {

namespace {

inline int wrap(int v, int n) {
  v %= n;
  return v < 0 ? v + n : v;
}

// Pyramid, index 0 = coarsest: texture/gaussian_pyramid.h, toroidal (the
// exemplar and the masks are tiles). Odd sides round up (ceil(w/2)).
std::vector<Image> pyramid(const Image& finest, int levels) {
  PyramidOptions po;
  po.levels = levels;
  po.toroidal = true;
  std::vector<Image> p = gaussian_pyramid(finest, po);
  std::reverse(p.begin(), p.end());
  return p;
}

Image first_channel(const Image& m) {
  Image out(m.width, m.height, 1);
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) out.at(x, y) = m.at(x, y, 0) > 0.5f ? 1.f : 0.f;
  return out;
}

constexpr int kColR = 2;  // 5x5 colour window
constexpr int kMaskR = 1; // 3x3 mask window

// Everything about the exemplar at one level.
struct ExemplarLevel {
  Image colour, mask;
  int w = 0, h = 0, C = 0, d = 0, D = 0;
  int dm = 0;                  // mask coefficients
  PcaBasis colour_pca;         // 25 C -> d
  PcaBasis mask_pca;           // 9 (weighted mask neighbourhood) -> dm
  std::unique_ptr<KdIndex<float>> tree;  // n x D feature vectors
  double scale = 0;            // V: mean squared norm of centred feature vectors
  const float* feature(std::size_t i) const { return tree->point(i); }
};

// PCA of the `raw`-dimensional vectors vec(x, y) over a regular subsample (at
// most ~16k) of the w x h pixels (texture/pca_kdtree.h).
template <class VecFn>
PcaBasis fit_pca(int raw, int d, int w, int h, VecFn vec) {
  int stride = 1;
  while ((std::size_t(w) * h) / (std::size_t(stride) * stride) > 16384) ++stride;
  std::vector<float> v(raw);
  PcaFit fit(raw);
  for (int y = 0; y < h; y += stride)
    for (int x = 0; x < w; x += stride) {
      vec(x, y, v.data());
      fit.add(v.data());
    }
  return fit.fit(d, "constrained tile synthesis (level " + std::to_string(w) + "x" + std::to_string(h) + ")");
}

void build_exemplar_level(ExemplarLevel& L, const Image& colour, const Image& mask,
                          const ConstrainedSynthesisOptions& opt) {
  L.colour = colour;
  L.mask = mask;
  L.w = colour.width;
  L.h = colour.height;
  L.C = colour.channels;
  const int raw = (2 * kColR + 1) * (2 * kColR + 1) * L.C;
  L.d = std::min(opt.pca_dims, raw);
  const int mask_n = (2 * kMaskR + 1) * (2 * kMaskR + 1);
  L.dm = opt.mask_pca_dims > 0 ? std::min(opt.mask_pca_dims, mask_n) : mask_n;
  L.D = L.d + L.dm;
  const std::size_t n = std::size_t(L.w) * L.h;
  auto raw_vec = [&](int x, int y, float* out) {
    int k = 0;
    for (int dy = -kColR; dy <= kColR; ++dy)
      for (int dx = -kColR; dx <= kColR; ++dx) {
        const float* p = colour.pixel(wrap(x + dx, L.w), wrap(y + dy, L.h));
        for (int c = 0; c < L.C; ++c) out[k++] = p[c];
      }
  };
  L.colour_pca = fit_pca(raw, L.d, L.w, L.h, raw_vec);
  auto mask_vec = [&](int x, int y, float* out) {
    int k = 0;
    for (int dy = -kMaskR; dy <= kMaskR; ++dy)
      for (int dx = -kMaskR; dx <= kMaskR; ++dx)
        out[k++] = static_cast<float>(opt.mask_weight) * mask.at(wrap(x + dx, L.w), wrap(y + dy, L.h));
  };
  L.mask_pca = fit_pca(mask_n, L.dm, L.w, L.h, mask_vec);
  // Feature vectors of every exemplar pixel.
  std::vector<float> pts(n * L.D, 0.f);
  tbb::parallel_for(0, L.h, [&](int y) {
    std::vector<float> rv(raw);
    float mv[9];
    for (int x = 0; x < L.w; ++x) {
      raw_vec(x, y, rv.data());
      float* f = &pts[(std::size_t(y) * L.w + x) * L.D];
      L.colour_pca.project(rv.data(), f);
      mask_vec(x, y, mv);
      L.mask_pca.project(mv, f + L.d);
    }
  });
  std::vector<double> fmean(L.D, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < L.D; ++k) fmean[k] += pts[i * L.D + k];
  for (double& m : fmean) m /= double(n);
  double var = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < L.D; ++k) {
      double e = pts[i * L.D + k] - fmean[k];
      var += e * e;
    }
  L.scale = std::max(var / double(n), 1e-12);
  L.tree = std::make_unique<KdIndex<float>>(std::move(pts), L.D);
}

// True when the 3x3 feature mask around texel (i, j)'s current exemplar pixel
// differs (thresholded at 0.5) from the target mask around (i, j).
bool mask_mismatch(const IndirectionMap& map, const ExemplarLevel& L, const Image& target_mask, int i, int j) {
  const int w = map.width, h = map.height;
  const int cx = map.x(i, j), cy = map.y(i, j);
  for (int dy = -kMaskR; dy <= kMaskR; ++dy)
    for (int dx = -kMaskR; dx <= kMaskR; ++dx)
      if ((L.mask.at(wrap(cx + dx, L.w), wrap(cy + dy, L.h)) > 0.5f) !=
          (target_mask.at(wrap(i + dx, w), wrap(j + dy, h)) > 0.5f))
        return true;
  return false;
}

// Optimises one indirection map in place at one level (section 1.2 "Optimization").
void optimise_map(IndirectionMap& map, const ExemplarLevel& L, const Image& target_mask, int passes,
                  std::uint64_t seed, const ConstrainedSynthesisOptions& opt, double exclude,
                  int ann_passes, bool ann_only_mismatched) {
  const int w = map.width, h = map.height;
  const std::size_t n_out = std::size_t(w) * h;
  const int raw = (2 * kColR + 1) * (2 * kColR + 1) * L.C;
  std::vector<int> usage(std::size_t(L.w) * L.h, 0);
  auto ex_index = [&](std::size_t t) {
    return std::size_t(map.coords[2 * t + 1]) * L.w + std::size_t(map.coords[2 * t]);
  };
  for (std::size_t t = 0; t < n_out; ++t) ++usage[ex_index(t)];
  const double penalty = opt.reuse_penalty * L.scale;
  const std::size_t k_ann = static_cast<std::size_t>(opt.candidates);
  std::vector<std::uint32_t> nn_idx(k_ann);
  std::vector<float> nn_d2(k_ann), rv(raw), q(L.D);
  float mv[9];
  std::vector<std::uint32_t> order(n_out);
  std::iota(order.begin(), order.end(), 0u);
  std::mt19937_64 rng(seed);
  for (int pass = 0; pass < passes; ++pass) {
    std::shuffle(order.begin(), order.end(), rng);
    for (std::uint32_t t : order) {
      const int i = static_cast<int>(t % w), j = static_cast<int>(t / w);
      // Query vector: colours the current map puts around (i,j), PCA-projected ...
      int k = 0;
      for (int dy = -kColR; dy <= kColR; ++dy)
        for (int dx = -kColR; dx <= kColR; ++dx) {
          std::size_t tt = std::size_t(wrap(j + dy, h)) * w + wrap(i + dx, w);
          const float* p = L.colour.pixel(map.coords[2 * tt], map.coords[2 * tt + 1]);
          for (int c = 0; c < L.C; ++c, ++k) rv[k] = p[c];
        }
      L.colour_pca.project(rv.data(), q.data());
      // ... followed by the target mask around (i,j), projected likewise.
      k = 0;
      for (int dy = -kMaskR; dy <= kMaskR; ++dy)
        for (int dx = -kMaskR; dx <= kMaskR; ++dx, ++k)
          mv[k] = static_cast<float>(opt.mask_weight) * target_mask.at(wrap(i + dx, w), wrap(j + dy, h));
      L.mask_pca.project(mv, q.data() + L.d);
      std::size_t found = 0;
      if (pass < ann_passes && (!ann_only_mismatched || mask_mismatch(map, L, target_mask, i, j)))
        found = L.tree->knn(q.data(), k_ann, static_cast<float>(opt.ann_eps), nn_idx.data(), nn_d2.data());
      // Candidates: ANN results, the current pixel, the coherent ones.
      std::uint32_t cand[32];
      int nc = 0;
      for (std::size_t a = 0; a < found && nc < 24; ++a) cand[nc++] = nn_idx[a];
      const std::size_t cur = ex_index(t);
      cand[nc++] = static_cast<std::uint32_t>(cur);
      static const int off[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
      for (const auto& o : off) {
        std::size_t tt = std::size_t(wrap(j + o[1], h)) * w + wrap(i + o[0], w);
        int cx = wrap(map.coords[2 * tt] - o[0], L.w), cy = wrap(map.coords[2 * tt + 1] - o[1], L.h);
        cand[nc++] = static_cast<std::uint32_t>(std::size_t(cy) * L.w + cx);
      }
      double best = std::numeric_limits<double>::infinity();
      std::size_t best_c = cur;
      for (int a = 0; a < nc; ++a) {
        const std::size_t c = cand[a];
        if (exclude > 0) {
          int dx = std::abs(int(c % L.w) - i), dy = std::abs(int(c / L.w) - j);
          dx = std::min(dx, L.w - dx);
          dy = std::min(dy, L.h - dy);
          if (double(dx) * dx + double(dy) * dy < exclude * exclude) continue;
        }
        const float* f = L.feature(c);
        double d2 = 0;
        for (int b = 0; b < L.D; ++b) {
          double e = double(q[b]) - f[b];
          d2 += e * e;
        }
        double cost = d2 + penalty * (usage[c] - (c == cur ? 1 : 0));
        if (cost < best || (cost == best && c < best_c)) {
          best = cost;
          best_c = c;
        }
      }
      if (best_c != cur) {
        --usage[cur];
        ++usage[best_c];
        map.coords[2 * t] = static_cast<std::int32_t>(best_c % L.w);
        map.coords[2 * t + 1] = static_cast<std::int32_t>(best_c / L.w);
      }
    }
  }
}

std::uint64_t mix_tile_seed(std::uint64_t seed, std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = seed ^ (a * 0x9E3779B97F4A7C15ull) ^ (b * 0xC2B2AE3D27D4EB4Full + 0x165667B19E3779F9ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

IndirectionMap identity_map(int w, int h) {
  IndirectionMap m{w, h, std::vector<std::int32_t>(std::size_t(w) * h * 2)};
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      m.coords[2 * (std::size_t(j) * w + i)] = i;
      m.coords[2 * (std::size_t(j) * w + i) + 1] = j;
    }
  return m;
}

// The coarse map upsampled to the fine level's ew x eh texels (ew is 2 c.width
// or 2 c.width - 1 for an odd side): I(2i+b) = 2 I(i) + b, wrapped.
IndirectionMap upsample_map(const IndirectionMap& c, int ew, int eh) {
  IndirectionMap m{ew, eh, std::vector<std::int32_t>(std::size_t(ew) * eh * 2)};
  for (int j = 0; j < m.height; ++j)
    for (int i = 0; i < m.width; ++i) {
      std::size_t t = std::size_t(j) * m.width + i;
      m.coords[2 * t] = wrap(2 * c.x(i / 2, j / 2) + (i & 1), ew);
      m.coords[2 * t + 1] = wrap(2 * c.y(i / 2, j / 2) + (j & 1), eh);
    }
  return m;
}

}  // namespace

ConstrainedSynthesisResult synthesize_constrained_tiles(const Image& exemplar, const Image& exemplar_mask,
                                                        const std::vector<Image>& target_masks,
                                                        const ConstrainedSynthesisOptions& opt) {
  const std::string fn = "synthesize_constrained_tiles: ";
  if (exemplar.empty()) throw InvalidInputError(fn + "empty exemplar");
  const int W = exemplar.width, H = exemplar.height;
  auto same = [&](const Image& m) { return m.width == W && m.height == H && m.channels >= 1; };
  if (!same(exemplar_mask))
    throw InvalidInputError(fn + "exemplar mask " + std::to_string(exemplar_mask.width) + "x" +
                            std::to_string(exemplar_mask.height) + " differs from exemplar " +
                            std::to_string(W) + "x" + std::to_string(H));
  if (target_masks.empty()) throw InvalidInputError(fn + "no target masks");
  for (std::size_t k = 0; k < target_masks.size(); ++k)
    if (!same(target_masks[k]))
      throw InvalidInputError(fn + "target mask " + std::to_string(k) + " is " +
                              std::to_string(target_masks[k].width) + "x" +
                              std::to_string(target_masks[k].height) + ", exemplar " + std::to_string(W) +
                              "x" + std::to_string(H));
  if (opt.levels < 0 || opt.coarse_passes < 0 || opt.fine_passes < 0 || opt.pca_dims < 1 ||
      !(opt.mask_weight >= 0) || !(opt.reuse_penalty >= 0) || opt.candidates < 1 || opt.candidates > 16 || opt.fine_ann_passes < 0 ||
      !(opt.ann_eps >= 0) || !(opt.exclude_radius >= 0))
    throw InvalidInputError(fn + "option out of range (levels " + std::to_string(opt.levels) +
                            ", passes " + std::to_string(opt.coarse_passes) + "/" +
                            std::to_string(opt.fine_passes) + ", pca_dims " + std::to_string(opt.pca_dims) +
                            ", candidates " + std::to_string(opt.candidates) + " (1..16))");
  // Level sizes halve rounding up (gaussian_pyramid): side >> r rounded up.
  auto side = [](int n, int r) { return (n + (1 << r) - 1) >> r; };
  int levels = opt.levels;
  if (levels == 0) {
    levels = 1;
    while (std::max(side(W, levels - 1), side(H, levels - 1)) > 32 && std::min(side(W, levels), side(H, levels)) >= 8)
      ++levels;
  }
  if (levels > 30 || std::min(side(W, levels - 1), side(H, levels - 1)) < 4)
    throw InvalidInputError(fn + "size " + std::to_string(W) + "x" + std::to_string(H) +
                            " does not allow " + std::to_string(levels) +
                            " levels (the coarsest side, ceil(side / 2^(levels-1)), must be >= 4)");
  const int K = static_cast<int>(target_masks.size());

  // Pyramids (section 1.2: input colour, input mask, interpolated masks).
  std::vector<Image> col_pyr = pyramid(exemplar, levels);
  std::vector<Image> emask_pyr = pyramid(first_channel(exemplar_mask), levels);
  std::vector<std::vector<Image>> tmask_pyr(K);
  tbb::parallel_for(0, K, [&](int k) { tmask_pyr[k] = pyramid(first_channel(target_masks[k]), levels); });
  std::vector<ExemplarLevel> ex(levels);
  tbb::parallel_for(0, levels, [&](int r) { build_exemplar_level(ex[r], col_pyr[r], emask_pyr[r], opt); });
  report_progress(opt.progress, "tile synthesis", 0.05);

  ConstrainedSynthesisResult res;
  res.levels = levels;
  res.maps.assign(K, std::vector<IndirectionMap>(levels));
  // Coarsest level, layer after layer.
  const int cw = ex[0].w, chh = ex[0].h;
  for (int k = 0; k < K; ++k) {
    IndirectionMap& m = res.maps[k][0];
    if (k == 0) {
      m = identity_map(cw, chh);
      if (opt.random_first_layer) {
        std::mt19937_64 rng(mix_tile_seed(opt.seed, 0xF1, 0));
        for (std::size_t t = 0; t < m.coords.size(); t += 2) {
          m.coords[t] = static_cast<std::int32_t>(rng() % std::uint64_t(cw));
          m.coords[t + 1] = static_cast<std::int32_t>(rng() % std::uint64_t(chh));
        }
      }
    } else {
      m = res.maps[k - 1][0];
    }
    if (k > 0 || opt.random_first_layer)
      optimise_map(m, ex[0], tmask_pyr[k][0], opt.coarse_passes, mix_tile_seed(opt.seed, k, 0), opt,
                   opt.exclude_radius * ex[0].w / W, opt.coarse_passes, false);
    report_progress(opt.progress, "tile synthesis", 0.05 + 0.25 * (k + 1) / K);
  }
  // Finer levels: layers are independent.
  std::atomic<int> done{0};
  tbb::parallel_for(0, K, [&](int k) {
    for (int r = 1; r < levels; ++r) {
      IndirectionMap& m = res.maps[k][r];
      if (k == 0 && !opt.random_first_layer) {
        m = identity_map(ex[r].w, ex[r].h);
        continue;
      }
      m = upsample_map(res.maps[k][r - 1], ex[r].w, ex[r].h);
      optimise_map(m, ex[r], tmask_pyr[k][r], opt.fine_passes, mix_tile_seed(opt.seed, k, r), opt,
                   opt.exclude_radius * ex[r].w / W, opt.fine_ann_passes, opt.fine_ann_only_mismatched);
    }
    int d = ++done;
    report_progress(opt.progress, "tile synthesis", 0.3 + 0.7 * d / K);
  });

  // Colours and quality figures at the finest level.
  const ExemplarLevel& F = ex[levels - 1];
  for (int k = 0; k < K; ++k) {
    const IndirectionMap& m = res.maps[k][levels - 1];
    Image out(W, H, exemplar.channels);
    long long agree = 0;
    std::vector<char> used(std::size_t(W) * H, 0);
    for (int j = 0; j < H; ++j)
      for (int i = 0; i < W; ++i) {
        int x = m.x(i, j), y = m.y(i, j);
        const float* p = exemplar.pixel(x, y);
        std::copy(p, p + exemplar.channels, out.pixel(i, j));
        agree += (F.mask.at(x, y) > 0.5f) == (target_masks[k].at(i, j, 0) > 0.5f);
        used[std::size_t(y) * W + x] = 1;
      }
    res.layers.push_back(std::move(out));
    res.mask_agreement.push_back(double(agree) / (double(W) * H));
    res.unused_fraction.push_back(1.0 - double(std::count(used.begin(), used.end(), 1)) / (double(W) * H));
  }
  report_progress(opt.progress, "tile synthesis", 1.0);
  return res;
}

}  // namespace surftex
