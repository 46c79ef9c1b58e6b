// SPDX-License-Identifier: AGPL-3.0-or-later
// The process-wide image limits (geometry/image_io.h). They live in the
// executable, not in the image IO module (geometry/image_io_table.h): the
// module reads them through the executable's exported symbols, so the value
// the command line sets is the one the module checks.
#include <algorithm>
#include <cmath>

#include "geometry/image_io.h"

#include <string>

#include "geometry/errors.h"

namespace surftex {
namespace {
ImageLimits g_limits;
}  // namespace

long long ImageLimits::max_side() const {
  const auto s = static_cast<long long>(std::ceil(std::sqrt(static_cast<double>(std::max(0LL, max_pixels)))));
  return std::max(16384LL, s);
}

void ImageLimits::check(long long w, long long h, long long side, const std::string& path,
                        const std::string& what) const {
  if (w > side || h > side || w * h > max_pixels)
    throw InvalidInputError("image '" + path + "' is " + std::to_string(w) + "x" + std::to_string(h) + " (" + what +
                            "); the limit is " + std::to_string(side) + " px a side and " + std::to_string(max_pixels) +
                            " pixels (" + std::to_string(max_bytes() >> 20) +
                            " MiB decoded): pass --max-image-pixels to raise it");
}

void set_image_limits(const ImageLimits& limits) { g_limits = limits; }
const ImageLimits& image_limits() { return g_limits; }

}  // namespace surftex
