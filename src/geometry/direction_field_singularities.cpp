// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/direction_field_singularities.h"

#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

std::vector<int> direction_field_indices(const Mesh& mesh, const FieldIndexOptions& opt) {
  const int N = opt.symmetry;
  if (N != 1 && N != 2 && N != 4)
    throw InvalidInputError("direction_field_indices: symmetry must be 1, 2 or 4, got " +
                            std::to_string(N));
  auto found = find(mesh, opt.direction_map);
  if (!found.second)
    throw InvalidInputError("direction_field_indices: face map '" + std::string(opt.direction_map.name) +
                            "' absent");
  const auto& dir = found.first;
  std::vector<int> index(mesh.num_vertices(), 0);
  const double step = 2 * M_PI / N;
  // The jump across each interior edge is computed once, from face(halfedge(e,0))
  // to the opposite face, so that both endpoints see exactly opposite values
  // (rounding at +-pi/N would otherwise break Poincare-Hopf on symmetric fields).
  std::vector<FaceFrame> frames(mesh.num_faces());
  for (FaceIndex f : mesh.faces()) frames[f.idx()] = face_frame(mesh, f);
  std::vector<double> jump(mesh.num_edges(), 0.0);
  for (EdgeIndex e : mesh.edges()) {
    if (mesh.is_border(e)) continue;
    const HalfedgeIndex h = mesh.halfedge(e, 0);
    const FaceIndex f = mesh.face(h), g = mesh.face(mesh.opposite(h));
    const FaceFrame &ff = frames[f.idx()], &fg = frames[g.idx()];
    const Vector3 ev = mesh.point(mesh.target(h)) - mesh.point(mesh.source(h));
    const double transported = ff.angle_of(dir[f]) - ff.angle_of(ev) + fg.angle_of(ev);
    double d = fg.angle_of(dir[g]) - transported;
    d -= step * std::round(d / step);  // [-pi/N, pi/N]
    jump[e.idx()] = d;
  }
  for (VertexIndex v : mesh.vertices()) {
    if (mesh.halfedge(v) == Mesh::null_halfedge() || mesh.is_border(v)) continue;
    double jumps = 0, angle_sum = 0;
    // CGAL visits the faces around v clockwise: face(h_i) -> face(opposite(next(h_i))).
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
      const HalfedgeIndex shared = mesh.next(h);  // in face(h), leaving v
      const EdgeIndex e = mesh.edge(shared);
      // jump[e] goes from face(halfedge(e,0)) to the other face.
      jumps += (mesh.halfedge(e, 0) == shared) ? jump[e.idx()] : -jump[e.idx()];
      angle_sum += corner_angle(mesh, h);
    }
    const double defect = 2 * M_PI - angle_sum;
    // Clockwise traversal: the counter-clockwise jump sum is -jumps.
    index[v.idx()] = static_cast<int>(std::lround(N * (defect - jumps) / (2 * M_PI)));
  }
  return index;
}

}  // namespace surftex
