// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Image IO through OpenImageIO: every format it reads (PNG, JPEG, TIFF, EXR,
// ...). Writing is atomic (temporary file, then rename).

#include <string>
#include <vector>

#include "geometry/image.h"

namespace surftex {

/// Reads the first subimage as floats. 8/16-bit integer formats map to [0,1].
/// Throws IOError naming the file if it cannot be opened or decoded, and
/// InvalidInputError if it is empty or holds a non-finite value.
Image read_image(const std::string& path);

struct WriteImageOptions {
  /// Store as 8-bit (PNG/JPEG default) when true, else as 32-bit float where
  /// the format supports it (EXR, TIFF). Values are clamped to [0,1] for 8-bit.
  bool eight_bit = true;
  /// Store as 16-bit integers (PNG, TIFF: height maps); overrides eight_bit.
  bool sixteen_bit = false;
  /// Allow replacing an existing file.
  bool overwrite = true;
};

/// Writes `img` to `path`; the format follows the extension. Throws IOError.
void write_image(const std::string& path, const Image& img, const WriteImageOptions& opt = {});

/// Writes several images as the subimages of one file (multi-page TIFF, multi-part
/// EXR). All must have the same channel count. Throws IOError if the format
/// cannot hold several subimages.
void write_image_layers(const std::string& path, const std::vector<Image>& layers,
                        const WriteImageOptions& opt = {});

/// Reads every subimage of a file (the inverse of write_image_layers).
std::vector<Image> read_image_layers(const std::string& path);

}  // namespace surftex
