// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Newell's method for the normal of a polygon: for corners p_0 .. p_{n-1}
// in order (indices mod n),
//   N_x = sum_k (y_k - y_{k+1}) (z_k + z_{k+1}), and cyclically for N_y, N_z,
// which equals sum_k p_k x p_{k+1}: twice the polygon's vector area. Its
// direction follows the right-hand rule along the corner order; its length
// is twice the area of a planar polygon, and it stays a sensible normal for
// non-planar and non-convex polygons. No CGAL: any point type, through an
// accessor.

#include <array>
#include <cstddef>

namespace surftex {

/// Twice the vector area of the closed polygon with `n` corners, corner k
/// given by `corner(k)` as anything indexable by [0], [1], [2] (halve it for
/// the vector area).
template <class CornerAt>
std::array<double, 3> newell_normal(std::size_t n, CornerAt&& corner) {
  std::array<double, 3> s{0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < n; ++k) {
    const auto& a = corner(k);
    const auto& b = corner(k + 1 == n ? 0 : k + 1);
    const double ax = a[0], ay = a[1], az = a[2], bx = b[0], by = b[1], bz = b[2];
    s[0] += (ay - by) * (az + bz);
    s[1] += (az - bz) * (ax + bx);
    s[2] += (ax - bx) * (ay + by);
  }
  return s;
}

}  // namespace surftex
