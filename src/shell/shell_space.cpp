// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/shell_space.h"

#include <CGAL/Polygon_mesh_processing/compute_normal.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <unordered_map>

#include "geometry/errors.h"
#include "geometry/properties.h"

namespace surftex {

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;

Point3 to_point(const Vec3& p) { return Point3(p[0], p[1], p[2]); }

bool positive(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return CGAL::orientation(to_point(a), to_point(b), to_point(c), to_point(d)) == CGAL::POSITIVE;
}

std::string vstr(double x) { return std::to_string(x); }
/// The base mesh, its atlas maps, and the prisms' bottom shell vertices, as
/// build_shell_space's stages share them.
struct ShellBuild {
  const Mesh& base;
  PropertyMap<HalfedgeIndex, UV> uvmap;
  PropertyMap<FaceIndex, int> patch;
  std::map<std::pair<int, int>, int> index;       // (chart, base vertex) -> bottom shell vertex
  std::vector<std::array<int, 3>> face_bottom;    // per base face: its corners' bottom shell vertices
};

void check_shell_inputs(const Mesh& base, const ShellSpaceOptions& opt) {
  if (!(opt.height > 0 && std::isfinite(opt.height)))
    throw InvalidInputError("shell space: height must be positive, got " + vstr(opt.height));
  if (!(opt.shrink_factor > 0 && opt.shrink_factor < 1))
    throw InvalidInputError("shell space: shrink_factor must be in (0,1), got " + vstr(opt.shrink_factor));
  if (opt.max_shrink_steps < 0)
    throw InvalidInputError("shell space: max_shrink_steps must be >= 0, got " +
                            std::to_string(opt.max_shrink_steps));
  if (base.number_of_faces() == 0) throw InvalidInputError("shell space: base mesh has no faces");
  if (base.has_garbage()) throw InvalidInputError("shell space: base mesh has removed elements (collect garbage)");
}

/// Atlas scale (uv per unit length, from the 3D and uv areas) and nominal
/// height (relative: times the mean edge length); w_scale converts heights to
/// texture units. Throws for a non-triangle, an uncharted face, zero area.
void scale_and_height(const ShellBuild& b, const ShellSpaceOptions& opt, ShellSpace& s) {
  const Mesh& base = b.base;
  double a3 = 0, auv = 0, edge_sum = 0;
  for (FaceIndex f : base.faces()) {
    if (base.degree(f) != 3)
      throw InvalidInputError("shell space: face " + std::to_string(f.idx()) + " is not a triangle");
    if (b.patch[f] < 0) throw InvalidInputError("shell space: face " + std::to_string(f.idx()) + " has no chart");
    HalfedgeIndex h = base.halfedge(f);
    a3 += std::sqrt(CGAL::squared_area(base.point(base.source(h)), base.point(base.target(h)),
                                       base.point(base.target(base.next(h)))));
    const UV& p = b.uvmap[base.prev(h)];
    const UV& q = b.uvmap[h];
    const UV& r = b.uvmap[base.next(h)];
    auv += std::abs(0.5 * ((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])));
  }
  for (EdgeIndex e : base.edges()) edge_sum += std::sqrt(CGAL::squared_distance(
                                       base.point(base.vertex(e, 0)), base.point(base.vertex(e, 1))));
  if (!(a3 > 0 && auv > 0)) throw InvalidInputError("shell space: base mesh or its uv atlas has zero area");
  s.uv_per_length = std::sqrt(auv / a3);
  s.height = opt.relative_height ? opt.height * edge_sum / static_cast<double>(base.number_of_edges())
                                 : opt.height;
  s.w_scale = s.height * s.uv_per_length;
}

/// Shell vertices per (chart, base vertex): a bottom and a top one, at the
/// base position and the corner's uv (w = 0 and 1); throws when a vertex has
/// two uvs inside one chart.
void create_shell_vertices(ShellBuild& b, ShellSpace& s) {
  const Mesh& base = b.base;
  b.face_bottom.resize(base.num_faces());
  for (FaceIndex f : base.faces()) {
    const int c = b.patch[f];
    int k = 0;
    for (HalfedgeIndex h : base.halfedges_around_face(base.halfedge(f))) {
      const VertexIndex v = base.target(h);
      const UV uv = b.uvmap[h];
      auto [it, inserted] = b.index.try_emplace({c, static_cast<int>(v.idx())}, static_cast<int>(s.shell_points.size()));
      if (inserted) {
        const Point3& p = base.point(v);
        for (int layer = 0; layer < 2; ++layer) {
          s.shell_points.push_back({p.x(), p.y(), p.z()});
          s.texture_points.push_back({uv[0], uv[1], static_cast<double>(layer)});
          s.base_vertex.push_back(static_cast<int>(v.idx()));
          s.chart.push_back(c);
          s.layer.push_back(static_cast<std::uint8_t>(layer));
          s.lateral.push_back(0);
          s.partner.push_back(static_cast<int>(s.shell_points.size()) + (layer == 0 ? 0 : -2));
        }
      } else {
        const Vec3& t = s.texture_points[static_cast<std::size_t>(it->second)];
        if (t[0] != uv[0] || t[1] != uv[1])
          throw InvalidInputError("shell space: vertex " + std::to_string(v.idx()) + " has two different uvs in chart " +
                                  std::to_string(c) + " (charts must be seamless inside)");
      }
      b.face_bottom[f.idx()][k++] = it->second;
    }
  }
}

/// Marks the lateral vertices, both layers: those on a chart's border (second
/// pass: every shell vertex now exists).
void mark_lateral_vertices(const ShellBuild& b, ShellSpace& s) {
  const Mesh& base = b.base;
  for (FaceIndex f : base.faces()) {
    const int c = b.patch[f];
    for (HalfedgeIndex h : base.halfedges_around_face(base.halfedge(f))) {
      HalfedgeIndex o = base.opposite(h);
      if (base.is_border(o) || b.patch[base.face(o)] != c) {
        for (VertexIndex v : {base.source(h), base.target(h)}) {
          const int bv = b.index.at({c, static_cast<int>(v.idx())});
          s.lateral[static_cast<std::size_t>(bv)] = 1;
          s.lateral[static_cast<std::size_t>(bv) + 1] = 1;
        }
      }
    }
  }
}

/// Three tets per prism, ordered by base vertex index (so that neighbouring
/// prisms split their shared side alike), oriented positively in texture
/// space. Throws SolverError for a degenerate uv triangle.
void build_prism_tets(const ShellBuild& b, ShellSpace& s) {
  const Mesh& base = b.base;
  const std::size_t nf = base.num_faces();
  s.tets.reserve(3 * nf);
  s.tet_face.reserve(3 * nf);
  for (FaceIndex f : base.faces()) {
    std::array<int, 3> fb = b.face_bottom[f.idx()];
    std::sort(fb.begin(), fb.end(), [&](int x, int y) { return s.base_vertex[x] < s.base_vertex[y]; });
    const int a = fb[0], bb = fb[1], c = fb[2], A = a + 1, B = bb + 1, C = c + 1;
    std::array<Tet, 3> t = {Tet{a, bb, c, C}, Tet{a, bb, B, C}, Tet{a, A, B, C}};
    for (Tet& tet : t) {
      CGAL::Orientation o = CGAL::orientation(to_point(s.texture_points[tet[0]]), to_point(s.texture_points[tet[1]]),
                                              to_point(s.texture_points[tet[2]]), to_point(s.texture_points[tet[3]]));
      if (o == CGAL::ZERO)
        throw SolverError("shell space: face " + std::to_string(f.idx()) +
                          " has a degenerate uv triangle (zero area in the atlas)");
      if (o == CGAL::NEGATIVE) std::swap(tet[0], tet[1]);
      s.tets.push_back(tet);
      s.tet_face.push_back(static_cast<int>(f.idx()));
    }
  }
}

/// The prisms inverted by the current offset: a tet not positive in world
/// space, or a top triangle turned over against its base triangle. Their base
/// vertices are set in `bad`; returns their count.
std::size_t mark_inverted_prisms(const ShellSpace& s, const std::vector<std::array<int, 3>>& face_bottom,
                                 std::vector<std::uint8_t>& bad) {
  std::fill(bad.begin(), bad.end(), 0);
  std::size_t nbad = 0;
  for (std::size_t t = 0; t < s.tets.size(); t += 3) {
    bool ok = true;
    for (std::size_t k = t; k < t + 3 && ok; ++k) {
      const Tet& q = s.tets[k];
      ok = positive(s.shell_points[q[0]], s.shell_points[q[1]], s.shell_points[q[2]], s.shell_points[q[3]]);
    }
    // Top triangle must not turn over against its base triangle.
    const std::array<int, 3>& b = face_bottom[static_cast<std::size_t>(s.tet_face[t])];
    if (ok) {
      auto cross = [&](int i0, int i1, int i2) {
        const Vec3 &p = s.shell_points[i0], &q = s.shell_points[i1], &r = s.shell_points[i2];
        const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, w[3] = {r[0] - p[0], r[1] - p[1], r[2] - p[2]};
        return Vec3{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
      };
      const Vec3 n0 = cross(b[0], b[1], b[2]), n1 = cross(b[0] + 1, b[1] + 1, b[2] + 1);
      ok = n0[0] * n1[0] + n0[1] * n1[1] + n0[2] * n1[2] > 0;
    }
    if (!ok) {
      ++nbad;
      for (int i : b) bad[static_cast<std::size_t>(s.base_vertex[i])] = 1;
    }
  }
  return nbad;
}

/// Top vertices at their base vertex moved along its offset direction by its
/// height.
void place_top_layer(const std::vector<Vector3>& normal, ShellSpace& s) {
  for (std::size_t i = 0; i < s.shell_points.size(); i += 2) {
    const int v = s.base_vertex[i];
    const Vector3& n = normal[static_cast<std::size_t>(v)];
    const double hv = s.vertex_height[static_cast<std::size_t>(v)];
    const Vec3& p = s.shell_points[i];
    s.shell_points[i + 1] = {p[0] + hv * n.x(), p[1] + hv * n.y(), p[2] + hv * n.z()};
  }
}

/// Local clamping: the heights of the vertices of inverted prisms shrink by
/// shrink_factor per round, at most max_shrink_steps rounds. Returns the
/// prisms still inverted (their vertices set in `bad`).
std::size_t shrink_inverted_prisms(const std::vector<Vector3>& normal, const std::vector<std::array<int, 3>>& face_bottom,
                                   const ShellSpaceOptions& opt, ShellSpace& s, std::vector<std::uint8_t>& shrunk,
                                   std::vector<std::uint8_t>& bad) {
  for (int round = 0;; ++round) {
    place_top_layer(normal, s);
    const std::size_t nbad = mark_inverted_prisms(s, face_bottom, bad);
    s.shrink_rounds = round;
    if (nbad == 0 || round >= opt.max_shrink_steps) return nbad;
    for (std::size_t v = 0; v < bad.size(); ++v)
      if (bad[v]) s.vertex_height[v] *= opt.shrink_factor, shrunk[v] = 1;
  }
}

/// Base positions as the shell's bottom layer holds them, per base vertex.
std::vector<Vec3> bottom_positions(const Mesh& base, const ShellSpace& s) {
  std::vector<Vec3> pos(base.num_vertices(), Vec3{0, 0, 0});
  for (std::size_t i = 0; i < s.shell_points.size(); i += 2) pos[static_cast<std::size_t>(s.base_vertex[i])] = s.shell_points[i];
  return pos;
}

/// Unfolds the base where no offset direction can make a prism positive: a
/// face turned over against all its neighbours (a fold, e.g. a tiny flipped
/// triangle in a scanned mesh) inverts its prism at any height. The vertices
/// in `bad` move to the mean of their neighbours (Jacobi, `passes` times), in
/// the shell's bottom layer only; the offset directions of every vertex next
/// to a moved one are recomputed (area-weighted face normals) and the moved
/// vertices get the full height back. Returns the vertices moved.
std::size_t unfold_base_layer(const Mesh& base, const std::vector<std::uint8_t>& bad, int passes, ShellSpace& s,
                              std::vector<Vector3>& normal) {
  std::vector<Vec3> pos = bottom_positions(base, s);
  std::size_t moved = 0;
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<Vec3> next = pos;
    for (VertexIndex v : base.vertices()) {
      if (!bad[v.idx()] || base.is_isolated(v)) continue;
      Vec3 sum{0, 0, 0};
      double n = 0;
      for (VertexIndex w : base.vertices_around_target(base.halfedge(v))) {
        for (int k = 0; k < 3; ++k) sum[k] += pos[w.idx()][k];
        n += 1;
      }
      for (int k = 0; k < 3; ++k) next[v.idx()][k] = sum[k] / n;
    }
    pos.swap(next);
  }
  for (std::size_t i = 0; i < s.shell_points.size(); i += 2) s.shell_points[i] = pos[static_cast<std::size_t>(s.base_vertex[i])];
  std::vector<std::uint8_t> touched(base.num_vertices(), 0);
  for (VertexIndex v : base.vertices()) {
    if (!bad[v.idx()]) continue;
    ++moved;
    s.vertex_height[v.idx()] = s.height;
    touched[v.idx()] = 1;
    for (VertexIndex w : base.vertices_around_target(base.halfedge(v))) touched[w.idx()] = 1;
  }
  for (VertexIndex v : base.vertices()) {
    if (!touched[v.idx()] || base.is_isolated(v)) continue;
    Vector3 sum(0, 0, 0);
    for (FaceIndex f : base.faces_around_target(base.halfedge(v))) {
      if (f == Mesh::null_face()) continue;
      std::array<Vec3, 3> p;
      int k = 0;
      for (VertexIndex w : base.vertices_around_face(base.halfedge(f))) p[static_cast<std::size_t>(k++)] = pos[w.idx()];
      const Vector3 a(p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]);
      const Vector3 b(p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]);
      sum = sum + CGAL::cross_product(a, b);
    }
    const double l = std::sqrt(sum.squared_length());
    if (l > 0) normal[v.idx()] = sum / l;
  }
  return moved;
}

/// Offset with local clamping (see the header); where shrinking cannot help,
/// the base layer is unfolded locally (unfold_base_layer, up to `attempts`
/// times with 4, 8, ... 128 passes, the moved set grown by what is still
/// inverted; with `ring`, by one ring of neighbours more each time) and the
/// shrinking resumed. Returns the prisms still inverted.
std::size_t clamp_and_unfold(const Mesh& base, std::vector<Vector3>& normal,
                             const std::vector<std::array<int, 3>>& face_bottom, const ShellSpaceOptions& opt,
                             bool ring, int attempts, ShellSpace& s) {
  s.vertex_height.assign(base.num_vertices(), s.height);
  std::vector<std::uint8_t> shrunk(base.num_vertices(), 0);
  std::vector<std::uint8_t> bad(base.num_vertices(), 0), unfold(base.num_vertices(), 0);
  std::size_t nbad = shrink_inverted_prisms(normal, face_bottom, opt, s, shrunk, bad);
  for (int attempt = 0; nbad > 0 && attempt < attempts; ++attempt) {
    for (std::size_t v = 0; v < bad.size(); ++v) unfold[v] |= bad[v];
    if (ring) {
      const std::vector<std::uint8_t> was = unfold;
      for (VertexIndex v : base.vertices())
        if (was[v.idx()] && !base.is_isolated(v))
          for (VertexIndex w : base.vertices_around_target(base.halfedge(v))) unfold[w.idx()] = 1;
    }
    s.unfolded_vertices = unfold_base_layer(base, unfold, 4 << std::min(attempt, 5), s, normal);
    nbad = shrink_inverted_prisms(normal, face_bottom, opt, s, shrunk, bad);
  }
  s.clamped_vertices = 0;
  for (auto x : shrunk) s.clamped_vertices += x;
  return nbad;
}

/// clamp_and_unfold; if prisms stay inverted (a scanned or modelled fold
/// whose neighbours lean over it too: chair.obj's seat corners), again from
/// the start with the unfolded set grown by a ring each time; if still, a
/// third time with the set grown by what stays inverted only, but up to 16
/// times (dragon_25k.off's 30 folded vertices, no offset direction positive
/// on all their faces: 9 times). Meshes a pass succeeds on are unchanged by
/// the later ones. Throws SolverError when prisms stay inverted.
void offset_with_clamping(const Mesh& base, std::vector<Vector3>& normal,
                          const std::vector<std::array<int, 3>>& face_bottom, const ShellSpaceOptions& opt,
                          ShellSpace& s) {
  const std::vector<Vec3> points = s.shell_points;
  const std::vector<Vector3> normals = normal;
  std::size_t nbad = clamp_and_unfold(base, normal, face_bottom, opt, false, 4, s);
  if (nbad > 0) {
    s.shell_points = points;
    normal = normals;
    nbad = clamp_and_unfold(base, normal, face_bottom, opt, true, 4, s);
  }
  if (nbad > 0) {
    s.shell_points = points;
    normal = normals;
    nbad = clamp_and_unfold(base, normal, face_bottom, opt, false, 16, s);
  }
  if (nbad > 0)
    throw SolverError("shell space: " + std::to_string(nbad) + " prisms still inverted after " +
                      std::to_string(s.shrink_rounds) + " shrink rounds and unfolding " +
                      std::to_string(s.unfolded_vertices) + " base vertices (height " + vstr(s.height) +
                      "; a uv triangle flipped by the atlas, or the surface is too curved for this height)");
}
}  // namespace

double tet_signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6.0;
}

/// Zhou et al. 2006 s.3.1: per chart of the base atlas, a prism of two shell
/// vertices per corner over every face, cut into three tets; the top layer
/// offset along the vertex normals, shrunk locally where prisms invert.
ShellSpace build_shell_space(const Mesh& base, const ShellSpaceOptions& opt) {
  check_shell_inputs(base, opt);
  auto [uvmap, has_uv] = find(base, kCornerUV);
  auto [patch, has_patch] = find(base, kFacePatch);
  if (!has_uv || !has_patch)
    throw InvalidInputError(std::string("shell space: base mesh needs the ") + kCornerUV.name + " and " +
                            kFacePatch.name + " maps (compute_base_mesh_atlas)");
  ShellBuild b{base, uvmap, patch, {}, {}};
  ShellSpace s;
  scale_and_height(b, opt, s);
  // Vertex normals.
  std::vector<Vector3> normal(base.num_vertices(), Vector3(0, 0, 0));
  for (VertexIndex v : base.vertices())
    if (!base.is_isolated(v)) normal[v.idx()] = PMP::compute_vertex_normal(v, base);
  create_shell_vertices(b, s);
  mark_lateral_vertices(b, s);
  build_prism_tets(b, s);
  offset_with_clamping(base, normal, b.face_bottom, opt, s);
  return s;
}

ShellOrientationCheck check_shell_orientation(const ShellSpace& s) {
  ShellOrientationCheck r;
  for (const Tet& t : s.tets) {
    if (!positive(s.shell_points[t[0]], s.shell_points[t[1]], s.shell_points[t[2]], s.shell_points[t[3]]))
      ++r.shell_not_positive;
    if (!positive(s.texture_points[t[0]], s.texture_points[t[1]], s.texture_points[t[2]], s.texture_points[t[3]]))
      ++r.texture_not_positive;
  }
  return r;
}

void shell_boundary_surface(const ShellSpace& s, int chart, Mesh& out) {
  out.clear();
  // Outward faces of a positive tet (a,b,c,d): (a,c,b), (a,b,d), (a,d,c), (b,c,d).
  std::map<std::array<int, 3>, std::pair<std::array<int, 3>, int>> faces;  // sorted key -> (oriented, count)
  for (const Tet& t : s.tets) {
    if (chart >= 0 && s.chart[t[0]] != chart) continue;
    const std::array<std::array<int, 3>, 4> fs = {std::array<int, 3>{t[0], t[2], t[1]}, {t[0], t[1], t[3]},
                                                   {t[0], t[3], t[2]}, {t[1], t[2], t[3]}};
    for (const auto& f : fs) {
      std::array<int, 3> key = f;
      std::sort(key.begin(), key.end());
      auto [it, ins] = faces.try_emplace(key, f, 0);
      it->second.second++;
    }
  }
  std::unordered_map<int, VertexIndex> vmap;
  for (const auto& [key, val] : faces) {
    if (val.second != 1) continue;
    std::array<VertexIndex, 3> vs;
    for (int k = 0; k < 3; ++k) {
      const int i = val.first[k];
      auto it = vmap.find(i);
      if (it == vmap.end())
        it = vmap.emplace(i, out.add_vertex(to_point(s.shell_points[static_cast<std::size_t>(i)]))).first;
      vs[k] = it->second;
    }
    if (out.add_face(vs[0], vs[1], vs[2]) == Mesh::null_face())
      throw TopologyError("shell boundary surface: boundary of chart " + std::to_string(chart) +
                          " is not a manifold surface");
  }
}

}  // namespace surftex
