// SPDX-License-Identifier: AGPL-3.0-or-later
// Per-vertex tangent frames (see vertex_tangents.h).
#include "geometry/vertex_tangents.h"
#include "geometry/vec3.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/errors.h"

namespace surftex {

namespace {

using D3 = std::array<double, 3>;
using vec3::cross;
using vec3::dot;
using vec3::sub;
D3 scale(const D3& a, double s) { return vec3::mul(a, s); }
D3 unit(const D3& a) {
  const double l = std::sqrt(dot(a, a));
  return l > 0 ? scale(a, 1 / l) : D3{0, 0, 0};
}
D3 d3(const std::array<float, 3>& a) { return {a[0], a[1], a[2]}; }
// a minus its component along the unit n.
D3 project(const D3& a, const D3& n) { return sub(a, scale(n, dot(a, n))); }

}  // namespace

std::vector<std::array<float, 4>> vertex_tangents(const std::vector<std::array<float, 3>>& P,
                                                  const std::vector<std::array<float, 3>>& N,
                                                  const std::vector<std::array<float, 2>>& uv,
                                                  const std::vector<std::uint32_t>& tri) {
  const std::size_t n = P.size();
  if (N.size() != n || uv.size() != n || tri.size() % 3 != 0)
    throw InvalidInputError("vertex_tangents: " + std::to_string(n) + " positions, " + std::to_string(N.size()) +
                            " normals, " + std::to_string(uv.size()) + " uv, " + std::to_string(tri.size()) +
                            " indices");
  for (std::uint32_t i : tri)
    if (i >= n) throw InvalidInputError("vertex_tangents: index " + std::to_string(i) + " out of range");
  std::vector<D3> ts(n, D3{0, 0, 0}), bs(n, D3{0, 0, 0}), nn(n);
  for (std::size_t v = 0; v < n; ++v) nn[v] = unit(d3(N[v]));
  for (std::size_t f = 0; f + 2 < tri.size(); f += 3) {
    const std::uint32_t c[3] = {tri[f], tri[f + 1], tri[f + 2]};
    const D3 e1 = sub(d3(P[c[1]]), d3(P[c[0]])), e2 = sub(d3(P[c[2]]), d3(P[c[0]]));
    const double du1 = uv[c[1]][0] - uv[c[0]][0], dv1 = uv[c[1]][1] - uv[c[0]][1];
    const double du2 = uv[c[2]][0] - uv[c[0]][0], dv2 = uv[c[2]][1] - uv[c[0]][1];
    const double r = du1 * dv2 - du2 * dv1;
    if (!(std::abs(r) > 0)) continue;
    const D3 t = scale(sub(scale(e1, dv2), scale(e2, dv1)), 1 / r);
    const D3 b = scale(sub(scale(e2, du1), scale(e1, du2)), 1 / r);
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = c[k];
      const D3 a = unit(project(sub(d3(P[c[(k + 1) % 3]]), d3(P[v])), nn[v]));
      const D3 o = unit(project(sub(d3(P[c[(k + 2) % 3]]), d3(P[v])), nn[v]));
      const double angle = std::acos(std::clamp(dot(a, o), -1.0, 1.0));
      const D3 tp = unit(project(t, nn[v])), bp = unit(project(b, nn[v]));
      for (int d = 0; d < 3; ++d) ts[v][d] += angle * tp[d], bs[v][d] += angle * bp[d];
    }
  }
  std::vector<std::array<float, 4>> out(n);
  for (std::size_t v = 0; v < n; ++v) {
    D3 t = unit(project(ts[v], nn[v]));
    if (dot(t, t) == 0) {  // any perpendicular of the normal
      const D3 ax = std::abs(nn[v][0]) < 0.9 ? D3{1, 0, 0} : D3{0, 1, 0};
      t = unit(project(ax, nn[v]));
      if (dot(t, t) == 0) t = {1, 0, 0};
    }
    const float w = dot(cross(nn[v], t), bs[v]) < 0 ? -1.f : 1.f;
    out[v] = {static_cast<float>(t[0]), static_cast<float>(t[1]), static_cast<float>(t[2]), w};
  }
  return out;
}

}  // namespace surftex
