// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Feature-mask morphing by level-set advection: Ray et al. 2009, section 1.1
// "Texture Feature Morphing". Given the feature masks F_0 of the first tile and
// F_M of the last, produces M+1 masks F_0 .. F_M in which the source features
// are pushed into the target features (they may split and merge), with the
// paper's four ingredients:
// The paper's ingredients: material-space oversampling (N >> M steps),
// advection of phi outside F_M along grad phi_N (conservative bilinear
// splats), interior dilation, sweeping towards phi_N (the last field is the
// target), and speed-adaptive subsampling H(m) (even sign changes per layer).
// On the torus. The choices where the paper is vague: mask_morph.cpp and
// docs/decisions/303.

#include <cstdint>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"

namespace surftex {

struct MaskMorphOptions {
  /// N, the advection steps; 0 (default) = max(16 M, ceil(2 D)), D the largest
  /// distance to the target features (at most half a texel per step); else >= M.
  int steps = 0;
  /// Field whose magnitude drives the sweep: Target (default, |phi_N|, the
  /// paper's stated purpose) or Source (|phi_0|, as printed).
  enum class SweepReference { Target, Source };
  SweepReference sweep_reference = SweepReference::Target;
  /// Rounds of coordinate descent refining H(m) after the arc-length start.
  int subsampling_rounds = 20;
  ProgressCallback progress;
};

struct MaskMorphResult {
  std::vector<Image> masks;               ///< M+1 masks (1 channel, 0/1); masks[0] == F_0, masks[M] == F_M
  std::vector<int> step_of_layer;         ///< H(m), m = 0..M, strictly increasing, H(0)=0, H(M)=N
  std::vector<long long> sign_changes;    ///< M counts: texels whose sign differs between F_m and F_m+1
  std::vector<long long> step_sign_changes;  ///< N counts between consecutive advection steps
  int steps = 0;                          ///< N used
  double step_length = 0;                 ///< dt in pixels
  double sweep_scale = 0;                 ///< sup |reference field| used by the sweep
};

/// Morphs `source_mask` (F_0) into `target_mask` (F_M) in `layers` = M >= 1
/// intervals (M+1 masks). Masks: images of the same size, channel 0 > 0.5 is
/// feature. Deterministic (no randomness). Throws InvalidInputError for empty
/// or differently sized masks, M < 1, or steps in [1, M).
MaskMorphResult morph_feature_masks(const Image& source_mask, const Image& target_mask, int layers,
                                    const MaskMorphOptions& opt = {});

/// Number of texels whose feature/background state differs between two masks
/// of the same size (InvalidInputError otherwise).
long long count_sign_changes(const Image& a, const Image& b);

}  // namespace surftex
