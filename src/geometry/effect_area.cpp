// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/effect_area.h"

#include <cmath>
#include <functional>
#include <queue>
#include <string>
#include <utility>

#include "geometry/errors.h"
#include "geometry/mesh_util.h"

namespace surftex {

EffectArea EffectArea::whole(const Mesh& mesh) {
  EffectArea a;
  a.face_free.assign(mesh.num_faces(), 0);
  a.vertex_free.assign(mesh.num_vertices(), 0);
  for (FaceIndex f : mesh.faces()) a.face_free[f.idx()] = 1;
  for (VertexIndex v : mesh.vertices()) a.vertex_free[v.idx()] = 1;
  a.free_faces = mesh.number_of_faces();
  a.free_vertices = mesh.number_of_vertices();
  return a;
}

EffectArea compute_effect_area(const Mesh& mesh, const std::vector<std::uint32_t>& seeds,
                               const EffectAreaOptions& opt) {
  if (std::isnan(opt.radius) || opt.radius < 0)
    throw InvalidInputError("compute_effect_area: radius must be >= 0, got " +
                            std::to_string(opt.radius));
  if (seeds.empty()) throw InvalidInputError("compute_effect_area: no seed vertex");
  const std::size_t nv = mesh.num_vertices();
  std::vector<double> dist(nv, std::numeric_limits<double>::infinity());
  std::vector<char> reached(nv, 0);
  using Item = std::pair<double, std::uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (std::uint32_t s : seeds) {
    if (s >= nv || mesh.is_removed(VertexIndex(s)))
      throw InvalidInputError("compute_effect_area: seed vertex " + std::to_string(s) +
                              " out of range (" + std::to_string(nv) + " vertices)");
    dist[s] = 0;
    queue.push({0.0, s});
  }
  EffectArea area;
  area.face_free.assign(mesh.num_faces(), 0);
  area.vertex_free.assign(nv, 0);
  const bool budget = opt.max_faces > 0;
  while (!queue.empty()) {
    const auto [d, vi] = queue.top();
    queue.pop();
    if (reached[vi] || d > dist[vi]) continue;
    if (d > opt.radius) break;
    if (budget && area.free_faces >= opt.max_faces) break;
    reached[vi] = 1;
    const VertexIndex v(vi);
    if (mesh.halfedge(v) == Mesh::null_halfedge()) continue;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
      // Faces completed by v enter the area (in order of distance).
      if (!mesh.is_border(h)) {
        const FaceIndex f = mesh.face(h);
        bool all = true;
        for (VertexIndex w : face_vertices(mesh, f)) all = all && reached[w.idx()];
        if (all && !area.face_free[f.idx()] && (!budget || area.free_faces < opt.max_faces)) {
          area.face_free[f.idx()] = 1;
          ++area.free_faces;
        }
      }
      const VertexIndex w = mesh.source(h);
      const double nd = d + norm(mesh.point(w) - mesh.point(v));
      if (nd < dist[w.idx()]) {
        dist[w.idx()] = nd;
        queue.push({nd, static_cast<std::uint32_t>(w.idx())});
      }
    }
  }
  for (VertexIndex v : mesh.vertices()) {
    if (!reached[v.idx()] || mesh.halfedge(v) == Mesh::null_halfedge()) continue;
    bool all = true;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh))
      if (!mesh.is_border(h) && !area.face_free[mesh.face(h).idx()]) all = false;
    if (all) {
      area.vertex_free[v.idx()] = 1;
      ++area.free_vertices;
    }
  }
  return area;
}

}  // namespace surftex
