// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Reading a material-space 3D tile back from the folder written by
// write_material_tile (material_tile.h), and the trilinear (s,t,m) lookup a
// renderer uses (Ray et al. 2009, section 3: "one 3D texture lookup").
//
// Folder format: tile.json ("format", "size", "channels", "layers",
// "layers_per_pair", "layer_list", optional "maps") and the layer PNGs it
// names (authoritative; layers.tif is not read). In full: docs/decisions/303.
//
// Lookup convention: layer texel (x, y) is centred at s = (x + 0.5) / size,
// t = (y + 0.5) / size (row y = 0 at the top of the image, t grows downwards
// in the image); s and t wrap with period 1. The material coordinate m in
// [0,1] (clamped) spans the whole stack: layer k sits at m = k / (L - 1)
// (L layers; with one layer m is ignored).

#include <string>
#include <vector>

#include "geometry/image.h"
#include "geometry/rasterizer.h"

namespace surftex {

/// A 3D tile in memory: L layers, each size x size, same channel count.
struct MaterialTile {
  std::vector<Image> layers;
  /// Optional maps, one per layer of the layers' size, or empty (none):
  /// normal 3 channels, height and roughness 1 channel.
  std::vector<Image> normal_layers, height_layers, roughness_layers;
  std::vector<double> material;  ///< m recorded per layer in tile.json (key index + fraction)
  int size = 0;
  int layers_per_pair = 0;  ///< M
};

/// Reads `dir`/tile.json and every layer file it lists; every field and file
/// header is checked against the image limits before decoding. Throws IOError
/// (missing, too large or unreadable files; names the file) and
/// InvalidInputError "tile.json: line L: field F: what" (malformed, missing or
/// out-of-range fields, maps or layers of the wrong size or channels).
MaterialTile read_material_tile(const std::string& dir);

/// Checks a tile made in memory the same way (non-empty, square, equal sizes
/// and channels >= 1; map stacks empty or one per layer of the layers' size,
/// normal >= 3 channels, height and roughness 1). Throws InvalidInputError.
void validate_material_tile(const MaterialTile& tile);

/// Trilinear lookup: bilinear in (s,t) with wrap-around (period 1) in each of
/// the two layers nearest to m (clamped to [0,1]), linear between them.
/// 1 channel = grey, >= 3 = the first three. Assumes a valid tile.
Vec3f sample_material_tile(const MaterialTile& tile, double s, double t, double m);

/// The same lookup in any stack of layers (the tile's or one of its map
/// stacks): 1 channel = grey in all three, >= 3 = the first three.
Vec3f sample_material_layers(const std::vector<Image>& layers, double s, double t, double m);

}  // namespace surftex
