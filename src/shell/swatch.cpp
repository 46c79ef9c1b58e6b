// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/swatch.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <CGAL/Polygon_mesh_processing/connected_components.h>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"

namespace surftex {

Swatch make_swatch(const Mesh& mesh) {
  if (mesh.number_of_faces() == 0) throw InvalidInputError("swatch: the mesh has no faces");
  // read_mesh refuses NaN/inf in files; a mesh built or transformed in code
  // (e.g. scaled by a huge factor) can still carry them, and one non-finite
  // point would poison every bounding box and cell size downstream.
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw InvalidInputError("swatch: vertex " + std::to_string(v.idx()) + " has a non-finite coordinate (" +
                              std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                              ")");
  }
  Swatch s;
  s.mesh = element_mesh_from(mesh);
  const int n = triangle_components(s.mesh, s.face_element);
  s.elements.assign(static_cast<std::size_t>(n), SwatchElement{});
  std::vector<std::vector<int>> tris(static_cast<std::size_t>(n));
  for (std::size_t t = 0; t < s.mesh.tris.size(); ++t) tris[s.face_element[t]].push_back(static_cast<int>(t));
  s.bbox_min = {1e300, 1e300, 1e300};
  s.bbox_max = {-1e300, -1e300, -1e300};
  double edge_sum = 0;
  std::size_t edges = 0;
  for (int e = 0; e < n; ++e) {
    ElementMesh em = extract_triangles(s.mesh, tris[e]);
    SwatchElement& el = s.elements[e];
    el.faces = em.tris.size();
    el.closed = count_border_edges(em) == 0;
    el.bbox_min = {1e300, 1e300, 1e300};
    el.bbox_max = {-1e300, -1e300, -1e300};
    for (const P3& p : em.points)
      for (int d = 0; d < 3; ++d) {
        el.bbox_min[d] = std::min(el.bbox_min[d], p[d]);
        el.bbox_max[d] = std::max(el.bbox_max[d], p[d]);
        el.centroid[d] += p[d] / static_cast<double>(em.points.size());
      }
    for (int d = 0; d < 3; ++d) {
      s.bbox_min[d] = std::min(s.bbox_min[d], el.bbox_min[d]);
      s.bbox_max[d] = std::max(s.bbox_max[d], el.bbox_max[d]);
    }
    for (const Tri& t : em.tris)
      for (int k = 0; k < 3; ++k) {
        const P3 &a = em.points[t[k]], &b = em.points[t[(k + 1) % 3]];
        edge_sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                              (a[2] - b[2]) * (a[2] - b[2]));
        ++edges;
      }
  }
  s.mean_edge_length = edges ? edge_sum / static_cast<double>(edges) : 0;
  if (!(s.length() > 0) || !(s.width() > 0))
    throw InvalidInputError("swatch: zero extent in x or y (" + std::to_string(s.length()) + " x " +
                            std::to_string(s.width()) + ")");
  return s;
}

Swatch load_swatch(const std::string& path) {
  Mesh m;
  read_mesh(path, m);
  return make_swatch(m);
}

ElementMesh swatch_element(const Swatch& s, int e) {
  std::vector<int> tris;
  for (std::size_t t = 0; t < s.face_element.size(); ++t)
    if (s.face_element[t] == e) tris.push_back(static_cast<int>(t));
  return extract_triangles(s.mesh, tris);
}

int label_elements(Mesh& mesh) {
  auto elem = get_or_add(mesh, kFaceElement, -1);
  // Component ids numbered in order of the first face, independent of CGAL's
  // numbering: relabel by first appearance.
  auto tmp = mesh.add_property_map<FaceIndex, std::size_t>("f:tmp_cc", 0).first;
  CGAL::Polygon_mesh_processing::connected_components(mesh, tmp);
  std::vector<int> relabel;
  int n = 0;
  for (FaceIndex f : mesh.faces()) {
    std::size_t c = tmp[f];
    if (c >= relabel.size()) relabel.resize(c + 1, -1);
    if (relabel[c] < 0) relabel[c] = n++;
    elem[f] = relabel[c];
  }
  mesh.remove_property_map(tmp);
  return n;
}

}  // namespace surftex
