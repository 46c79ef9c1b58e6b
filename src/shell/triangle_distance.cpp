// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/triangle_distance.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "geometry/mesh.h"

namespace surftex {
namespace {
using Triangle3 = Kernel::Triangle_3;
using Iterator = std::vector<Triangle3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

P3 barycentric(const Triangle3& t, const Point3& p) {
  const Vector3 v0 = t[1] - t[0], v1 = t[2] - t[0], v2 = p - t[0];
  const double d00 = v0 * v0, d01 = v0 * v1, d11 = v1 * v1, d20 = v2 * v0, d21 = v2 * v1;
  const double den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0)) return {1, 0, 0};
  double b = (d11 * d20 - d01 * d21) / den, c = (d00 * d21 - d01 * d20) / den;
  b = std::clamp(b, 0.0, 1.0);
  c = std::clamp(c, 0.0, 1.0 - b);
  return {1 - b - c, b, c};
}
}  // namespace

struct TriangleDistance::Impl {
  std::vector<Triangle3> tris;
  Tree tree;
};

TriangleDistance::TriangleDistance(const ElementMesh& m) : impl_(std::make_unique<Impl>()) {
  impl_->tris.reserve(m.tris.size());
  for (const Tri& t : m.tris) {
    auto P = [&](int i) { return Point3(m.points[i][0], m.points[i][1], m.points[i][2]); };
    impl_->tris.emplace_back(P(t[0]), P(t[1]), P(t[2]));
  }
  if (!impl_->tris.empty()) {
    impl_->tree.insert(impl_->tris.cbegin(), impl_->tris.cend());
    impl_->tree.build();
    impl_->tree.accelerate_distance_queries();
  }
}
TriangleDistance::~TriangleDistance() = default;
TriangleDistance::TriangleDistance(TriangleDistance&&) noexcept = default;
TriangleDistance& TriangleDistance::operator=(TriangleDistance&&) noexcept = default;

bool TriangleDistance::empty() const { return impl_->tris.empty(); }

TriangleDistance::Hit TriangleDistance::closest(const P3& q) const {
  Hit h;
  if (impl_->tris.empty()) return h;
  const Point3 p(q[0], q[1], q[2]);
  auto pp = impl_->tree.closest_point_and_primitive(p);
  h.tri = static_cast<int>(pp.second - impl_->tris.cbegin());
  h.point = {pp.first.x(), pp.first.y(), pp.first.z()};
  h.distance = std::sqrt(CGAL::squared_distance(p, pp.first));
  h.bary = barycentric(impl_->tris[h.tri], pp.first);
  return h;
}

}  // namespace surftex
