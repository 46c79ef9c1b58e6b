// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Constrained tile synthesis: Ray et al. 2009, section 1.2. Synthesises, for a
// sequence of target feature masks F_0 .. F_K (one per material layer), tiles
// made of the pixels of one exemplar tile whose feature mask follows F_k,
// keeping the exemplar's colour histogram.
//
// Each layer is an indirection map per pyramid level, optimised coarse to fine:
// layer 0 the identity, layer k starting from layer k-1's coarsest map, finer
// levels upsampled; each pass replaces I(p) by the exemplar pixel of nearest
// neighbourhood (5x5 colour PCA + 3x3 mask x mask_weight; kd-tree plus
// coherent candidates, a reuse penalty keeping the histogram). Everything
// wraps, so every layer tiles. In full: docs/decisions/303-pbr-maps.md.

#include <cstdint>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"

namespace surftex {

/// Exemplar coordinates (pixels at the map's resolution) of every output texel.
struct IndirectionMap {
  int width = 0, height = 0;
  std::vector<std::int32_t> coords;  ///< 2 per texel (x, y), row-major
  std::int32_t x(int i, int j) const { return coords[2 * (std::size_t(j) * width + i)]; }
  std::int32_t y(int i, int j) const { return coords[2 * (std::size_t(j) * width + i) + 1]; }
};

struct ConstrainedSynthesisOptions {
  /// Pyramid levels (>= 1), each halving the sides (rounding up); 0 (default) =
  /// halve while the longer side exceeds 32 and the shorter stays >= 8.
  int levels = 0;
  int coarse_passes = 20;  ///< passes at the coarsest level (>= 0)
  int fine_passes = 3;     ///< passes at every finer level (>= 0)
  /// Of the fine passes, how many query the kd-tree (>= 0, default 1); the
  /// others only compare the current and coherent candidates. The coarsest
  /// level always queries it in every pass.
  int fine_ann_passes = 1;
  /// At the finer levels, query the kd-tree only for texels whose current
  /// exemplar pixel's 3x3 feature mask differs from the target's (the others
  /// compare the current and coherent candidates only). Default on.
  bool fine_ann_only_mismatched = true;
  /// PCA coefficients of the 5x5 colour neighbourhood (1..25*channels). Default 5 (paper, section 4).
  int pca_dims = 5;
  double mask_weight = 2;  ///< scale of the 3x3 mask entries in the vector (>= 0)
  /// PCA coefficients of the 3x3 mask neighbourhood (0..9, 0 = raw). Default 3 (paper, section 4).
  int mask_pca_dims = 3;
  /// Reuse penalty: a candidate used u times (by other texels) costs
  /// reuse_penalty * u * V more, V the mean squared norm of the centred
  /// exemplar vectors (>= 0; 0 = no histogram preservation).
  double reuse_penalty = 0.05;
  int candidates = 2;      ///< kd-tree neighbours per query (1..16)
  double ann_eps = 4.0;    ///< nanoflann approximation: (1+eps)-approximate distances (>= 0)
  /// Layer 0 starts from the identity (paper). RandomFirst starts it from
  /// seeded random coordinates and optimises it too (used to make several
  /// different tiles with the same mask).
  bool random_first_layer = false;
  /// Candidates closer than this (finest texels, toroidal) to the output position
  /// are refused (>= 0, default 0); with random_first_layer forces a rearrangement.
  double exclude_radius = 0;
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

struct ConstrainedSynthesisResult {
  /// maps[k][r]: layer k at level r, r = 0 the coarsest, levels-1 the finest.
  std::vector<std::vector<IndirectionMap>> maps;
  std::vector<Image> layers;             ///< exemplar colours at the finest maps
  std::vector<double> mask_agreement;    ///< per layer: fraction of texels whose exemplar mask equals F_k
  std::vector<double> unused_fraction;   ///< per layer: fraction of exemplar pixels not used
  int levels = 0;
};

/// `exemplar`: the key tile (any channel count, tileable, W x H); `exemplar_mask`:
/// its feature mask (W x H, channel 0 > 0.5 = feature); `target_masks`: F_0 ..
/// F_K (each W x H). Returns K+1 layers of W x H. Deterministic for a seed,
/// whatever the thread count. Throws InvalidInputError for empty or mismatched
/// sizes, a coarsest level side (ceil(side / 2^(levels-1))) below 4, or options out of range;
/// SolverError if the PCA eigen-decomposition fails.
ConstrainedSynthesisResult synthesize_constrained_tiles(const Image& exemplar,
                                                        const Image& exemplar_mask,
                                                        const std::vector<Image>& target_masks,
                                                        const ConstrainedSynthesisOptions& opt = {});

}  // namespace surftex
