// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Binary feature masks ("texton masks") of textures: Ray et al. 2009, section 1
// ("Texture features, stored as binary masks F_m, can either be painted by the
// user or constructed automatically using image gradients").
//
// A mask is a surftex::Image with one channel holding exactly 0 (background) or
// 1 (feature), the same size as its texture. Everything here treats images as
// tiles (toroidal neighbourhoods), because the masks describe periodic tiles.

#include <string>

#include "geometry/image.h"
#include "texture/image_ops.h"

namespace surftex {

// luminance() lives in texture/image_ops.h.

/// A user-painted mask from any image: feature where luminance >= `threshold`
/// (default 0.5, luminance in [0,1] for 8-bit files). Throws InvalidInputError
/// on an empty image or a threshold outside [0,1].
Image mask_from_painted(const Image& painted, double threshold = 0.5);

/// Reads a painted mask file (any format OpenImageIO reads) and thresholds it
/// as mask_from_painted. Throws IOError / InvalidInputError naming the file.
Image read_feature_mask(const std::string& path, double threshold = 0.5);

struct FeatureMaskOptions {
  enum class Rule {
    /// Luminance after a toroidal Gaussian blur, thresholded at Otsu's
    /// threshold; the class with fewer pixels (the minority) is the feature
    /// (dots on a background, mortar lines between bricks, dark stripes ...).
    Luminance,
    /// Gradient magnitude (central differences) of the blurred luminance,
    /// thresholded at Otsu's threshold: features are the edges. This is the
    /// paper's "constructed automatically using image gradients".
    Gradient,
  };
  Rule rule = Rule::Luminance;
  /// Standard deviation of the blur before thresholding, in pixels (>= 0;
  /// default 1; 0 = no blur). Removes single-pixel noise from the mask.
  double blur_sigma = 1.0;
};

struct FeatureMaskResult {
  Image mask;                   ///< 1 channel, 0/1
  double threshold = 0;         ///< Otsu threshold on the thresholded quantity
  bool feature_is_dark = false; ///< Luminance rule: the feature class is below the threshold
  double feature_fraction = 0;  ///< fraction of pixels in the feature class
};

/// Computes a feature mask automatically from the texture. Deterministic.
/// A constant image gives an all-background mask (feature_fraction 0).
/// Throws InvalidInputError on an empty image or blur_sigma < 0.
FeatureMaskResult compute_feature_mask(const Image& texture, const FeatureMaskOptions& opt = {});

/// Number of feature pixels of a mask (values > 0.5).
long long count_feature_pixels(const Image& mask);

/// Converts a mask to a 1-channel 0/1 image for writing (identity for masks
/// already in that form; values > 0.5 become 1).
Image binarize_mask(const Image& mask);

}  // namespace surftex
