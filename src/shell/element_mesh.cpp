// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/element_mesh.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <unordered_map>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/union_find.h"

namespace surftex {
namespace {
std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}
}  // namespace

int triangle_components(const ElementMesh& m, std::vector<int>& comp) {
  UnionFind<int> sets(m.points.size());
  for (const Tri& t : m.tris)
    for (int k = 1; k < 3; ++k) sets.unite(t[0], t[k]);
  std::vector<int> id(m.points.size(), -1);
  comp.assign(m.tris.size(), -1);
  int n = 0;
  for (std::size_t i = 0; i < m.tris.size(); ++i) {
    const int r = sets.find(m.tris[i][0]);
    if (id[r] < 0) id[r] = n++;
    comp[i] = id[r];
  }
  return n;
}

std::size_t count_border_edges(const ElementMesh& m) {
  std::unordered_map<std::uint64_t, int> count;
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) {
      int a = t[k], b = t[(k + 1) % 3];
      ++count[edge_key(std::min(a, b), std::max(a, b))];
    }
  std::size_t n = 0;
  for (auto& e : count) n += e.second == 1;
  return n;
}

bool is_closed_oriented(const ElementMesh& m) {
  std::unordered_map<std::uint64_t, int> directed;
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) {
      if (t[k] == t[(k + 1) % 3]) return false;
      if (++directed[edge_key(t[k], t[(k + 1) % 3])] > 1) return false;
    }
  for (auto& e : directed) {
    int a = static_cast<int>(e.first >> 32), b = static_cast<int>(e.first & 0xffffffffu);
    if (!directed.count(edge_key(b, a))) return false;
  }
  return true;
}

bool boundary_loops(const ElementMesh& m, std::vector<std::vector<int>>& loops) {
  loops.clear();
  std::unordered_map<std::uint64_t, int> directed;
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) ++directed[edge_key(t[k], t[(k + 1) % 3])];
  std::unordered_map<int, int> next;  // border edge a -> b
  std::vector<int> starts;
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) {
      int a = t[k], b = t[(k + 1) % 3];
      if (directed.count(edge_key(b, a))) continue;
      if (next.count(a)) return false;
      next[a] = b;
      starts.push_back(a);
    }
  std::unordered_map<int, char> used;
  for (int s : starts) {
    if (used.count(s)) continue;
    std::vector<int> loop;
    int v = s;
    while (!used.count(v)) {
      used[v] = 1;
      loop.push_back(v);
      auto it = next.find(v);
      if (it == next.end()) return false;
      v = it->second;
    }
    if (v != s) return false;
    loops.push_back(std::move(loop));
  }
  return true;
}

std::vector<P3> face_normals(const ElementMesh& m) {
  std::vector<P3> n(m.tris.size(), P3{0, 0, 0});
  for (std::size_t i = 0; i < m.tris.size(); ++i) {
    const P3 &a = m.points[m.tris[i][0]], &b = m.points[m.tris[i][1]], &c = m.points[m.tris[i][2]];
    P3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    P3 x{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    double l = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    if (l > 0) n[i] = {x[0] / l, x[1] / l, x[2] / l};
  }
  return n;
}

std::vector<P3> vertex_normals(const ElementMesh& m) {
  std::vector<P3> n(m.points.size(), P3{0, 0, 0});
  for (const Tri& t : m.tris) {
    const P3 &a = m.points[t[0]], &b = m.points[t[1]], &c = m.points[t[2]];
    P3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    P3 x{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) n[t[k]][d] += x[d];
  }
  for (P3& v : n) {
    double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0) v = {v[0] / l, v[1] / l, v[2] / l};
  }
  return n;
}

std::vector<std::vector<int>> vertex_neighbours(const ElementMesh& m) {
  std::vector<std::vector<int>> nb(m.points.size());
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) {
      nb[t[k]].push_back(t[(k + 1) % 3]);
      nb[t[k]].push_back(t[(k + 2) % 3]);
    }
  for (auto& v : nb) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
  }
  return nb;
}

ElementMesh extract_triangles(const ElementMesh& m, const std::vector<int>& tris) {
  ElementMesh out;
  std::unordered_map<int, int> remap;
  for (int t : tris) {
    Tri nt;
    for (int k = 0; k < 3; ++k) {
      int v = m.tris[t][k];
      auto it = remap.find(v);
      if (it == remap.end()) {
        it = remap.emplace(v, static_cast<int>(out.points.size())).first;
        out.points.push_back(m.points[v]);
      }
      nt[k] = it->second;
    }
    out.tris.push_back(nt);
  }
  return out;
}

void append(ElementMesh& a, const ElementMesh& b) {
  const int off = static_cast<int>(a.points.size());
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  for (const Tri& t : b.tris) a.tris.push_back({t[0] + off, t[1] + off, t[2] + off});
}

ElementMesh element_mesh_from(const Mesh& mesh) {
  ElementMesh out;
  std::vector<int> id(mesh.num_vertices() + mesh.number_of_removed_vertices(), -1);
  for (VertexIndex v : mesh.vertices()) {
    id[v.idx()] = static_cast<int>(out.points.size());
    const Point3& p = mesh.point(v);
    out.points.push_back({p.x(), p.y(), p.z()});
  }
  for (FaceIndex f : mesh.faces()) {
    Tri t;
    int k = 0;
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
      if (k == 3) throw InvalidInputError("element_mesh_from: face " + std::to_string(f.idx()) +
                                          " is not a triangle");
      t[k++] = id[v.idx()];
    }
    if (k != 3)
      throw InvalidInputError("element_mesh_from: face " + std::to_string(f.idx()) + " is degenerate");
    out.tris.push_back(t);
  }
  return out;
}

void mesh_from_elements(const std::vector<ElementMesh>& elements, Mesh& out) {
  out.clear();
  auto elem = get_or_add(out, kFaceElement, -1);
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const ElementMesh& m = elements[e];
    std::vector<VertexIndex> vs;
    vs.reserve(m.points.size());
    for (const P3& p : m.points) vs.push_back(out.add_vertex(Point3(p[0], p[1], p[2])));
    for (const Tri& t : m.tris) {
      FaceIndex f = out.add_face(vs[t[0]], vs[t[1]], vs[t[2]]);
      if (f == Mesh::null_face())
        throw TopologyError("mesh_from_elements: element " + std::to_string(e) +
                            " has a non-manifold triangle (" + std::to_string(t[0]) + "," +
                            std::to_string(t[1]) + "," + std::to_string(t[2]) + ")");
      elem[f] = static_cast<int>(e);
    }
  }
}

}  // namespace surftex
