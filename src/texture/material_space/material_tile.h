// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Material-space 3D tiles: Ray et al. 2009, section 1 (pipeline steps 1-3,
// Figures 2 and 5) and section 4 (several key tiles, hiding the periodicity of
// one tile, Figure 14). A 3D tile is a stack of layers T_m, each a periodic
// (tileable) image; the material coordinate m runs along the stack.
//
// For each pair of consecutive key textures (I_a, I_b):
//  1. make tileable key tiles T_a, T_b of size x size (see MaterialTileOptions::
//     key_tiles) and their feature masks F_a, F_b (painted, or automatic);
//  2. morph F_a into F_b (mask_morph.h, section 1.1) giving F_0 .. F_M;
//  3. synthesise layers from T_a constrained by F_0..F_M and from T_b by
//     F_M..F_0 (constrained_tile_synthesis.h, section 1.2) and blend them:
//     T_m = (1 - m/M) A_m + (m/M) B_m.
// Pairs are chained (A to B to C): the last layer of a pair is the first of the
// next. Same-mask mode (one key): M+1 different tiles of the one texture that
// share its mask, to hide periodicity (Figure 14).
//
// Maps of the keys (normal, height, roughness; "additional attributes, such
// as normal maps") follow the colour's coordinates and blend; normals are
// tangent-space, RGB = (n + 1) / 2, +x right, +y up, renormalised.

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"
#include "texture/material_space/constrained_tile_synthesis.h"
#include "texture/feature_mask.h"
#include "texture/mask_morph.h"

namespace surftex {

/// One key texture: the image and, optionally, a painted feature mask of the
/// same size (empty = computed with MaterialTileOptions::auto_mask).
struct MaterialKey {
  Image texture;
  Image mask;
  std::string name;  ///< for reports (file name)
  /// Optional maps of the texture's size (empty = none); a kind given for one
  /// key must be given for every key. normal: >= 3 channels, (n + 1) / 2, +y
  /// up; height, roughness: grey (or the luminance of RGB), [0, 1].
  Image normal{}, height{}, roughness{};
};

struct MaterialTileOptions {
  int size = 256;    ///< layer side in texels (>= 16; levels halve it rounding up)
  int layers = 8;    ///< M: intervals per key pair (>= 1); a pair gives M+1 layers
  /// Key tiles: the input's largest centred square resampled to size x size,
  /// then made tileable (graph-cut on the torus, tileable_tile.h, or with a
  /// painted mask toroidal synthesis from itself); true = used as is (it must
  /// already tile). Default false.
  bool keys_are_tileable = false;
  /// One key: same-mask mode (M+1 tiles sharing the key's mask). Ignored for
  /// two or more keys.
  FeatureMaskOptions auto_mask;
  MaskMorphOptions morph;
  ConstrainedSynthesisOptions synthesis;  ///< its seed is replaced by `seed`
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

struct MaterialTileResult {
  std::vector<Image> layers;            ///< (K-1) M + 1 layers (M+1 in same-mask mode), size x size
  std::vector<Image> masks;             ///< the constraint mask F of every layer
  std::vector<double> material;         ///< m of every layer in [0, K-1] (key index + fraction)
  std::vector<long long> sign_changes;  ///< per layer: texels changing sign since the previous layer (0 for the first)
  std::vector<double> mask_agreement;   ///< per layer: min over the two syntheses of the mask agreement
  std::vector<Image> key_tiles, key_masks;  ///< T and F of every key
  /// The keys' maps through the same coordinates, one per layer (empty when
  /// the keys have none): normal 3 channels (n + 1) / 2 unit, height and
  /// roughness 1 channel.
  std::vector<Image> normal_layers, height_layers, roughness_layers;
  /// Wall seconds per stage; morph and synthesis are summed over the key
  /// pairs, which run in parallel (so their sum may exceed seconds_total).
  double seconds_keys = 0, seconds_morph = 0, seconds_synthesis = 0, seconds_total = 0;
};

/// Builds the 3D tile. `keys`: 1 (same-mask mode) or more key textures.
/// Deterministic for a seed, whatever the thread count; the colour layers do
/// not depend on the maps. Throws InvalidInputError for no keys, an empty
/// texture, a mask or map whose size differs from its texture, a map kind
/// given for some keys only, a normal map of fewer than 3 channels, or options
/// out of range; errors of the stages propagate.
MaterialTileResult make_material_tile(const std::vector<MaterialKey>& keys,
                                      const MaterialTileOptions& opt = {});

/// The largest centred square of `img`, resampled bilinearly to size x size.
Image square_resample(const Image& img, int size);

}  // namespace surftex

namespace surftex {

/// What the tile description records besides the result.
struct MaterialTileInfo {
  std::vector<std::string> sources;  ///< key texture names (files)
  std::vector<std::string> masks;    ///< mask file per key ("" = automatic)
  std::uint64_t seed = 1;
  int layers_per_pair = 0;           ///< M
  /// Map files per key (empty = none), recorded as "source_maps".
  std::vector<std::string> normal_sources{}, height_sources{}, roughness_sources{};
};

/// Writes the tile into folder `dir`: layer_NNN.png, mask_NNN.png, layers.tif,
/// map layers when present, and tile.json (global fields and per-layer m,
/// files, sign changes, mask agreement); staged and renamed, so a failure
/// leaves nothing. Throws IOError if `dir` exists and !overwrite, or on any
/// write failure.
void write_material_tile(const std::string& dir, const MaterialTileResult& tile, const MaterialTileInfo& info,
                         bool overwrite = false);

}  // namespace surftex
