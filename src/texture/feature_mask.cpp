// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/feature_mask.h"

#include "texture/image_ops.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"

namespace surftex {

namespace {

// Separable toroidal Gaussian blur of a 1-channel image (kernel radius 3 sigma).
Image blur_wrap(const Image& in, double sigma) {
  if (sigma <= 0) return in;
  int r = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<double> k(2 * r + 1);
  double sum = 0;
  for (int i = -r; i <= r; ++i) sum += k[i + r] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& v : k) v /= sum;
  Image tmp(in.width, in.height, 1), out(in.width, in.height, 1);
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      double s = 0;
      for (int i = -r; i <= r; ++i) s += k[i + r] * in.at_wrap(x + i, y);
      tmp.at(x, y) = static_cast<float>(s);
    }
  for (int y = 0; y < in.height; ++y)
    for (int x = 0; x < in.width; ++x) {
      double s = 0;
      for (int i = -r; i <= r; ++i) s += k[i + r] * tmp.at_wrap(x, y + i);
      out.at(x, y) = static_cast<float>(s);
    }
  return out;
}

// Otsu's threshold over a 256-bin histogram of `values` in [lo, hi]: the bin
// edge maximising the between-class variance. Returns lo if all values equal.
double otsu_threshold(const std::vector<float>& values, double lo, double hi) {
  if (!(hi > lo)) return lo;
  constexpr int kBins = 256;
  std::array<double, kBins> hist{};
  for (float v : values) {
    int b = static_cast<int>((v - lo) / (hi - lo) * kBins);
    hist[std::clamp(b, 0, kBins - 1)] += 1;
  }
  double total = static_cast<double>(values.size()), sum_all = 0;
  for (int i = 0; i < kBins; ++i) sum_all += i * hist[i];
  double w0 = 0, sum0 = 0, best = -1;
  int best_i = 0;
  for (int i = 0; i < kBins - 1; ++i) {
    w0 += hist[i];
    sum0 += i * hist[i];
    double w1 = total - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    double m0 = sum0 / w0, m1 = (sum_all - sum0) / w1;
    double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) {
      best = between;
      best_i = i;
    }
  }
  return lo + (best_i + 1) * (hi - lo) / kBins;  // upper edge of the last "low" bin
}

}  // namespace

Image mask_from_painted(const Image& painted, double threshold) {
  if (painted.empty()) throw InvalidInputError("mask_from_painted: empty mask image");
  if (!(threshold >= 0 && threshold <= 1))
    throw InvalidInputError("mask_from_painted: threshold " + std::to_string(threshold) +
                            " outside [0,1]");
  Image lum = luminance(painted);
  for (float& v : lum.data) v = v >= threshold ? 1.f : 0.f;
  return lum;
}

Image read_feature_mask(const std::string& path, double threshold) {
  Image img = read_image(path);
  try {
    return mask_from_painted(img, threshold);
  } catch (const InvalidInputError& e) {
    throw InvalidInputError("feature mask '" + path + "': " + e.what());
  }
}

FeatureMaskResult compute_feature_mask(const Image& texture, const FeatureMaskOptions& opt) {
  if (texture.empty()) throw InvalidInputError("compute_feature_mask: empty texture");
  if (!(opt.blur_sigma >= 0))
    throw InvalidInputError("compute_feature_mask: blur_sigma " + std::to_string(opt.blur_sigma) +
                            " must be >= 0");
  Image q = blur_wrap(luminance(texture), opt.blur_sigma);
  if (opt.rule == FeatureMaskOptions::Rule::Gradient) {
    Image g(q.width, q.height, 1);
    for (int y = 0; y < q.height; ++y)
      for (int x = 0; x < q.width; ++x) {
        double gx = 0.5 * (q.at_wrap(x + 1, y) - q.at_wrap(x - 1, y));
        double gy = 0.5 * (q.at_wrap(x, y + 1) - q.at_wrap(x, y - 1));
        g.at(x, y) = static_cast<float>(std::sqrt(gx * gx + gy * gy));
      }
    q = std::move(g);
  }
  auto [mn, mx] = std::minmax_element(q.data.begin(), q.data.end());
  FeatureMaskResult res;
  res.mask = Image(q.width, q.height, 1, 0.f);
  if (!(*mx > *mn)) return res;  // constant: no feature
  res.threshold = otsu_threshold(q.data, *mn, *mx);
  long long above = 0;
  for (float v : q.data) above += v >= res.threshold;
  long long n = static_cast<long long>(q.data.size());
  // Gradient rule: features are the high-gradient pixels. Luminance rule: the minority class.
  bool dark = opt.rule == FeatureMaskOptions::Rule::Luminance && above * 2 > n;
  res.feature_is_dark = dark;
  long long feat = 0;
  for (std::size_t i = 0; i < q.data.size(); ++i) {
    bool f = dark ? q.data[i] < res.threshold : q.data[i] >= res.threshold;
    res.mask.data[i] = f ? 1.f : 0.f;
    feat += f;
  }
  res.feature_fraction = static_cast<double>(feat) / n;
  return res;
}

long long count_feature_pixels(const Image& mask) {
  long long c = 0;
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x) c += mask.at(x, y, 0) > 0.5f;
  return c;
}

Image binarize_mask(const Image& mask) {
  Image out(mask.width, mask.height, 1);
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x) out.at(x, y) = mask.at(x, y, 0) > 0.5f ? 1.f : 0.f;
  return out;
}

}  // namespace surftex
