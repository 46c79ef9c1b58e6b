// SPDX-License-Identifier: AGPL-3.0-or-later
// The process-wide image limits (geometry/image_io.h). They live in the
// executable, not in the image IO module (geometry/image_io_table.h): the
// module reads them through the executable's exported symbols, so the value
// the command line sets is the one the module checks.
#include <algorithm>
#include <cmath>

#include "geometry/image_io.h"

namespace surftex {
namespace {
ImageLimits g_limits;
}  // namespace

long long ImageLimits::max_side() const {
  const auto s = static_cast<long long>(std::ceil(std::sqrt(static_cast<double>(std::max(0LL, max_pixels)))));
  return std::max(16384LL, s);
}

void set_image_limits(const ImageLimits& limits) { g_limits = limits; }
const ImageLimits& image_limits() { return g_limits; }

}  // namespace surftex
