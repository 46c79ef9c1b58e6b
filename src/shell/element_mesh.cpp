// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/element_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>
#include <unordered_map>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/newell.h"
#include "geometry/properties.h"
#include "geometry/self_intersections.h"
#include "geometry/union_find.h"
#include "geometry/vec3.h"

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

int element_genus(const std::vector<Tri>& tris) {
  if (tris.empty()) return 0;
  int n = 0;
  for (const Tri& t : tris) n = std::max({n, t[0] + 1, t[1] + 1, t[2] + 1});
  std::unordered_map<std::uint64_t, int> uses;
  std::vector<char> used(static_cast<std::size_t>(n), 0);
  UnionFind<int> parts(static_cast<std::size_t>(n));
  for (const Tri& t : tris)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      ++uses[edge_key(std::min(a, b), std::max(a, b))];
      used[static_cast<std::size_t>(a)] = 1;
      parts.unite(a, b);
    }
  // Border loops: components of the graph of border edges.
  UnionFind<int> border(static_cast<std::size_t>(n));
  std::vector<char> on_border(static_cast<std::size_t>(n), 0);
  for (const auto& [key, count] : uses) {
    if (count != 1) continue;
    const int a = static_cast<int>(key >> 32), b = static_cast<int>(key & 0xffffffffu);
    border.unite(a, b);
    on_border[static_cast<std::size_t>(a)] = on_border[static_cast<std::size_t>(b)] = 1;
  }
  long long v = 0, c = 0, loops = 0;
  for (int i = 0; i < n; ++i) {
    if (!used[static_cast<std::size_t>(i)]) continue;
    ++v;
    c += parts.find(i) == i;
    loops += on_border[static_cast<std::size_t>(i)] && border.find(i) == i;
  }
  const long long chi = v - static_cast<long long>(uses.size()) + static_cast<long long>(tris.size());
  return static_cast<int>((2 * c - chi - loops) / 2);
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

namespace {
// Joins two closed rings sampled at the same parameters j / size (outer `o`,
// inner `in`, both in the loop's direction) by a strip of triangles, taking
// whichever ring's next vertex comes first.
void zip_rings(ElementMesh& m, const std::vector<int>& o, const std::vector<int>& in) {
  const std::size_t no = o.size(), ni = in.size();
  std::size_t a = 0, b = 0;
  while (a < no || b < ni) {
    // Outer next when its parameter (a + 1) / no is not past (b + 1) / ni.
    const bool outer = b == ni || (a < no && (a + 1) * ni <= (b + 1) * no);
    if (outer) {
      m.tris.push_back({o[(a + 1) % no], o[a % no], in[b % ni]});
      ++a;
    } else {
      m.tris.push_back({o[a % no], in[b % ni], in[(b + 1) % ni]});
      ++b;
    }
  }
}
}  // namespace

void cap_loop(ElementMesh& m, const std::vector<int>& loop) {
  const std::size_t n = loop.size();
  if (n < 3) return;
  P3 c{0, 0, 0};
  for (int v : loop)
    for (int d = 0; d < 3; ++d) c[d] += m.points[static_cast<std::size_t>(v)][d] / static_cast<double>(n);
  auto dist = [](const P3& p, const P3& q) {
    return std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
  };
  double edge = 0, radius = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const P3& p = m.points[static_cast<std::size_t>(loop[k])];
    edge += dist(p, m.points[static_cast<std::size_t>(loop[(k + 1) % n])]) / static_cast<double>(n);
    radius += dist(p, c) / static_cast<double>(n);
  }
  // Rings at 1 - i / (rings + 1) of the way out, i = 1..rings: spokes of about one edge.
  const int rings = edge > 0 ? std::max(0, static_cast<int>(std::lround(radius / edge)) - 1) : 0;
  std::vector<int> outer = loop;
  for (int i = 1; i <= rings; ++i) {
    const double t = 1.0 - static_cast<double>(i) / (rings + 1);
    const std::size_t ni = std::max<std::size_t>(3, static_cast<std::size_t>(std::lround(static_cast<double>(n) * t)));
    std::vector<int> inner(ni);
    for (std::size_t j = 0; j < ni; ++j) {
      // The loop's point at parameter j / ni (linear between its vertices), shrunk by t towards c.
      const double f = static_cast<double>(j * n) / static_cast<double>(ni);
      const std::size_t k = std::min(n - 1, static_cast<std::size_t>(f));
      const double w = f - static_cast<double>(k);
      const P3 &p = m.points[static_cast<std::size_t>(loop[k])], &q = m.points[static_cast<std::size_t>(loop[(k + 1) % n])];
      P3 r{};
      for (int d = 0; d < 3; ++d) r[d] = c[d] + t * ((1 - w) * p[d] + w * q[d] - c[d]);
      inner[j] = static_cast<int>(m.points.size());
      m.points.push_back(r);
    }
    zip_rings(m, outer, inner);
    outer = std::move(inner);
  }
  const int cv = static_cast<int>(m.points.size());
  m.points.push_back(c);
  for (std::size_t k = 0; k < outer.size(); ++k) m.tris.push_back({outer[(k + 1) % outer.size()], outer[k], cv});
}

std::size_t recentre_fans(ElementMesh& m, int min_valence, double min_offset) {
  // (vertex, next, after) per triangle corner: around v, next -> after.
  std::vector<std::array<int, 3>> corners;
  corners.reserve(3 * m.tris.size());
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) corners.push_back({t[k], t[(k + 1) % 3], t[(k + 2) % 3]});
  std::sort(corners.begin(), corners.end());
  std::vector<std::pair<int, P3>> moves;
  for (std::size_t i = 0; i < corners.size();) {
    std::size_t j = i;
    while (j < corners.size() && corners[j][0] == corners[i][0]) ++j;
    const int v = corners[i][0], n = static_cast<int>(j - i);
    if (n >= min_valence) {
      std::unordered_map<int, int> next;
      for (std::size_t c = i; c < j; ++c) next[corners[c][1]] = corners[c][2];
      std::vector<int> ring{corners[i][1]};  // walk the fan; skip unless it closes after n steps
      while (static_cast<int>(ring.size()) <= n) {
        auto it = next.find(ring.back());
        if (it == next.end()) break;
        ring.push_back(it->second);
      }
      if (static_cast<int>(ring.size()) == n + 1 && ring.back() == ring.front()) {
        ring.pop_back();
        const P3& p = m.points[static_cast<std::size_t>(v)];
        P3 mean{0, 0, 0};
        double spoke = 0;
        for (int u : ring) {
          const P3& q = m.points[static_cast<std::size_t>(u)];
          for (int d = 0; d < 3; ++d) mean[d] += q[d] / n;
          spoke += vec3::norm(vec3::sub(q, p)) / n;
        }
        const P3 nn =
            newell_normal(ring.size(), [&](std::size_t k) -> const P3& { return m.points[static_cast<std::size_t>(ring[k])]; });
        P3 off = vec3::sub(mean, p);
        if (const double ln = vec3::norm(nn); ln > 0) off = vec3::sub(off, vec3::mul(nn, vec3::dot(off, nn) / (ln * ln)));
        if (vec3::norm(off) > min_offset * spoke) moves.push_back({v, vec3::add(p, off)});
      }
    }
    i = j;
  }
  for (const auto& [v, q] : moves) m.points[static_cast<std::size_t>(v)] = q;
  return moves.size();
}

double longest_edge_length(const ElementMesh& m) {
  double l2 = 0;
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) {
      const P3 &a = m.points[static_cast<std::size_t>(t[k])], &b = m.points[static_cast<std::size_t>(t[(k + 1) % 3])];
      l2 = std::max(l2, (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }
  return std::sqrt(l2);
}

double longest_edge_length(const std::vector<ElementMesh>& els) {
  double l = 0;
  for (const ElementMesh& m : els) l = std::max(l, longest_edge_length(m));
  return l;
}

namespace {
// Squared length of every triangle side of `m`, appended to `l2`.
void append_side_lengths2(const ElementMesh& m, std::vector<double>& l2) {
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) {
      const P3 d = vec3::sub(m.points[static_cast<std::size_t>(t[k])], m.points[static_cast<std::size_t>(t[(k + 1) % 3])]);
      l2.push_back(vec3::dot(d, d));
    }
}

double median_length(std::vector<double>& l2) {
  if (l2.empty()) return 0;
  std::nth_element(l2.begin(), l2.begin() + static_cast<std::ptrdiff_t>(l2.size() / 2), l2.end());
  return std::sqrt(l2[l2.size() / 2]);
}
}  // namespace

double median_edge_length(const ElementMesh& m) {
  std::vector<double> l2;
  l2.reserve(3 * m.tris.size());
  append_side_lengths2(m, l2);
  return median_length(l2);
}

double median_edge_length(const std::vector<ElementMesh>& els) {
  std::size_t n = 0;
  for (const ElementMesh& m : els) n += 3 * m.tris.size();
  std::vector<double> l2;
  l2.reserve(n);
  for (const ElementMesh& m : els) append_side_lengths2(m, l2);
  return median_length(l2);
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

std::vector<std::uint32_t> faces_near_changed_elements(const std::vector<ElementMesh>& els,
                                                       const std::vector<char>& fresh) {
  struct Box3 {
    P3 lo, hi;
  };
  std::vector<Box3> box(els.size());
  for (std::size_t e = 0; e < els.size(); ++e) {
    box[e] = {{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
    for (const P3& p : els[e].points)
      for (int k = 0; k < 3; ++k)
        box[e].lo[k] = std::min(box[e].lo[k], p[k]), box[e].hi[k] = std::max(box[e].hi[k], p[k]);
  }
  auto meet = [&](std::size_t a, std::size_t b) {
    for (int k = 0; k < 3; ++k)
      if (box[a].hi[k] < box[b].lo[k] || box[b].hi[k] < box[a].lo[k]) return false;
    return true;
  };
  std::vector<char> take(els.size(), 0);
  for (std::size_t a = 0; a < els.size(); ++a) {
    if (!fresh[a]) continue;
    take[a] = 1;
    for (std::size_t b = 0; b < els.size(); ++b) take[b] = take[b] || meet(a, b);
  }
  std::vector<std::uint32_t> faces;
  std::uint32_t first = 0;
  for (std::size_t e = 0; e < els.size(); ++e) {
    if (take[e])
      for (std::size_t t = 0; t < els[e].tris.size(); ++t)
        faces.push_back(first + static_cast<std::uint32_t>(t));
    first += static_cast<std::uint32_t>(els[e].tris.size());
  }
  return faces;
}

std::vector<std::array<std::uint32_t, 2>> element_self_crossings(const ElementMesh& m, bool parallel) {
  Mesh mesh;
  mesh_from_elements({m}, mesh);
  SelfIntersectionOptions so;
  so.parallel = parallel;
  return self_intersecting_faces(mesh, so);
}

namespace {
// Neighbours (with repeats, as the triangles list them) of the vertices of
// the flagged triangles and one ring more; empty for every other vertex.
std::vector<std::vector<int>> smoothing_neighbours(const ElementMesh& m, const std::vector<char>& faces) {
  const std::size_t nv = m.points.size();
  std::vector<char> region(nv, 0), grown(nv, 0);
  for (std::size_t t = 0; t < m.tris.size(); ++t)
    if (faces[t])
      for (int v : m.tris[t]) region[static_cast<std::size_t>(v)] = 1;
  for (const Tri& t : m.tris)
    if (region[static_cast<std::size_t>(t[0])] || region[static_cast<std::size_t>(t[1])] || region[static_cast<std::size_t>(t[2])])
      for (int v : t) grown[static_cast<std::size_t>(v)] = 1;
  std::vector<std::vector<int>> nb(nv);
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k)
      if (grown[static_cast<std::size_t>(t[k])]) {
        nb[static_cast<std::size_t>(t[k])].push_back(t[(k + 1) % 3]);
        nb[static_cast<std::size_t>(t[k])].push_back(t[(k + 2) % 3]);
      }
  return nb;
}

// `steps` umbrella steps (each vertex with neighbours to their mean, all at once).
void umbrella_steps(std::vector<P3>& points, const std::vector<std::vector<int>>& nb, int steps) {
  for (int it = 0; it < steps; ++it) {
    std::vector<P3> next = points;
    for (std::size_t v = 0; v < points.size(); ++v) {
      if (nb[v].empty()) continue;
      P3 a{0, 0, 0};
      for (int u : nb[v]) a = vec3::add(a, points[static_cast<std::size_t>(u)]);
      next[v] = vec3::mul(a, 1.0 / static_cast<double>(nb[v].size()));
    }
    points.swap(next);
  }
}
}  // namespace

bool smooth_out_crossings(ElementMesh& m, const std::vector<char>& faces, std::size_t own) {
  if (faces.size() != m.tris.size())
    throw InvalidInputError("smooth_out_crossings: " + std::to_string(faces.size()) + " flags for " +
                            std::to_string(m.tris.size()) + " triangles");
  const auto nb = smoothing_neighbours(m, faces);
  ElementMesh trial = m;
  int done = 0;
  for (int steps : {4, 16, 64}) {  // (16 steps from the start are the first 4 and 12 more)
    umbrella_steps(trial.points, nb, steps - done);
    done = steps;
    if (element_self_crossings(trial).size() <= own) {
      m = std::move(trial);
      return true;
    }
  }
  return false;
}

}  // namespace surftex
