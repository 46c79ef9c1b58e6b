// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Constrained tile synthesis: Ray et al. 2009, section 1.2. Synthesises, for a
// sequence of target feature masks F_0 .. F_K (one per material layer), tiles
// made of the pixels of one exemplar tile whose feature mask follows F_k,
// keeping the exemplar's colour histogram.
//
// Each layer is an indirection map per resolution (exemplar pixel coordinates
// per output texel), optimised coarse to fine on a Gaussian pyramid (a 5-tap
// binomial, toroidal, factor 2 per level). Initialisation follows the paper:
//  - layer 0: the identity (the exemplar itself; F_0 must be its mask);
//  - layer k > 0, coarsest level: a copy of layer k-1's optimised coarsest map;
//  - finer levels: the coarser map upsampled, I(2i+b) = 2 I(i) + b.
// Optimisation: `coarse_passes` (20) passes at the coarsest level, `fine_passes`
// (3) above; each pass visits the texels in a seeded random order and replaces
// I(p) by the exemplar pixel whose neighbourhood vector is nearest, where the
// vector is the 5x5 colour neighbourhood reduced by PCA (Eigen) to `pca_dims`
// (5) coefficients, followed by the 3x3 feature mask scaled by `mask_weight` (2).
// Nearest neighbours: a kd-tree (nanoflann) approximate search for `candidates`
// neighbours, plus the current and the four coherent candidates (I(p+o) - o);
// each candidate is penalised by how many output texels already use it, which
// keeps the histogram. All neighbourhoods wrap (output and exemplar are tiles),
// so every layer tiles.

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
  /// Pyramid levels (>= 1). Each level halves the sides, rounding up
  /// (texture/gaussian_pyramid.h): 63x45 -> 32x23 -> 16x12. 0 (default) =
  /// halve while the longer side exceeds 32 texels and the next level's
  /// shorter side stays >= 8: 256 -> 4 levels (256, 128, 64, 32).
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
  /// PCA coefficients of the 5x5 colour neighbourhood (1..25*channels).
  /// Default 5, the paper's timing setting (section 4: "5x5 patch size for
  /// colors (reduced to a 5 dimensions vector)"; section 1.2 mentions 8).
  int pca_dims = 5;
  double mask_weight = 2;  ///< scale of the 3x3 mask entries in the vector (>= 0)
  /// PCA coefficients kept of the (weighted) 3x3 mask neighbourhood (0..9,
  /// 0 = all 9 raw entries). Default 3, the paper's figure (section 4,
  /// "3x3 patch size for feature (reduced to a 3 dimensions vector)"); it keeps
  /// the kd-tree low-dimensional (8 instead of 14), which is what makes it fast.
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
  /// Candidates whose exemplar position lies closer than this (finest-level
  /// texels, toroidal) to the output position are refused (>= 0, default 0 =
  /// none). Used with random_first_layer to force a tile that is a real
  /// rearrangement of the exemplar rather than the exemplar itself.
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
