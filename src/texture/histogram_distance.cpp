// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/histogram_distance.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"

namespace surftex {
namespace {
std::vector<double> histogram(const Image& img, int c, const HistogramOptions& opt) {
  std::vector<double> h(opt.bins, 0.0);
  const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
  const double scale = opt.bins / (opt.hi - opt.lo);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = img.data[i * img.channels + c];
    const int b = std::isfinite(v) ? static_cast<int>(std::floor((v - opt.lo) * scale)) : 0;
    h[std::clamp(b, 0, opt.bins - 1)] += 1.0;
  }
  for (double& v : h) v /= static_cast<double>(n);
  return h;
}
}  // namespace

double histogram_chi_square(const Image& a, const Image& b, const HistogramOptions& opt) {
  auto bad = [](const std::string& m) { throw InvalidInputError("histogram_chi_square: " + m); };
  if (a.empty()) bad("first image is empty");
  if (b.empty()) bad("second image is empty");
  if (a.channels != b.channels)
    bad("channel counts differ (" + std::to_string(a.channels) + " vs " + std::to_string(b.channels) + ")");
  if (opt.bins < 1) bad("bins " + std::to_string(opt.bins) + " < 1");
  if (!(opt.hi > opt.lo)) bad("range [" + std::to_string(opt.lo) + ", " + std::to_string(opt.hi) + "] is empty");
  double total = 0;
  for (int c = 0; c < a.channels; ++c) {
    const auto p = histogram(a, c, opt), q = histogram(b, c, opt);
    double d = 0;
    for (int i = 0; i < opt.bins; ++i)
      if (p[i] + q[i] > 0) d += (p[i] - q[i]) * (p[i] - q[i]) / (p[i] + q[i]);
    total += 0.5 * d;
  }
  return total / a.channels;
}

}  // namespace surftex
