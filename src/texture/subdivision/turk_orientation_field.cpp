// SPDX-License-Identifier: AGPL-3.0-or-later
// Turk (2001) orientation and sweep fields by diffusion (Bangay & Morkel 2006,
// section 3.1.1). See turk_orientation_field.h.
#include "texture/subdivision/turk_orientation_field.h"

#include <cmath>
#include <deque>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/polygon_util.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

Vector3 project_unit(const Vector3& d, const Vector3& n) {
  const Vector3 t = d - (d * n) * n;
  const double l = std::sqrt(t.squared_length());
  if (!(l > 1e-12) || !std::isfinite(l)) return Vector3(0, 0, 0);
  return t / l;
}

Vector3 default_tangent(const Vector3& n) {
  Vector3 t = project_unit(Vector3(1, 0, 0), n);
  if (t.squared_length() == 0) t = project_unit(Vector3(0, 1, 0), n);
  return t;
}

}  // namespace

TurkFieldResult turk_orientation_field(Mesh& mesh, const std::vector<OrientationKey>& keys,
                                       const TurkFieldOptions& opt) {
  if (mesh.has_garbage()) mesh.collect_garbage();
  const std::size_t nv = mesh.number_of_vertices();
  if (nv == 0) throw InvalidInputError("turk_orientation_field: the mesh has no vertices");
  if (opt.smoothing_passes < 0)
    throw InvalidInputError("turk_orientation_field: smoothing_passes must be >= 0 (got " +
                            std::to_string(opt.smoothing_passes) + ")");
  const std::vector<Vector3> normal = polygon_vertex_normals(mesh);
  auto dir = get_or_add(mesh, kVertexDirection, Vector3(0, 0, 0));
  std::vector<Vector3> cur(nv, Vector3(0, 0, 0));
  std::vector<char> is_key(nv, 0);
  for (const OrientationKey& k : keys) {
    if (k.vertex >= nv)
      throw InvalidInputError("turk_orientation_field: key vertex " + std::to_string(k.vertex) + " out of range (" +
                              std::to_string(nv) + " vertices)");
    const Vector3 d(k.direction[0], k.direction[1], k.direction[2]);
    if (!std::isfinite(d.squared_length()) || d.squared_length() == 0)
      throw InvalidInputError("turk_orientation_field: key direction at vertex " + std::to_string(k.vertex) +
                              " is zero or not finite");
    Vector3 t = project_unit(d, normal[k.vertex]);
    if (t.squared_length() == 0) t = default_tangent(normal[k.vertex]);  // key along the normal
    cur[k.vertex] = t;
    is_key[k.vertex] = 1;
  }
  if (opt.from_existing)
    for (VertexIndex v : mesh.vertices())
      if (!is_key[v.idx()]) cur[v.idx()] = project_unit(dir[v], normal[v.idx()]);

  TurkFieldResult res;
  auto pass = [&](bool fill_only) {
    std::vector<Vector3> next = cur;
    std::size_t changed = 0;
    for (VertexIndex v : mesh.vertices()) {
      const std::size_t i = v.idx();
      if (is_key[i] || mesh.is_isolated(v)) continue;
      if (fill_only && cur[i].squared_length() > 0) continue;
      Vector3 s(0, 0, 0);
      for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(v))) s = s + cur[w.idx()];
      const Vector3 t = project_unit(s, normal[i]);
      if (t.squared_length() > 0) {
        if (cur[i].squared_length() == 0) ++changed;
        next[i] = t;
      }
    }
    cur.swap(next);
    return changed;
  };
  // Fill: spread from defined vertices until nothing new gets a value.
  for (;;) {
    std::size_t undefined = 0;
    for (std::size_t i = 0; i < nv; ++i) undefined += cur[i].squared_length() == 0;
    if (undefined == 0) break;
    if (pass(true) == 0) break;
    ++res.fill_passes;
  }
  for (VertexIndex v : mesh.vertices())
    if (cur[v.idx()].squared_length() == 0) {
      cur[v.idx()] = default_tangent(normal[v.idx()]);
      ++res.unreached;
    }
  for (int p = 0; p < opt.smoothing_passes; ++p) {
    pass(false);
    ++res.smoothing_passes;
  }
  for (VertexIndex v : mesh.vertices()) dir[v] = cur[v.idx()];
  return res;
}

SweepFieldResult turk_sweep_field(Mesh& mesh, std::size_t anchor, const SweepFieldOptions& opt) {
  if (mesh.has_garbage()) mesh.collect_garbage();
  const std::size_t nv = mesh.number_of_vertices();
  if (nv == 0) throw InvalidInputError("turk_sweep_field: the mesh has no vertices");
  if (anchor >= nv)
    throw InvalidInputError("turk_sweep_field: anchor " + std::to_string(anchor) + " out of range (" +
                            std::to_string(nv) + " vertices)");
  if (opt.passes < 0)
    throw InvalidInputError("turk_sweep_field: passes must be >= 0 (got " + std::to_string(opt.passes) + ")");
  auto dirp = find(mesh, kVertexDirection);
  if (!dirp.second) throw InvalidInputError("turk_sweep_field: the mesh has no kVertexDirection (v:dir) map");
  auto dir = dirp.first;
  auto sweep = get_or_add(mesh, kVertexSweep, 0.0);
  std::vector<double> s(nv, 0.0);
  std::vector<char> known(nv, 0);
  std::vector<char> is_anchor(nv, 0);
  auto step = [&](VertexIndex v, VertexIndex w) {  // value v gets from neighbour w
    Vector3 d = dir[v] + dir[w];
    const double l = std::sqrt(d.squared_length());
    d = l > 1e-12 ? d / l : dir[v];
    return s[w.idx()] + (mesh.point(v) - mesh.point(w)) * d;
  };
  if (opt.from_existing) {
    for (VertexIndex v : mesh.vertices()) s[v.idx()] = sweep[v], known[v.idx()] = 1;
    is_anchor[anchor] = 1;
  } else {
    // Breadth-first initialisation from the anchor (and one anchor per other component).
    std::vector<char> seen(nv, 0);
    for (std::size_t start = anchor, k = 0; k <= nv; start = k++) {
      if (k > 0 && (start >= nv || seen[start])) continue;
      if (mesh.is_isolated(VertexIndex(static_cast<Mesh::size_type>(start)))) {
        seen[start] = known[start] = 1;
        continue;
      }
      std::deque<std::size_t> q{start};
      seen[start] = known[start] = is_anchor[start] = 1;
      s[start] = 0;
      while (!q.empty()) {
        const VertexIndex v(static_cast<Mesh::size_type>(q.front()));
        q.pop_front();
        for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(v))) {
          if (seen[w.idx()]) continue;
          seen[w.idx()] = 1;
          // mean over already-known neighbours
          double acc = 0;
          int c = 0;
          for (VertexIndex u : mesh.vertices_around_target(mesh.halfedge(w)))
            if (known[u.idx()]) acc += step(w, u), ++c;
          s[w.idx()] = acc / c;
          known[w.idx()] = 1;
          q.push_back(w.idx());
        }
      }
    }
  }
  for (int p = 0; p < opt.passes; ++p) {
    for (VertexIndex v : mesh.vertices()) {
      if (is_anchor[v.idx()] || mesh.is_isolated(v)) continue;
      double acc = 0;
      int c = 0;
      for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(v))) acc += step(v, w), ++c;
      s[v.idx()] = acc / c;
    }
  }
  SweepFieldResult res;
  res.min_value = res.max_value = s[0];
  for (VertexIndex v : mesh.vertices()) {
    sweep[v] = s[v.idx()];
    res.min_value = std::min(res.min_value, s[v.idx()]);
    res.max_value = std::max(res.max_value, s[v.idx()]);
  }
  return res;
}

}  // namespace surftex
