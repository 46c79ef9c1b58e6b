// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Helpers for general polygon meshes (quads, n-gons), used by the sqrt(2)
// subdivision and the subdivision synthesis: Newell vector area, polygon area,
// area-weighted vertex normals, mean incident edge length. Include in .cpp
// files only (pulls in CGAL through mesh.h). Nothing here writes properties.

#include <cmath>
#include <vector>

#include "geometry/mesh.h"
#include "geometry/newell.h"

namespace surftex {

/// Newell vector area of polygon f: half the sum of cross products of
/// consecutive corners; its length is the area of a planar polygon.
inline Vector3 polygon_vector_area(const Mesh& mesh, FaceIndex f) {
  std::vector<const Point3*> corners;
  for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) corners.push_back(&mesh.point(v));
  const auto n = newell_normal(corners.size(), [&](std::size_t k) -> const Point3& { return *corners[k]; });
  return Vector3(0.5 * n[0], 0.5 * n[1], 0.5 * n[2]);
}

inline double polygon_area(const Mesh& mesh, FaceIndex f) {
  return std::sqrt(polygon_vector_area(mesh, f).squared_length());
}

/// Unit vertex normals (sum of the Newell vector areas of incident faces),
/// indexed by vertex index; (0,0,1) where the sum vanishes.
inline std::vector<Vector3> polygon_vertex_normals(const Mesh& mesh) {
  std::vector<Vector3> n(mesh.number_of_vertices(), Vector3(0, 0, 0));
  for (FaceIndex f : mesh.faces()) {
    const Vector3 a = polygon_vector_area(mesh, f);
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) n[v.idx()] = n[v.idx()] + a;
  }
  for (Vector3& v : n) {
    const double l = std::sqrt(v.squared_length());
    v = (l > 1e-300 && std::isfinite(l)) ? v / l : Vector3(0, 0, 1);
  }
  return n;
}

/// Mean length of the edges incident to v (0 for an isolated vertex).
inline double mean_incident_edge_length(const Mesh& mesh, VertexIndex v) {
  double s = 0;
  int c = 0;
  for (HalfedgeIndex h : mesh.halfedges_around_target(mesh.halfedge(v))) {
    s += std::sqrt((mesh.point(mesh.source(h)) - mesh.point(v)).squared_length());
    ++c;
  }
  return c ? s / c : 0.0;
}

}  // namespace surftex
