// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Helpers shared by the shell tests (header-only, included by test .cpp files).
#include <gtest/gtest.h>

#include <cstdlib>

#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "shell/shell_space.h"
#include "shell/swatch.h"
#include "shell/swatch_generators.h"
#include "test_support.h"

namespace surftex::test {

/// One chart whose uv is the planar (x, y) position scaled by `s` and shifted by `off`.
inline void set_planar_uv(Mesh& m, double s, double off) {
  auto uv = get_or_add(m, kCornerUV, UV{0, 0});
  auto patch = get_or_add(m, kFacePatch, -1);
  for (FaceIndex f : m.faces()) {
    patch[f] = 0;
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
      const Point3& p = m.point(m.target(h));
      uv[h] = {p.x() * s + off, p.y() * s + off};
    }
  }
}

/// A small generated chain mail (3x3 rings) as a mesh, for fast tests.
inline Mesh small_chainmail_mesh(std::uint64_t seed = 1, int segments = 12, int sides = 6) {
  ChainmailOptions o;
  o.rings_x = o.rings_y = 3;
  o.segments = segments;
  o.sides = sides;
  o.seed = seed;
  Mesh m;
  make_chainmail_swatch(m, o);
  return m;
}

/// The same as a swatch.
inline Swatch small_chainmail_swatch(std::uint64_t seed = 1, int segments = 12, int sides = 6) {
  return make_swatch(small_chainmail_mesh(seed, segments, sides));
}

/// A 4 x 4 thread weave mesh (generator defaults otherwise, e.g. WeaveOptions::spacing).
inline Mesh weave_4x4_mesh(int segments_per_spacing, int sides) {
  WeaveOptions wo;
  wo.threads_x = wo.threads_y = 4;
  wo.segments_per_spacing = segments_per_spacing;
  wo.sides = sides;
  Mesh wm;
  make_weave_swatch(wm, wo);
  return wm;
}

/// The same as a swatch.
inline Swatch weave_4x4(int segments_per_spacing, int sides) { return make_swatch(weave_4x4_mesh(segments_per_spacing, sides)); }

/// An icosphere of `subdivisions` squashed to 0.08 along z: a lens, two
/// nearly flat faces meeting at a sharp rim.
inline Mesh flat_lens(int subdivisions) {
  Mesh base;
  make_icosphere(base, subdivisions);
  for (VertexIndex v : base.vertices()) {
    const Point3 p = base.point(v);
    base.point(v) = Point3(p.x(), p.y(), 0.08 * p.z());
  }
  return base;
}

/// A small generated scatter swatch for fast tests.
inline Swatch small_scatter_swatch(std::uint64_t seed = 1) {
  ScatterOptions o;
  o.size = 6;
  o.subdivisions = 1;
  o.seed = seed;
  Mesh m;
  make_scatter_swatch(m, o);
  return make_swatch(m);
}

inline Point3 to_point(const Vec3& p) { return Point3(p[0], p[1], p[2]); }

/// Independent exact check: counts tets not POSITIVE in shell and texture space.
inline std::pair<std::size_t, std::size_t> count_not_positive(const ShellSpace& s) {
  std::size_t a = 0, b = 0;
  for (const Tet& t : s.tets) {
    if (CGAL::orientation(to_point(s.shell_points[t[0]]), to_point(s.shell_points[t[1]]),
                          to_point(s.shell_points[t[2]]), to_point(s.shell_points[t[3]])) != CGAL::POSITIVE)
      ++a;
    if (CGAL::orientation(to_point(s.texture_points[t[0]]), to_point(s.texture_points[t[1]]),
                          to_point(s.texture_points[t[2]]), to_point(s.texture_points[t[3]])) != CGAL::POSITIVE)
      ++b;
  }
  return {a, b};
}

}  // namespace surftex::test
