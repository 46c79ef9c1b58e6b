// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// What an image file is, told by its first bytes, and whether its container
// holds together, checked before a decoder sees it: third-party decoders
// allocate what a header claims (an OpenEXR attribute of 342 MB in a 2 KB
// file, found by fuzz_image_header), and some print to stderr or abort.

#include <string>

#include "geometry/image_io.h"

namespace surftex {

/// The formats surftex reads, by OpenImageIO's name: png, jpeg, tiff,
/// openexr, bmp, hdr, pnm (with PFM), webp, gif by their signature, targa
/// by a .tga/.tpic name (TGA has no signature). Anything else (DICOM, RAW,
/// video, ... which OpenImageIO would also try) is refused with IOError.
std::string sniff_image_format(const std::string& path);

/// Checks the container of `path` of format `format` (sniff_image_format's
/// answer) against its size and `limits`, throwing IOError or
/// InvalidInputError with the part and byte offset:
/// - PNG: every chunk inside the file with a matching CRC, IHDR first with
///   valid fields within the limits, IEND last (PNG specification 5.3-5.6, 11.2.2);
/// - OpenEXR: every attribute inside the file, the data window within the
///   limits, the offset table inside the file (OpenEXR file layout).
/// Other formats are left to their decoder.
void check_image_container(const std::string& path, const std::string& format, const ImageLimits& limits);

}  // namespace surftex
