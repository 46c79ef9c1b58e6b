// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Image IO through OpenImageIO: every format it reads (PNG, JPEG, TIFF, EXR,
// ...). Writing is atomic (temporary file, then rename).

#include <string>
#include <vector>

#include "geometry/image.h"

namespace surftex {

/// What an image file may hold before it is decoded (issue 21 item 4): its
/// header (width, height, channels) is checked first, no pixel is read for
/// a file over the limits. An Image holds 4-byte floats, so the decoded size
/// is width * height * channels * 4 bytes.
struct ImageLimits {
  /// Most pixels (width * height). Default 16777216 (4096 x 4096), i.e.
  /// 256 MiB decoded as 4-channel float; the CLI's --max-image-pixels.
  long long max_pixels = 1LL << 24;
  /// Longest side in pixels: 16384, or sqrt(max_pixels) when that is larger.
  long long max_side() const;
  /// Most decoded bytes: max_pixels * 16 (256 MiB by default).
  long long max_bytes() const { return max_pixels * 16; }
  /// Most channels.
  static constexpr int kMaxChannels = 16;
  /// Throws InvalidInputError naming these limits and --max-image-pixels when
  /// a w x h image of `path` is over them. `side`: the longest side allowed
  /// (max_side() or less); `what`: where the size comes from ("PNG header",
  /// "3 channels, 12 MiB decoded"), said beside it.
  void check(long long w, long long h, long long side, const std::string& path, const std::string& what) const;
};

/// The process-wide limits every read_image* call checks (the CLI sets them
/// once from --max-image-pixels; library callers may too).
void set_image_limits(const ImageLimits& limits);
const ImageLimits& image_limits();

struct ImageHeader {
  int width = 0, height = 0, channels = 0;
  int subimages = 1;
  std::string format;  ///< OpenImageIO's format name ("png", "tiff", ...)
};

/// Reads and checks only the header of the image at `path` (no pixel is
/// decoded): refuses, naming the file, the sizes and the limit, an empty
/// image, a volume or deep image, more than kMaxChannels channels, a side
/// longer than max_side() or more than max_pixels pixels. Throws IOError
/// (cannot open, not an image) or InvalidInputError (over a limit).
ImageHeader read_image_header(const std::string& path, const ImageLimits& limits = image_limits());

/// Reads the first subimage as floats. 8/16-bit integer formats map to [0,1].
/// The header is checked against image_limits() before any pixel is decoded.
/// Throws IOError naming the file if it cannot be opened or decoded, and
/// InvalidInputError if it is empty, over the limits or holds a non-finite value.
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
