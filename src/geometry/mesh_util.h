// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Small geometric helpers shared by the field and parameterization code
// (face normals that are never NaN, areas, corner angles, cotangents, local
// face frames). Include in .cpp files only: it pulls in CGAL through mesh.h.

#include <CGAL/boost/graph/iterator.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"

namespace surftex {

inline double norm(const Vector3& v) { return std::sqrt(v.squared_length()); }

/// v / |v|, or `fallback` when |v| is (numerically) zero or not finite.
inline Vector3 normalized_or(const Vector3& v, const Vector3& fallback) {
  const double l = norm(v);
  if (!(l > 1e-300) || !std::isfinite(l)) return fallback;
  return v / l;
}

/// Throws InvalidInputError naming `who` if a face is not a triangle.
inline void require_triangle_mesh(const Mesh& mesh, const char* who) {
  for (FaceIndex f : mesh.faces()) {
    if (mesh.degree(f) != 3) {
      throw InvalidInputError(std::string(who) + ": face " + std::to_string(f.idx()) +
                              " has " + std::to_string(mesh.degree(f)) +
                              " vertices; triangulate the mesh first");
    }
  }
}

/// The three vertices of triangle f, in order (target of halfedge(f) first).
inline std::array<VertexIndex, 3> face_vertices(const Mesh& mesh, FaceIndex f) {
  const HalfedgeIndex h = mesh.halfedge(f);
  return {mesh.target(h), mesh.target(mesh.next(h)), mesh.target(mesh.prev(h))};
}

// The longest side of the mesh's axis-aligned bounding box (the unit in which
// subdiv and patches count exemplar widths across the object).
inline double longest_bbox_side(const Mesh& mesh) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  }
  return std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
}

inline double face_area(const Mesh& mesh, FaceIndex f) {
  const auto v = face_vertices(mesh, f);
  const Vector3 c =
      CGAL::cross_product(mesh.point(v[1]) - mesh.point(v[0]), mesh.point(v[2]) - mesh.point(v[0]));
  return 0.5 * norm(c);
}

/// Unit normal of triangle f: the largest of the three corner cross products
/// (same direction for a good triangle, the stable one for a sliver); (0,0,1)
/// for a fully collapsed face.
inline Vector3 robust_face_normal(const Mesh& mesh, FaceIndex f) {
  const auto v = face_vertices(mesh, f);
  Vector3 best(0, 0, 0);
  double best_len = 0;
  for (int i = 0; i < 3; ++i) {
    const Point3& a = mesh.point(v[i]);
    const Vector3 c =
        CGAL::cross_product(mesh.point(v[(i + 1) % 3]) - a, mesh.point(v[(i + 2) % 3]) - a);
    const double l = c.squared_length();
    if (l > best_len) {
      best_len = l;
      best = c;
    }
  }
  return normalized_or(best, Vector3(0, 0, 1));
}

/// Angle of face(h) at target(h), in radians, in [0, pi]; 0 for collapsed corners.
inline double corner_angle(const Mesh& mesh, HalfedgeIndex h) {
  const Point3& p = mesh.point(mesh.target(h));
  const Vector3 a = mesh.point(mesh.source(h)) - p;
  const Vector3 b = mesh.point(mesh.target(mesh.next(h))) - p;
  const double s = norm(CGAL::cross_product(a, b));
  const double c = a * b;
  if (s == 0 && c == 0) return 0;
  return std::atan2(s, c);
}

/// Cotangent of the angle opposite to halfedge h in face(h) (0 on a border
/// halfedge), clamped to [-cot_max, cot_max] so slivers stay finite.
inline double cotan_opposite(const Mesh& mesh, HalfedgeIndex h, double cot_max = 1e3) {
  if (mesh.is_border(h)) return 0;
  const Point3& o = mesh.point(mesh.target(mesh.next(h)));
  const Vector3 a = mesh.point(mesh.source(h)) - o;
  const Vector3 b = mesh.point(mesh.target(h)) - o;
  const double s = norm(CGAL::cross_product(a, b));
  const double c = a * b;
  if (!(s > 1e-300)) return c >= 0 ? cot_max : -cot_max;
  return std::clamp(c / s, -cot_max, cot_max);
}

/// Orthonormal tangent frame of face f: e1 along the first edge of the face
/// (source(halfedge(f)) -> target(halfedge(f))), e2 = n x e1, n the face normal.
struct FaceFrame {
  Vector3 e1, e2, n;
  /// Angle of the tangential part of v in this frame.
  double angle_of(const Vector3& v) const { return std::atan2(v * e2, v * e1); }
  Vector3 direction(double angle) const { return std::cos(angle) * e1 + std::sin(angle) * e2; }
};

inline FaceFrame face_frame(const Mesh& mesh, FaceIndex f) {
  FaceFrame fr;
  fr.n = robust_face_normal(mesh, f);
  const HalfedgeIndex h = mesh.halfedge(f);
  Vector3 e = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
  e = e - (e * fr.n) * fr.n;
  // Fall back to any vector orthogonal to n for a collapsed first edge.
  Vector3 any = std::abs(fr.n.x()) < 0.9 ? Vector3(1, 0, 0) : Vector3(0, 1, 0);
  any = any - (any * fr.n) * fr.n;
  fr.e1 = normalized_or(e, normalized_or(any, Vector3(1, 0, 0)));
  fr.e2 = CGAL::cross_product(fr.n, fr.e1);
  return fr;
}

/// Wraps an angle into (-pi, pi].
inline double wrap_angle(double a) {
  const double two_pi = 2 * M_PI;
  a = std::fmod(a, two_pi);
  if (a <= -M_PI) a += two_pi;
  if (a > M_PI) a -= two_pi;
  return a;
}

}  // namespace surftex
