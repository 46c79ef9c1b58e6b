// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Points on a base mesh (element vertices' feet) bucketed in cells of the
// query radius, for "is any within radius" queries: the bare-area measure
// (issue 17 item 4) and the scatter fill.
#include <cmath>
#include <unordered_map>
#include <vector>

#include "geometry/vec3.h"
#include "shell/element_mesh.h"

namespace surftex {

class FootGrid {
 public:
  explicit FootGrid(double radius) : rad_(radius) {}
  void add(const P3& p) { grid_[key(p, 0, 0, 0)].push_back(p); }
  bool covered(const P3& x) const {
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          auto it = grid_.find(key(x, i, j, k));
          if (it == grid_.end()) continue;
          for (const P3& q : it->second)
            if (vec3::dot(vec3::sub(x, q), vec3::sub(x, q)) <= rad_ * rad_) return true;
        }
    return false;
  }

 private:
  long long key(const P3& p, int di, int dj, int dk) const {
    const long long i = static_cast<long long>(std::floor(p[0] / rad_)) + di, j = static_cast<long long>(std::floor(p[1] / rad_)) + dj,
                    k = static_cast<long long>(std::floor(p[2] / rad_)) + dk;
    return (i * 73856093LL) ^ (j * 19349663LL) ^ (k * 83492791LL);
  }
  double rad_;
  std::unordered_map<long long, std::vector<P3>> grid_;
};

}  // namespace surftex
