// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/surface_normals.h"

#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

void compute_face_normals(Mesh& mesh) {
  require_triangle_mesh(mesh, "compute_face_normals");
  auto fn = get_or_add(mesh, kFaceNormal, Vector3(0, 0, 1));
  for (FaceIndex f : mesh.faces()) fn[f] = robust_face_normal(mesh, f);
}

void compute_vertex_normals(Mesh& mesh, const VertexNormalOptions& options) {
  require_triangle_mesh(mesh, "compute_vertex_normals");
  auto vn = get_or_add(mesh, kVertexNormal, Vector3(0, 0, 1));
  for (VertexIndex v : mesh.vertices()) {
    Vector3 sum(0, 0, 0), plain(0, 0, 0);
    if (mesh.halfedge(v) == Mesh::null_halfedge()) {
      vn[v] = Vector3(0, 0, 1);
      continue;
    }
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
      if (mesh.is_border(h)) continue;
      const FaceIndex f = mesh.face(h);
      const Vector3 n = robust_face_normal(mesh, f);
      double w = 0;
      if (options.weighting == NormalWeighting::kArea) {
        w = face_area(mesh, f);
      } else {
        w = corner_angle(mesh, h);
      }
      sum = sum + w * n;
      plain = plain + n;
    }
    vn[v] = normalized_or(sum, normalized_or(plain, Vector3(0, 0, 1)));
  }
}

}  // namespace surftex
