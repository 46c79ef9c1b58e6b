// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/render_mesh.h"

#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/properties.h"

namespace surftex {

RenderMesh make_render_mesh(const Mesh& mesh, const RenderMeshOptions& opt) {
  if (mesh.number_of_faces() == 0) throw InvalidInputError("make_render_mesh: the mesh has no faces");
  RenderMesh out;
  std::vector<int> vmap(mesh.num_vertices(), -1);
  out.positions.reserve(mesh.number_of_vertices());
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw InvalidInputError("make_render_mesh: vertex " + std::to_string(v.idx()) + " has a non-finite coordinate");
    vmap[v.idx()] = static_cast<int>(out.positions.size());
    out.positions.push_back({static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  }
  PropertyMap<HalfedgeIndex, UV> uv_map;
  if (opt.corner_uvs) {
    auto [m, found] = find(mesh, kCornerUV);
    if (!found) throw InvalidInputError(std::string("make_render_mesh: texture coordinates requested but the mesh has no '") + kCornerUV.name + "' property");
    uv_map = m;
  }
  for (FaceIndex f : mesh.faces()) {
    HalfedgeIndex h0 = mesh.halfedge(f);
    HalfedgeIndex h1 = mesh.next(h0);
    for (HalfedgeIndex h2 = mesh.next(h1); h2 != h0; h1 = h2, h2 = mesh.next(h2)) {
      out.triangles.push_back({vmap[mesh.target(h0).idx()], vmap[mesh.target(h1).idx()], vmap[mesh.target(h2).idx()]});
      out.triangle_face.push_back(static_cast<int>(f.idx()));
      if (opt.corner_uvs)
        for (HalfedgeIndex h : {h0, h1, h2})
          out.corner_uvs.push_back({static_cast<float>(uv_map[h][0]), static_cast<float>(uv_map[h][1])});
    }
  }
  if (opt.vertex_colors) {
    auto [cmap, found] = find(mesh, kVertexColor);
    if (!found) throw InvalidInputError(std::string("make_render_mesh: vertex colours requested but the mesh has no '") + kVertexColor.name + "' property");
    out.vertex_colors.reserve(out.positions.size());
    for (VertexIndex v : mesh.vertices()) out.vertex_colors.push_back(cmap[v]);
  }
  if (opt.smooth_normals) {
    // Area-weighted: the sum of the (unnormalised) cross products of the incident triangles.
    std::vector<std::array<double, 3>> acc(out.positions.size(), {0.0, 0.0, 0.0});
    for (const auto& t : out.triangles) {
      const Vec3f &a = out.positions[t[0]], &b = out.positions[t[1]], &c = out.positions[t[2]];
      double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
      double w[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
      double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i) acc[t[k]][i] += n[i];
    }
    out.vertex_normals.reserve(acc.size());
    for (const auto& n : acc) {
      double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      double s = l > 0 ? 1.0 / l : 0.0;  // isolated or degenerate: zero, the face normal takes over
      out.vertex_normals.push_back({static_cast<float>(n[0] * s), static_cast<float>(n[1] * s), static_cast<float>(n[2] * s)});
    }
  }
  return out;
}

}  // namespace surftex
