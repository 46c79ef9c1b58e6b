// SPDX-License-Identifier: AGPL-3.0-or-later
// See displace_by_vertex_color.h.
#include "texture/displace_by_vertex_color.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/polygon_util.h"
#include "geometry/properties.h"

namespace surftex {

DisplaceResult displace_by_vertex_color(Mesh& mesh, double height) {
  if (!std::isfinite(height))
    throw InvalidInputError("displace_by_vertex_color: height must be finite (got " + std::to_string(height) + ")");
  auto col = find(mesh, kVertexColor);
  if (!col.second) throw InvalidInputError("displace_by_vertex_color: the mesh has no kVertexColor (v:color) map");
  const auto n = polygon_vertex_normals(mesh);
  DisplaceResult res;
  bool first = true;
  std::vector<Point3> p(mesh.number_of_vertices());
  for (VertexIndex v : mesh.vertices()) {
    const Color3f& c = col.first[v];
    const double grey = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    const double off = height * grey;
    p[v.idx()] = mesh.point(v) + n[v.idx()] * off;
    res.min_offset = first ? off : std::min(res.min_offset, off);
    res.max_offset = first ? off : std::max(res.max_offset, off);
    first = false;
  }
  for (VertexIndex v : mesh.vertices()) mesh.point(v) = p[v.idx()];
  return res;
}

}  // namespace surftex
