// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/quilt_coverage.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/vec3.h"
#include "shell/quilting/foot_grid.h"
#include "shell/triangle_distance.h"

namespace surftex {

FootGrid feet_on_base(const TriangleDistance& base, const std::vector<P3>& points, double radius) {
  std::vector<P3> feet(points.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    int hint = -1;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const TriangleDistance::Hit h = base.closest(points[i], hint);
      feet[i] = h.point;
      hint = h.tri;
    }
  });
  FootGrid grid(radius);
  for (const P3& p : feet) grid.add(p);
  return grid;
}

BareArea output_bare_area(const Mesh& base, const Mesh& quilt, double radius, const std::array<double, 3>& up) {
  if (!(radius > 0) || !std::isfinite(radius)) throw InvalidInputError("output_bare_area: radius must be > 0");
  const ElementMesh b = element_mesh_from(base);  // throws for a face that is not a triangle
  std::vector<P3> pts;
  for (VertexIndex v : quilt.vertices()) {
    const Point3& p = quilt.point(v);
    pts.push_back({p.x(), p.y(), p.z()});
  }
  const FootGrid feet = feet_on_base(TriangleDistance(b), pts, radius);
  auto height = [&](const P3& p) { return vec3::dot(p, up); };
  double hmin = 1e300, hmax = -1e300;
  for (const P3& p : b.points) hmin = std::min(hmin, height(p)), hmax = std::max(hmax, height(p));
  double area[5] = {0, 0, 0, 0, 0}, bare[5] = {0, 0, 0, 0, 0};
  for (const Tri& t : b.tris) {
    const P3 v[3] = {b.points[static_cast<std::size_t>(t[0])], b.points[static_cast<std::size_t>(t[1])],
                     b.points[static_cast<std::size_t>(t[2])]};
    const P3 c{(v[0][0] + v[1][0] + v[2][0]) / 3, (v[0][1] + v[1][1] + v[2][1]) / 3, (v[0][2] + v[1][2] + v[2][2]) / 3};
    const int nbare = bare_samples_of(v[0], v[1], v[2], feet);
    const double a = 0.5 * vec3::norm(vec3::cross(vec3::sub(v[1], v[0]), vec3::sub(v[2], v[0])));
    const int band = hmax > hmin ? std::clamp(static_cast<int>(4 * (height(c) - hmin) / (hmax - hmin)), 0, 3) : 0;
    area[4] += a, area[band] += a;
    bare[4] += a * nbare / 4, bare[band] += a * nbare / 4;
  }
  BareArea r;
  r.overall = area[4] > 0 ? bare[4] / area[4] : 0;
  for (int k = 0; k < 4; ++k) r.by_height[static_cast<std::size_t>(k)] = area[k] > 0 ? bare[k] / area[k] : 0;
  return r;
}

}  // namespace surftex
