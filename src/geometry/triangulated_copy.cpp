// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/triangulated_copy.h"

#include <algorithm>
#include <string>
#include <unordered_set>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex {

std::vector<std::uint32_t> triangulated_copy(const Mesh& m, Mesh& t) {
  auto key = [](VertexIndex a, VertexIndex b) {
    const std::uint64_t x = std::min(a.idx(), b.idx()), y = std::max(a.idx(), b.idx());
    return (x << 32) | y;
  };
  std::unordered_set<std::uint64_t> edges;
  for (EdgeIndex e : m.edges()) edges.insert(key(m.vertex(e, 0), m.vertex(e, 1)));
  t = Mesh();
  std::vector<std::uint32_t> from;  // source vertex of every vertex of t
  std::vector<VertexIndex> to(m.num_vertices(), Mesh::null_vertex());
  for (VertexIndex v : m.vertices()) {
    to[v.idx()] = t.add_vertex(m.point(v));
    from.push_back(v.idx());
  }
  for (FaceIndex f : m.faces()) {
    std::vector<VertexIndex> vs;
    for (VertexIndex v : m.vertices_around_face(m.halfedge(f))) vs.push_back(v);
    if (vs.size() == 4 && (m.point(vs[0]) - m.point(vs[2])).squared_length() >
                              (m.point(vs[1]) - m.point(vs[3])).squared_length())
      std::rotate(vs.begin(), vs.begin() + 1, vs.end());
    bool fits = false;
    for (std::size_t start = 0; start < vs.size() && !fits; ++start) {
      fits = true;
      for (std::size_t i = 2; i + 1 < vs.size() && fits; ++i) fits = !edges.count(key(vs[0], vs[i]));
      if (!fits) std::rotate(vs.begin(), vs.begin() + 1, vs.end());
    }
    std::vector<VertexIndex> tv;
    if (fits) {
      for (std::size_t i = 2; i + 1 < vs.size(); ++i) edges.insert(key(vs[0], vs[i]));
      for (VertexIndex v : vs) tv.push_back(to[v.idx()]);
    } else {  // every start has an existing diagonal: the fan on copies
      for (VertexIndex v : vs) {
        tv.push_back(t.add_vertex(m.point(v)));
        from.push_back(v.idx());
      }
    }
    for (std::size_t i = 1; i + 1 < tv.size(); ++i)
      if (t.add_face(tv[0], tv[i], tv[i + 1]) == Mesh::null_face())
        throw TopologyError("triangulated_copy: could not add a triangle of face " + std::to_string(f.idx()));
  }
  auto src = find(m, kVertexColor);
  if (src.second) {
    auto dst = get_or_add(t, kVertexColor);
    for (VertexIndex v : t.vertices()) dst[v] = src.first[VertexIndex(from[v.idx()])];
  }
  return from;
}

}  // namespace surftex
