// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Points bucketed in cubic cells of a query radius, for "what lies within
// radius" queries: the bare-area measure (issue 17 item 4) and the scatter
// fill (FootGrid: element vertices' feet on a base mesh), the benchmark's
// nearest-gap measure (CellGrid of tagged points).
#include <cmath>
#include <unordered_map>
#include <utility>
#include <vector>

#include "geometry/vec3.h"
#include "shell/element_mesh.h"

namespace surftex {

/// Items with a position (`position(item)`) in cells of side `cell`; a query
/// visits the items of the 27 cells around a point, so every item within
/// `cell` of it (and some farther).
template <class Item>
class CellGrid {
 public:
  explicit CellGrid(double cell) : h_(cell) {}
  void add(const P3& p, Item item) { cells_[key(p, 0, 0, 0)].push_back({p, std::move(item)}); }
  /// Calls fn(position, item) for the items of the cells around `p` until it returns true; whether one did.
  template <class Fn>
  bool any_near(const P3& p, Fn&& fn) const {
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          auto it = cells_.find(key(p, i, j, k));
          if (it == cells_.end()) continue;
          for (const auto& [q, item] : it->second)
            if (fn(q, item)) return true;
        }
    return false;
  }

 private:
  long long key(const P3& p, int di, int dj, int dk) const {
    const long long i = static_cast<long long>(std::floor(p[0] / h_)) + di, j = static_cast<long long>(std::floor(p[1] / h_)) + dj,
                    k = static_cast<long long>(std::floor(p[2] / h_)) + dk;
    return (i * 73856093LL) ^ (j * 19349663LL) ^ (k * 83492791LL);
  }
  double h_;
  std::unordered_map<long long, std::vector<std::pair<P3, Item>>> cells_;
};

/// Feet of element vertices: is any within `radius` of a point?
class FootGrid {
 public:
  explicit FootGrid(double radius) : rad_(radius), grid_(radius) {}
  void add(const P3& p) { grid_.add(p, 0); }
  bool covered(const P3& x) const {
    return grid_.any_near(x, [&](const P3& q, char) { return vec3::dot(vec3::sub(x, q), vec3::sub(x, q)) <= rad_ * rad_; });
  }

 private:
  double rad_;
  CellGrid<char> grid_;
};

/// A triangle's four sample points (its centroid and its corner triangles'
/// centroids, (4 a + b + c) / 6), each standing for a quarter of its area:
/// how many have no foot within the grid's radius (0..4). The bare-area
/// measure and the scatter fills count bare area with it.
inline int bare_samples_of(const P3& a, const P3& b, const P3& c, const FootGrid& feet) {
  int n = feet.covered({(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3}) ? 0 : 1;
  const P3* v[3] = {&a, &b, &c};
  for (int k = 0; k < 3; ++k) {
    const P3 &p = *v[k], &q = *v[(k + 1) % 3], &r = *v[(k + 2) % 3];
    n += feet.covered({(4 * p[0] + q[0] + r[0]) / 6, (4 * p[1] + q[1] + r[1]) / 6, (4 * p[2] + q[2] + r[2]) / 6}) ? 0 : 1;
  }
  return n;
}

}  // namespace surftex
