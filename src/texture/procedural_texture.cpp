// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/procedural_texture.h"
#include "geometry/constants.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "geometry/errors.h"

namespace surftex {

namespace {

void check_size(int size) {
  if (size < 4 || size > 8192)
    throw InvalidInputError("texture size must be in 4..8192, got " + std::to_string(size));
}

double smooth(double t) { return t * t * (3 - 2 * t); }

// Periodic value noise on an n x n lattice, sampled at (x,y) in [0,1)^2.
double value_noise(const std::vector<double>& lattice, int n, double x, double y) {
  double fx = x * n, fy = y * n;
  int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  double tx = smooth(fx - x0), ty = smooth(fy - y0);
  auto L = [&](int i, int j) { return lattice[((j % n + n) % n) * n + ((i % n + n) % n)]; };
  double a = L(x0, y0) * (1 - tx) + L(x0 + 1, y0) * tx;
  double b = L(x0, y0 + 1) * (1 - tx) + L(x0 + 1, y0 + 1) * tx;
  return a * (1 - ty) + b * ty;
}
}  // namespace

Image make_stripes(int size, double period, double angle_deg) {
  check_size(size);
  if (!(period >= 2.0) || !std::isfinite(period))
    throw InvalidInputError("stripe period must be at least 2 pixels, got " + std::to_string(period));
  if (!std::isfinite(angle_deg)) throw InvalidInputError("stripe angle must be finite");
  // The stripe normal n = (-sin a, cos a) (y up); waves per image along x / y are rounded to integers.
  double a = angle_deg * kPi / 180.0;
  double waves = size / period;
  double kx = std::round(-std::sin(a) * waves), ky = std::round(std::cos(a) * waves);
  if (kx == 0 && ky == 0) ky = 1;
  Image img(size, size, 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double yu = size - y;  // y up, periodic: row 0 and row size-1 are neighbours
      double v = 0.5 + 0.5 * std::cos(2 * kPi * (kx * x + ky * yu) / size);
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = static_cast<float>(0.1 + 0.8 * v);
    }
  return img;
}

Image make_checker(int size, int cells) {
  check_size(size);
  if (cells < 1 || cells > size) throw InvalidInputError("checker cells must be in 1..size");
  Image img(size, size, 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      bool on = ((x * cells / size) + (y * cells / size)) % 2 == 0;
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = on ? 0.9f : 0.1f;
    }
  return img;
}

Image make_noise(int size, int base_cells, std::uint64_t seed) {
  check_size(size);
  if (base_cells < 1 || base_cells > size)
    throw InvalidInputError("noise base cells must be in 1..size, got " + std::to_string(base_cells));
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<std::vector<double>> octaves;
  std::vector<int> ns;
  for (int n = base_cells; n <= size / 2 && octaves.size() < 5; n *= 2) {
    std::vector<double> lat(static_cast<std::size_t>(n) * n);
    for (double& v : lat) v = U(rng);
    octaves.push_back(std::move(lat));
    ns.push_back(n);
  }
  if (octaves.empty()) {
    octaves.push_back(std::vector<double>(static_cast<std::size_t>(base_cells) * base_cells, 0.5));
    ns.push_back(base_cells);
  }
  const double c0[3] = {0.35, 0.22, 0.12}, c1[3] = {0.85, 0.72, 0.52};
  Image img(size, size, 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double v = 0, amp = 1, norm = 0;
      for (std::size_t o = 0; o < octaves.size(); ++o) {
        v += amp * value_noise(octaves[o], ns[o], (x + 0.5) / size, (y + 0.5) / size);
        norm += amp;
        amp *= 0.55;
      }
      v = std::clamp(v / norm, 0.0, 1.0);
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = static_cast<float>(c0[c] + (c1[c] - c0[c]) * v);
    }
  return img;
}

Image make_cells(int size, int cells, std::uint64_t seed) {
  check_size(size);
  if (cells < 1 || cells > size / 2) throw InvalidInputError("cells must be in 1..size/2");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  struct Site { double x, y; float shade[3]; };
  std::vector<Site> sites;
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      Site s{(i + 0.15 + 0.7 * U(rng)) / cells, (j + 0.15 + 0.7 * U(rng)) / cells, {}};
      double g = 0.45 + 0.45 * U(rng);
      s.shade[0] = static_cast<float>(g);
      s.shade[1] = static_cast<float>(g * (0.8 + 0.2 * U(rng)));
      s.shade[2] = static_cast<float>(g * (0.6 + 0.2 * U(rng)));
      sites.push_back(s);
    }
  Image img(size, size, 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double px = (x + 0.5) / size, py = (y + 0.5) / size;
      double d1 = 1e9, d2 = 1e9;
      const Site* best = nullptr;
      for (const Site& s : sites) {
        double dx = std::abs(px - s.x), dy = std::abs(py - s.y);
        dx = std::min(dx, 1 - dx);  // torus
        dy = std::min(dy, 1 - dy);
        double d = std::sqrt(dx * dx + dy * dy);
        if (d < d1) { d2 = d1; d1 = d; best = &s; }
        else if (d < d2) d2 = d;
      }
      double edge = (d2 - d1) * cells;  // ~0 on the mortar line
      double m = std::clamp(edge / 0.12, 0.0, 1.0);
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = static_cast<float>(0.08 + (best->shade[c] - 0.08) * m);
    }
  return img;
}

}  // namespace surftex
