// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/signed_distance_field.h"

#include <cmath>
#include <limits>
#include <vector>

#include "geometry/errors.h"

namespace surftex {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// 1D squared distance transform on a cycle of length n (Felzenszwalb &
// Huttenlocher 2012, "Distance transforms of sampled functions", lower envelope
// of parabolas), run over 3 periods. f: n values (0 at sites, kInf elsewhere, or
// squared distances of a previous pass). d: n outputs. Scratch buffers reused.
struct Envelope1D {
  std::vector<double> ff, z;
  std::vector<int> v;
  void run(const double* f, int stride, int n, double* d, int dstride) {
    int m = 3 * n;
    ff.resize(m);
    v.resize(m);
    z.resize(m + 1);
    bool any = false;
    for (int i = 0; i < m; ++i) {
      ff[i] = f[(i % n) * stride];
      any |= ff[i] < kInf;
    }
    if (!any) {
      for (int i = 0; i < n; ++i) d[i * dstride] = kInf;
      return;
    }
    int k = -1;
    for (int q = 0; q < m; ++q) {
      if (ff[q] == kInf) continue;
      if (k < 0) {
        k = 0;
        v[0] = q;
        z[0] = -kInf;
        z[1] = kInf;
        continue;
      }
      double s;
      for (;;) {
        int p = v[k];
        s = ((ff[q] + double(q) * q) - (ff[p] + double(p) * p)) / (2.0 * (q - p));
        if (s <= z[k] && k > 0) {
          --k;
          continue;
        }
        break;
      }
      if (s <= z[k]) {  // k == 0 and the new parabola dominates everywhere
        v[0] = q;
        z[0] = -kInf;
        z[1] = kInf;
        continue;
      }
      ++k;
      v[k] = q;
      z[k] = s;
      z[k + 1] = kInf;
    }
    int j = 0;
    for (int q = n; q < 2 * n; ++q) {
      while (z[j + 1] < q) ++j;
      double dq = double(q - v[j]);
      d[(q - n) * dstride] = dq * dq + ff[v[j]];
    }
  }
};

}  // namespace

Image squared_distance_transform_torus(const Image& sites) {
  if (sites.empty()) throw InvalidInputError("squared_distance_transform_torus: empty image");
  const int w = sites.width, h = sites.height;
  std::vector<double> f(static_cast<std::size_t>(w) * h), g(f.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) f[std::size_t(y) * w + x] = sites.at(x, y, 0) > 0.5f ? 0.0 : kInf;
  Envelope1D env;
  for (int x = 0; x < w; ++x) env.run(f.data() + x, w, h, g.data() + x, w);  // columns
  for (int y = 0; y < h; ++y) env.run(g.data() + std::size_t(y) * w, 1, w, f.data() + std::size_t(y) * w, 1);
  Image out(w, h, 1);
  for (std::size_t i = 0; i < f.size(); ++i) out.data[i] = static_cast<float>(f[i]);
  return out;
}

Image signed_distance_field(const Image& mask) {
  if (mask.empty()) throw InvalidInputError("signed_distance_field: empty mask");
  const int w = mask.width, h = mask.height;
  Image inside(w, h, 1), outside(w, h, 1);
  long long nin = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool f = mask.at(x, y, 0) > 0.5f;
      inside.at(x, y) = f;
      outside.at(x, y) = !f;
      nin += f;
    }
  const float big = static_cast<float>(w + h);
  if (nin == 0) return Image(w, h, 1, -big);
  if (nin == static_cast<long long>(w) * h) return Image(w, h, 1, big);
  Image d_to_in = squared_distance_transform_torus(inside);
  Image d_to_out = squared_distance_transform_torus(outside);
  Image phi(w, h, 1);
  for (std::size_t i = 0; i < phi.data.size(); ++i)
    phi.data[i] = inside.data[i] > 0.5f ? std::sqrt(d_to_out.data[i]) : -std::sqrt(d_to_in.data[i]);
  return phi;
}

}  // namespace surftex
