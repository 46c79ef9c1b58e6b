// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Arithmetic on plain coordinates (std::array<double, 3>) for the code that
// works outside CGAL's vector types: the rasterizer, the bakes, the fidelity
// measure. Files bring in what they use with using-declarations.

#include <array>
#include <cmath>

namespace surftex::vec3 {

using V3 = std::array<double, 3>;

inline V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline V3 add(const V3& a, const V3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline V3 mul(const V3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const V3& a) { return std::sqrt(dot(a, a)); }

}  // namespace surftex::vec3
