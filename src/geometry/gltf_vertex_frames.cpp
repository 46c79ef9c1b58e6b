// SPDX-License-Identifier: AGPL-3.0-or-later
// glTF vertices and their frames (see gltf_vertex_frames.h).
#include "geometry/gltf_vertex_frames.h"

#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/newell.h"
#include "geometry/properties.h"
#include "geometry/vertex_tangents.h"

namespace surftex {

std::vector<std::array<float, 3>> export_vertex_normals(const Mesh& mesh) {
  std::vector<std::size_t> id(mesh.num_vertices(), SIZE_MAX);
  std::vector<std::array<double, 3>> pos;
  pos.reserve(mesh.number_of_vertices());
  for (VertexIndex v : mesh.vertices()) {
    id[v.idx()] = pos.size();
    const Point3& p = mesh.point(v);
    pos.push_back({p.x(), p.y(), p.z()});
  }
  std::vector<std::array<float, 3>> normals(pos.size(), {0.f, 0.f, 0.f});
  auto m = find(mesh, kVertexNormal);
  if (m.second) {
    for (VertexIndex v : mesh.vertices()) {
      const Vector3& n = m.first[v];
      normals[id[v.idx()]] = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
    }
    return normals;
  }
  // Area-weighted smooth normals (Newell's method per face: twice the
  // vector area, so larger faces weigh more).
  std::vector<std::array<double, 3>> acc(pos.size(), {0.0, 0.0, 0.0});
  std::vector<std::size_t> f;
  for (FaceIndex fc : mesh.faces()) {
    f.clear();
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(fc))) f.push_back(id[mesh.target(h).idx()]);
    const std::array<double, 3> n =
        newell_normal(f.size(), [&](std::size_t k) -> const std::array<double, 3>& { return pos[f[k]]; });
    for (std::size_t v : f)
      for (int c = 0; c < 3; ++c) acc[v][c] += n[c];
  }
  for (std::size_t i = 0; i < acc.size(); ++i) {
    double l = std::sqrt(acc[i][0] * acc[i][0] + acc[i][1] * acc[i][1] + acc[i][2] * acc[i][2]);
    normals[i] = l > 0 ? std::array<float, 3>{static_cast<float>(acc[i][0] / l), static_cast<float>(acc[i][1] / l),
                                              static_cast<float>(acc[i][2] / l)}
                       : std::array<float, 3>{0.f, 0.f, 1.f};
  }
  return normals;
}

std::uint32_t GltfVertexSplit::id(std::size_t vertex, const std::array<double, 2>& uv) {
  auto [it, inserted] = key_to_id_.emplace(std::make_pair(vertex, uv), static_cast<std::uint32_t>(source_.size()));
  if (inserted) {
    source_.push_back(vertex);
    // glTF's UV origin is the top-left of the image, OBJ's/ours the bottom-left.
    texcoord_.push_back({static_cast<float>(uv[0]), static_cast<float>(1.0 - uv[1])});
  }
  return it->second;
}

std::vector<std::array<float, 4>> gltf_vertex_tangents(const std::vector<std::array<double, 3>>& positions,
                                                       const std::vector<std::array<float, 3>>& normals,
                                                       const GltfVertexSplit& split,
                                                       const std::vector<std::uint32_t>& triangles) {
  const auto& src = split.source();
  const auto& tc = split.texcoord();
  std::vector<std::array<float, 3>> p(src.size()), n(src.size());
  std::vector<std::array<float, 2>> t(src.size());
  for (std::size_t i = 0; i < src.size(); ++i) {
    if (src[i] >= positions.size() || src[i] >= normals.size())
      throw InvalidInputError("gltf_vertex_tangents: glTF vertex " + std::to_string(i) + " names mesh vertex " +
                              std::to_string(src[i]) + " of " + std::to_string(positions.size()));
    for (int c = 0; c < 3; ++c) p[i][c] = static_cast<float>(positions[src[i]][c]);
    n[i] = normals[src[i]];
    t[i] = {tc[i][0], 1.f - tc[i][1]};  // uv with v up
  }
  return vertex_tangents(p, n, t, triangles);
}

GltfVertexFrames gltf_vertex_frames(const Mesh& mesh) {
  auto uv = find(mesh, kCornerUV);
  if (!uv.second) throw InvalidInputError("gltf_vertex_frames: the mesh has no corner uv (kCornerUV)");
  if (mesh.has_garbage()) throw InvalidInputError("gltf_vertex_frames: the mesh has removed elements");
  std::vector<std::array<double, 3>> pos;
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    pos.push_back({p.x(), p.y(), p.z()});
  }
  GltfVertexFrames fr;
  fr.normal = export_vertex_normals(mesh);
  fr.corner.assign(mesh.num_halfedges(), 0);
  GltfVertexSplit split;
  std::vector<std::uint32_t> tri;
  std::vector<std::uint32_t> ids;
  for (FaceIndex f : mesh.faces()) {  // as write_glb: corners in order, fanned from the first
    ids.clear();
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      fr.corner[h.idx()] = split.id(mesh.target(h).idx(), uv.first[h]);
      ids.push_back(fr.corner[h.idx()]);
    }
    for (std::size_t k = 1; k + 1 < ids.size(); ++k) tri.insert(tri.end(), {ids[0], ids[k], ids[k + 1]});
  }
  fr.tangent = gltf_vertex_tangents(pos, fr.normal, split, tri);
  std::vector<std::array<float, 3>> n(split.size());
  for (std::size_t i = 0; i < split.size(); ++i) n[i] = fr.normal[split.source()[i]];
  fr.normal = std::move(n);
  return fr;
}

}  // namespace surftex
