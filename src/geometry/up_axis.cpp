// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/up_axis.h"

#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex {

namespace {

Vector3 turned(const Vector3& v) { return Vector3(v.x(), v.z(), -v.y()); }

template <class Index>
void turn_vectors(Mesh& mesh, PropertyName<Index, Vector3> name) {
  auto m = find(mesh, name);
  if (!m.second) return;
  if constexpr (std::is_same_v<Index, VertexIndex>) {
    for (VertexIndex v : mesh.vertices()) m.first[v] = turned(m.first[v]);
  } else {
    for (FaceIndex f : mesh.faces()) m.first[f] = turned(m.first[f]);
  }
}

}  // namespace

void z_up_to_y_up(Mesh& mesh) {
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    mesh.point(v) = Point3(p.x(), p.z(), -p.y());
  }
  turn_vectors(mesh, kVertexNormal);
  turn_vectors(mesh, kFaceNormal);
  turn_vectors(mesh, kVertexDmax);
  turn_vectors(mesh, kVertexDmin);
  turn_vectors(mesh, kFaceDirection);
  turn_vectors(mesh, kVertexDirection);
}

}  // namespace surftex
