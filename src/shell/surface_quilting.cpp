// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/surface_quilting.h"

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <unordered_map>

#include "geometry/direction_field.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/timer.h"
#include "shell/triangle_distance.h"

namespace surftex {

namespace {
namespace PMP = CGAL::Polygon_mesh_processing;
namespace SMP = CGAL::Surface_mesh_parameterization;
using V2 = std::array<double, 2>;
constexpr double kPi = 3.14159265358979323846;
// Cosine of the largest angle between an off-patch vertex's face and its
// nearest patch face for the element to be expressed in the patch frame.
constexpr double kFrameCos = 0.5;

P3 sub3(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot3(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
P3 cross3(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm3(const P3& a) { return std::sqrt(dot3(a, a)); }
double area2(const V2& a, const V2& b, const V2& c) {
  return 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
}
// Barycentric (b0, b1, b2) of p in the 2D triangle (a, b, c); false if degenerate.
bool bary2(const V2& p, const V2& a, const V2& b, const V2& c, std::array<double, 3>& w) {
  const double d = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  if (!(std::abs(d) > 0)) return false;
  w[1] = ((p[0] - a[0]) * (c[1] - a[1]) - (p[1] - a[1]) * (c[0] - a[0])) / d;
  w[2] = ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) / d;
  w[0] = 1 - w[1] - w[2];
  return true;
}

// The base mesh as arrays (face index order, vertices of each face in
// vertices_around_face(halfedge(f)) order).
struct Base {
  std::vector<P3> pts;
  std::vector<std::array<int, 3>> faces;
  std::vector<P3> centroid, normal;
  std::vector<double> area;
  std::vector<std::array<int, 3>> edge_nb;      // face across the edge (v_k, v_k+1), -1 = border
  std::vector<std::vector<int>> vertex_nb;      // faces sharing a vertex (excluding itself)
};

Base make_base(const Mesh& m) {
  if (m.has_garbage()) throw InvalidInputError("quilt_surface: the base mesh has garbage (call collect_garbage)");
  if (m.number_of_faces() == 0) throw InvalidInputError("quilt_surface: the base mesh has no face");
  Base b;
  b.pts.resize(m.number_of_vertices());
  for (VertexIndex v : m.vertices()) {
    const Point3& p = m.point(v);
    b.pts[v.idx()] = {p.x(), p.y(), p.z()};
  }
  const std::size_t nf = m.number_of_faces();
  b.faces.resize(nf);
  b.edge_nb.assign(nf, {-1, -1, -1});
  for (FaceIndex f : m.faces()) {
    int k = 0;
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
      if (k == 3) throw InvalidInputError("quilt_surface: base face " + std::to_string(f.idx()) + " is not a triangle");
      b.faces[f.idx()][k] = static_cast<int>(m.target(h).idx());
      // edge (v_k, v_k+1) is the next halfedge's
      const HalfedgeIndex hn = m.next(h);
      const FaceIndex g = m.face(m.opposite(hn));
      b.edge_nb[f.idx()][k] = g == Mesh::null_face() ? -1 : static_cast<int>(g.idx());
      ++k;
    }
    if (k != 3) throw InvalidInputError("quilt_surface: base face " + std::to_string(f.idx()) + " is not a triangle");
  }
  b.centroid.resize(nf);
  b.normal.resize(nf);
  b.area.resize(nf);
  std::vector<std::vector<int>> vf(b.pts.size());
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = b.faces[f];
    const P3 &a = b.pts[t[0]], &c1 = b.pts[t[1]], &c2 = b.pts[t[2]];
    b.centroid[f] = {(a[0] + c1[0] + c2[0]) / 3, (a[1] + c1[1] + c2[1]) / 3, (a[2] + c1[2] + c2[2]) / 3};
    P3 n = cross3(sub3(c1, a), sub3(c2, a));
    const double l = norm3(n);
    b.area[f] = 0.5 * l;
    b.normal[f] = l > 0 ? P3{n[0] / l, n[1] / l, n[2] / l} : P3{0, 0, 0};
    for (int v : t) vf[v].push_back(static_cast<int>(f));
  }
  b.vertex_nb.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    auto& nb = b.vertex_nb[f];
    for (int v : b.faces[f])
      for (int g : vf[v])
        if (g != static_cast<int>(f)) nb.push_back(g);
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
  }
  return b;
}

// Disc-preserving breadth-first growth (rule of base_mesh_atlas.h).
std::vector<int> grow_patch(const Base& b, int seed, double radius, double cos_max, int max_faces,
                            std::vector<int>& stamp, int stamp_id, std::vector<int>& vstamp) {
  std::vector<int> patch{seed};
  stamp[seed] = stamp_id;
  for (int v : b.faces[seed]) vstamp[v] = stamp_id;
  std::deque<int> q;
  for (int g : b.edge_nb[seed])
    if (g >= 0) q.push_back(g);
  const P3& c0 = b.centroid[seed];
  const P3& n0 = b.normal[seed];
  const double r2 = radius * radius;
  while (!q.empty() && static_cast<int>(patch.size()) < max_faces) {
    const int f = q.front();
    q.pop_front();
    if (stamp[f] == stamp_id) continue;
    const P3 d = sub3(b.centroid[f], c0);
    if (dot3(d, d) > r2 || dot3(b.normal[f], n0) < cos_max) continue;
    int shared = 0, apex = -1;
    for (int k = 0; k < 3; ++k) {
      const int g = b.edge_nb[f][k];
      if (g >= 0 && stamp[g] == stamp_id) {
        ++shared;
        apex = b.faces[f][(k + 2) % 3];  // vertex opposite edge (v_k, v_k+1)
      }
    }
    if (!(shared == 2 || (shared == 1 && vstamp[apex] != stamp_id))) continue;
    stamp[f] = stamp_id;
    patch.push_back(f);
    for (int v : b.faces[f]) vstamp[v] = stamp_id;
    for (int g : b.edge_nb[f])
      if (g >= 0 && stamp[g] != stamp_id) q.push_back(g);
  }
  return patch;
}

struct Flat {
  std::vector<int> faces;
  std::unordered_map<int, int> local;  // base vertex -> flat vertex
  std::vector<V2> uv;                  // per flat vertex (mesh units)
  double max_distortion = 0;
};

// LSCM of the patch, oriented and scaled to the 3D area.
bool flatten_patch(const Base& b, const std::vector<int>& faces, Flat& out, std::string& err) {
  out.faces = faces;
  out.local.clear();
  Mesh sub;
  std::vector<int> verts;
  for (int f : faces)
    for (int v : b.faces[f])
      if (out.local.emplace(v, static_cast<int>(verts.size())).second) {
        verts.push_back(v);
        sub.add_vertex(Point3(b.pts[v][0], b.pts[v][1], b.pts[v][2]));
      }
  double a3 = 0;
  for (int f : faces) {
    const auto& t = b.faces[f];
    if (sub.add_face(VertexIndex(static_cast<Mesh::size_type>(out.local[t[0]])), VertexIndex(static_cast<Mesh::size_type>(out.local[t[1]])),
                     VertexIndex(static_cast<Mesh::size_type>(out.local[t[2]]))) ==
        Mesh::null_face()) {
      err = "patch is not manifold";
      return false;
    }
    a3 += b.area[f];
  }
  std::vector<HalfedgeIndex> borders;
  PMP::extract_boundary_cycles(sub, std::back_inserter(borders));
  if (borders.size() != 1) {
    err = "patch has " + std::to_string(borders.size()) + " border loops";
    return false;
  }
  auto uvmap = sub.add_property_map<VertexIndex, Point2>("v:patch_uv", Point2(0, 0)).first;
  const SMP::Error_code code = SMP::parameterize(sub, SMP::LSCM_parameterizer_3<Mesh>(), borders.front(), uvmap);
  if (code != SMP::OK) {
    err = std::string("LSCM failed: ") + SMP::get_error_message(code);
    return false;
  }
  out.uv.resize(verts.size());
  for (VertexIndex v : sub.vertices()) {
    const Point2& p = uvmap[v];
    if (!std::isfinite(p.x()) || !std::isfinite(p.y())) {
      err = "LSCM gave a non-finite uv";
      return false;
    }
    out.uv[v.idx()] = {p.x(), p.y()};
  }
  double auv = 0;
  for (int f : faces) {
    const auto& t = b.faces[f];
    auv += area2(out.uv[out.local[t[0]]], out.uv[out.local[t[1]]], out.uv[out.local[t[2]]]);
  }
  if (!(std::abs(auv) > 0)) {
    err = "LSCM gave a zero-area patch";
    return false;
  }
  if (auv < 0)
    for (auto& p : out.uv) p[0] = -p[0];
  const double s = std::sqrt(a3 / std::abs(auv));
  for (auto& p : out.uv) p = {p[0] * s, p[1] * s};
  out.max_distortion = 1;
  for (int f : faces) {
    const auto& t = b.faces[f];
    const double a = area2(out.uv[out.local[t[0]]], out.uv[out.local[t[1]]], out.uv[out.local[t[2]]]);
    const double r = a > 0 && b.area[f] > 0 ? std::max(a / b.area[f], b.area[f] / a) : std::numeric_limits<double>::infinity();
    out.max_distortion = std::max(out.max_distortion, r);
  }
  return true;
}

// Point location over the frame triangles of a patch.
class PatchLocator {
 public:
  PatchLocator(std::vector<std::array<V2, 3>> tris, double cell) : tris_(std::move(tris)) {
    lo_ = {1e300, 1e300};
    V2 hi{-1e300, -1e300};
    for (auto& t : tris_)
      for (auto& p : t) lo_ = {std::min(lo_[0], p[0]), std::min(lo_[1], p[1])}, hi = {std::max(hi[0], p[0]), std::max(hi[1], p[1])};
    cell_ = cell;
    nx_ = std::max(1, static_cast<int>(std::ceil((hi[0] - lo_[0]) / cell_)) + 1);
    ny_ = std::max(1, static_cast<int>(std::ceil((hi[1] - lo_[1]) / cell_)) + 1);
    if (static_cast<double>(nx_) * ny_ > 4e6) {  // keep the bucket grid small
      const double f = std::sqrt(static_cast<double>(nx_) * ny_ / 4e6);
      cell_ *= f;
      nx_ = std::max(1, static_cast<int>(std::ceil((hi[0] - lo_[0]) / cell_)) + 1);
      ny_ = std::max(1, static_cast<int>(std::ceil((hi[1] - lo_[1]) / cell_)) + 1);
    }
    buckets_.resize(static_cast<std::size_t>(nx_) * ny_);
    for (std::size_t k = 0; k < tris_.size(); ++k) {
      double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
      for (auto& p : tris_[k]) x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]), y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
      const int i0 = cx(x0), i1 = cx(x1), j0 = cy(y0), j1 = cy(y1);
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) buckets_[static_cast<std::size_t>(j) * nx_ + i].push_back(static_cast<int>(k));
    }
  }
  // Triangle containing p (largest smallest barycentric coordinate >= -eps), or -1.
  int locate(const V2& p, std::array<double, 3>& w) const {
    const double fx = (p[0] - lo_[0]) / cell_, fy = (p[1] - lo_[1]) / cell_;
    if (!(fx >= 0 && fy >= 0 && fx < nx_ && fy < ny_)) return -1;
    const auto& bk = buckets_[static_cast<std::size_t>(fy) * nx_ + static_cast<std::size_t>(fx)];
    int best = -1;
    double best_min = -1e-9;
    for (int k : bk) {
      std::array<double, 3> b;
      if (!bary2(p, tris_[k][0], tris_[k][1], tris_[k][2], b)) continue;
      const double m = std::min({b[0], b[1], b[2]});
      if (m >= best_min) best_min = m, best = k, w = b;
    }
    return best;
  }
  // The triangle whose barycentric coordinates of p have the largest minimum (extrapolation).
  int nearest(const V2& p, std::array<double, 3>& w) const {
    const int k = locate(p, w);
    if (k >= 0) return k;
    int best = -1;
    double best_min = -1e300;
    for (std::size_t t = 0; t < tris_.size(); ++t) {
      std::array<double, 3> b;
      if (!bary2(p, tris_[t][0], tris_[t][1], tris_[t][2], b)) continue;
      const double m = std::min({b[0], b[1], b[2]});
      if (m > best_min) best_min = m, best = static_cast<int>(t), w = b;
    }
    return best;
  }

 private:
  int cx(double x) const { return std::clamp(static_cast<int>((x - lo_[0]) / cell_), 0, nx_ - 1); }
  int cy(double y) const { return std::clamp(static_cast<int>((y - lo_[1]) / cell_), 0, ny_ - 1); }
  std::vector<std::array<V2, 3>> tris_;
  V2 lo_{0, 0};
  double cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<std::vector<int>> buckets_;
};

// Gives every vertex one fan: a vertex whose triangles form several fans
// (groups connected across edges at the vertex; a pinch, which a
// Surface_mesh cannot hold) gets a copy per extra fan.
void split_pinched_vertices(std::vector<Tri>& tris, std::vector<SurfaceQuiltVertex>& loc) {
  std::vector<std::vector<int>> vt(loc.size());
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int v : tris[t]) vt[static_cast<std::size_t>(v)].push_back(static_cast<int>(t));
  const std::size_t nv = loc.size();
  for (std::size_t v = 0; v < nv; ++v) {
    const auto& ts = vt[v];
    if (ts.size() < 2) continue;
    std::vector<int> fan(ts.size(), -1);
    int nfan = 0;
    for (std::size_t i = 0; i < ts.size(); ++i) {
      if (fan[i] >= 0) continue;
      fan[i] = nfan;
      std::vector<std::size_t> stack{i};
      while (!stack.empty()) {
        const std::size_t x = stack.back();
        stack.pop_back();
        for (std::size_t j = 0; j < ts.size(); ++j) {
          if (fan[j] >= 0) continue;
          int shared = 0;  // vertices other than v in common
          for (int a : tris[static_cast<std::size_t>(ts[x])])
            for (int b2 : tris[static_cast<std::size_t>(ts[j])])
              if (a == b2 && a != static_cast<int>(v)) ++shared;
          if (shared > 0) fan[j] = nfan, stack.push_back(j);
        }
      }
      ++nfan;
    }
    for (int f = 1; f < nfan; ++f) {
      const int copy = static_cast<int>(loc.size());
      loc.push_back(loc[v]);
      for (std::size_t i = 0; i < ts.size(); ++i)
        if (fan[i] == f)
          for (int& a : tris[static_cast<std::size_t>(ts[i])])
            if (a == static_cast<int>(v)) a = copy;
    }
  }
}

struct Element {
  ElementMesh mesh;                     // triangles (points unused between steps)
  std::vector<SurfaceQuiltVertex> loc;  // per vertex
  bool alive = true;
};

P3 base_point(const Base& b, const SurfaceQuiltVertex& v) {
  const auto& t = b.faces[v.face];
  const double b0 = 1 - v.b1 - v.b2;
  P3 p;
  for (int d = 0; d < 3; ++d) p[d] = b0 * b.pts[t[0]][d] + v.b1 * b.pts[t[1]][d] + v.b2 * b.pts[t[2]][d];
  return p;
}

// Barycentric coordinates of the projection of p on the plane of face f.
std::array<double, 3> project_bary(const Base& b, int f, const P3& p) {
  const auto& t = b.faces[f];
  const P3 e1 = sub3(b.pts[t[1]], b.pts[t[0]]), e2 = sub3(b.pts[t[2]], b.pts[t[0]]), dp = sub3(p, b.pts[t[0]]);
  const double g11 = dot3(e1, e1), g12 = dot3(e1, e2), g22 = dot3(e2, e2), det = g11 * g22 - g12 * g12;
  if (!(det > 0)) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
  const double r1 = dot3(dp, e1), r2 = dot3(dp, e2);
  const double w1 = (r1 * g22 - r2 * g12) / det, w2 = (g11 * r2 - g12 * r1) / det;
  return {1 - w1 - w2, w1, w2};
}

// Moves a location with negative barycentric coordinates (a vertex beyond the
// patch it was made on) onto the face that contains it: walks across the edge
// opposite the most negative coordinate, projecting the point onto each new
// face's plane; after 64 steps the coordinates are clamped to the face.
// Returns false, leaving the location on the border face extrapolated in its
// plane, if the walk leaves the base mesh across a border edge (the caller
// removes such elements; clamping them onto the border line, as before,
// flattened every element hanging over an open end into a ribbon).
bool settle_location(const Base& b, SurfaceQuiltVertex& v) {
  constexpr double kEps = 1e-9;
  for (int it = 0; it < 64; ++it) {
    const std::array<double, 3> w{1 - v.b1 - v.b2, v.b1, v.b2};
    int j = 0;
    for (int k = 1; k < 3; ++k)
      if (w[k] < w[j]) j = k;
    if (w[j] >= -kEps) return true;
    const int g = b.edge_nb[v.face][(j + 1) % 3];
    if (g < 0) return false;
    const P3 p = base_point(b, v);
    const auto wg = project_bary(b, g, p);
    v.face = g;
    v.b1 = wg[1];
    v.b2 = wg[2];
  }
  std::array<double, 3> w{std::max(0.0, 1 - v.b1 - v.b2), std::max(0.0, v.b1), std::max(0.0, v.b2)};
  const double sum = w[0] + w[1] + w[2];
  if (sum > 0) v.b1 = w[1] / sum, v.b2 = w[2] / sum;
  else v.b1 = v.b2 = 1.0 / 3;
  return true;
}

// Trims an element (SurfaceQuiltOptions::trim_at_border): the triangles
// drop[t] (a vertex past the border of the base mesh) are removed, the rest split into connected components; a component is kept if
// its border is a set of simple loops, each no wider than cap_max (mesh
// units, measured between the vertices lifted by their height above z0
// along the face normal), its cap's edges within max_edge2 (squared, as
// max_edge_stretch measures; 0 = no limit) and the component has at least 3 triangles per
// loop vertex (more than a ring around its cut); each loop is closed by a
// fan from its first vertex (no new vertex; the cut of a tube is a small,
// nearly planar polygon), so that every piece is closed again.
void trim_element(const Base& b, const std::vector<Tri>& tris, const std::vector<SurfaceQuiltVertex>& loc,
                  const std::vector<char>& drop, double scale, double z0, double cap_max, double max_edge2,
                      std::vector<std::pair<std::vector<Tri>, std::vector<SurfaceQuiltVertex>>>& pieces) {
  ElementMesh kept;
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (!drop[t]) kept.tris.push_back(tris[t]);
  if (kept.tris.empty()) return;
  kept.points.assign(loc.size(), P3{0, 0, 0});
  std::vector<int> comp;
  const int nc = triangle_components(kept, comp);
  std::vector<std::vector<int>> by(static_cast<std::size_t>(nc));
  for (std::size_t t = 0; t < comp.size(); ++t) by[static_cast<std::size_t>(comp[t])].push_back(static_cast<int>(t));
  auto lifted = [&](const SurfaceQuiltVertex& v) {
    const P3 p = base_point(b, v);
    const P3& n = b.normal[v.face];
    const double h = (v.z - z0) * scale;
    return P3{p[0] + h * n[0], p[1] + h * n[1], p[2] + h * n[2]};
  };
  for (const auto& ts : by) {
    std::vector<int> id(loc.size(), -1);
    std::vector<Tri> pt;
    std::vector<SurfaceQuiltVertex> pl;
    for (int t : ts) {
      Tri tr = kept.tris[static_cast<std::size_t>(t)];
      for (int& v : tr) {
        if (id[static_cast<std::size_t>(v)] < 0) {
          id[static_cast<std::size_t>(v)] = static_cast<int>(pl.size());
          pl.push_back(loc[static_cast<std::size_t>(v)]);
        }
        v = id[static_cast<std::size_t>(v)];
      }
      pt.push_back(tr);
    }
    ElementMesh m;
    m.tris = pt;
    m.points.assign(pl.size(), P3{0, 0, 0});
    std::vector<std::vector<int>> loops;
    if (!boundary_loops(m, loops)) continue;
    std::size_t loop_vertices = 0;
    bool ok = true;
    for (const auto& l : loops) {
      loop_vertices += l.size();
      if (l.size() < 3 || l.size() > 256) {
        ok = false;
        break;
      }
      std::vector<P3> q;
      for (int v : l) q.push_back(lifted(pl[static_cast<std::size_t>(v)]));
      for (std::size_t i = 0; i < q.size() && ok; ++i)
        for (std::size_t j = i + 1; j < q.size(); ++j)
          if (dot3(sub3(q[i], q[j]), sub3(q[i], q[j])) > cap_max * cap_max) {
            ok = false;
            break;
          }
      // The cap's edges (from the loop's first vertex) obey the stretch limit too.
      for (std::size_t i = 2; i + 1 < l.size() && ok && max_edge2 > 0; ++i) {
        const SurfaceQuiltVertex &v0 = pl[static_cast<std::size_t>(l[0])], &v1 = pl[static_cast<std::size_t>(l[i])];
        const P3 d = sub3(base_point(b, v0), base_point(b, v1));
        const double dz = (v0.z - v1.z) * scale;
        if (dot3(d, d) + dz * dz > max_edge2) ok = false;
      }
      if (!ok) break;
    }
    if (!ok || pt.size() < 3 * loop_vertices) continue;
    // The loops follow their border edges' direction (a -> b); the caps use b -> a.
    for (const auto& l : loops)
      for (std::size_t i = 1; i + 1 < l.size(); ++i) pt.push_back({l[0], l[i + 1], l[i]});
    // A cap's diagonal may coincide with an edge of the piece (a directed
    // edge used twice: not manifold): such a piece is dropped; a vertex
    // where caps meet gets a copy per fan.
    std::set<std::pair<int, int>> directed;
    bool manifold = true;
    for (const Tri& t : pt)
      for (int k = 0; k < 3 && manifold; ++k)
        if (!directed.emplace(t[k], t[(k + 1) % 3]).second) manifold = false;
    if (!manifold) continue;
    split_pinched_vertices(pt, pl);
    pieces.emplace_back(std::move(pt), std::move(pl));
  }
}

void check_options(const SurfaceQuiltOptions& o) {
  auto bad = [](const std::string& what, double v) {
    throw InvalidInputError("quilt_surface: " + what + " (" + std::to_string(v) + ")");
  };
  if (!(o.relative_size > 0 && o.relative_size <= 10)) bad("relative_size must be in (0, 10]", o.relative_size);
  if (!(o.patch_radius > 0) || !std::isfinite(o.patch_radius)) bad("patch_radius must be > 0", o.patch_radius);
  if (!(o.max_normal_angle_deg > 0 && o.max_normal_angle_deg <= 180))
    bad("max_normal_angle_deg must be in (0, 180]", o.max_normal_angle_deg);
  if (o.max_patch_faces < 1) bad("max_patch_faces must be >= 1", o.max_patch_faces);
  if (!(o.max_area_distortion > 1)) bad("max_area_distortion must be > 1", o.max_area_distortion);
  if (!(o.cell_size >= 0) || !std::isfinite(o.cell_size)) bad("cell_size must be >= 0", o.cell_size);
  if (o.subpatch_radius < 0) bad("subpatch_radius must be >= 0", o.subpatch_radius);
  if (!(o.max_past_border >= 0 && o.max_past_border <= 1)) bad("max_past_border must be in [0, 1]", o.max_past_border);
  if (!(o.max_edge_stretch >= 0) || !std::isfinite(o.max_edge_stretch)) bad("max_edge_stretch must be >= 0", o.max_edge_stretch);
  if (!(o.max_z_growth >= 0 && o.max_z_growth <= 10)) bad("max_z_growth must be in [0, 10]", o.max_z_growth);
  if (!(o.transport_below >= 0 && o.transport_below <= 1)) bad("transport_below must be in [0, 1]", o.transport_below);
  if (!(o.rotation_max_deg >= 0 && o.rotation_max_deg <= 90)) bad("rotation_max_deg must be in [0, 90]", o.rotation_max_deg);
  if (!(o.rotation_step_deg > 0 && o.rotation_step_deg <= 90)) bad("rotation_step_deg must be in (0, 90]", o.rotation_step_deg);
  if (o.rotation_match_vertices < 1) bad("rotation_match_vertices must be >= 1", o.rotation_match_vertices);
  if (!(o.align_min_overlap >= 0 && o.align_min_overlap <= 1)) bad("align_min_overlap must be in [0, 1]", o.align_min_overlap);
  if (!(o.align_sigma > 0) || !std::isfinite(o.align_sigma)) bad("align_sigma must be > 0", o.align_sigma);
  if (!(o.aligned_rotation_max_deg >= 0 && o.aligned_rotation_max_deg <= 90))
    bad("aligned_rotation_max_deg must be in [0, 90]", o.aligned_rotation_max_deg);
  if (!(o.align_field_max_deg >= 0 && o.align_field_max_deg <= 45))
    bad("align_field_max_deg must be in [0, 45]", o.align_field_max_deg);
  if (!(o.field_smoothing >= 0) || !std::isfinite(o.field_smoothing)) bad("field_smoothing must be >= 0", o.field_smoothing);
  if (!(o.field_min_projection > 0 && o.field_min_projection <= 1))
    bad("field_min_projection must be in (0, 1]", o.field_min_projection);
  if (o.field == SurfaceQuiltOptions::Field::kUp && !(norm3(o.up) > 0) )
    throw InvalidInputError("quilt_surface: the up vector must be non-zero");
}

}  // namespace

SurfaceQuiltResult quilt_surface(const Mesh& mesh, const Swatch& swatch, SurfaceQuilt& out,
                                 const SurfaceQuiltOptions& opt) {
  check_options(opt);
  Timer timer;
  SurfaceQuiltResult res;
  const Base b = make_base(mesh);
  const int nf = static_cast<int>(b.faces.size());
  P3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const P3& p : b.pts)
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  const double diag = norm3(sub3(hi, lo));
  if (!(diag > 0)) throw InvalidInputError("quilt_surface: the base mesh has a zero-size bounding box");
  const double S = opt.relative_size * diag / std::max(swatch.length(), swatch.width());  // mesh units per swatch unit
  const double c = opt.cell_size > 0 ? opt.cell_size : std::max(swatch.length(), swatch.width()) / 10.0;
  const int sx = static_cast<int>(std::ceil(swatch.length() / c - 1e-9));
  const int sy = static_cast<int>(std::ceil(swatch.width() / c - 1e-9));
  if (std::min(sx, sy) < 3)
    throw InvalidInputError("quilt_surface: the swatch covers only " + std::to_string(sx) + "x" + std::to_string(sy) +
                            " cells of size " + std::to_string(c) + " (need >= 3)");
  const int r_full = opt.subpatch_radius > 0 ? opt.subpatch_radius : std::max(1, std::min(sx, sy) / 4);
  if (2 * r_full + 1 > std::min(sx, sy))
    throw InvalidInputError("quilt_surface: subpatch_radius " + std::to_string(r_full) + " too large for a swatch of " +
                            std::to_string(sx) + "x" + std::to_string(sy) + " cells");
  const double swatch_diag = std::hypot(swatch.length(), swatch.width()) * S;
  const double cos_max = std::cos(opt.max_normal_angle_deg * kPi / 180.0);
  P3 up = opt.up;
  {
    const double l = norm3(up);
    if (l > 0) up = {up[0] / l, up[1] / l, up[2] / l};
  }

  // The smooth guidance field (SurfaceQuiltOptions::smooth_field): a
  // 4-symmetric direction per base face interpolated from the projected up.
  std::vector<P3> field_dir;
  if (opt.field == SurfaceQuiltOptions::Field::kUp && opt.smooth_field) {
    Mesh fm = mesh;  // (interpolate_direction_field writes a property map)
    DirectionFieldOptions fo;
    fo.symmetry = 4;
    fo.smoothing = opt.field_smoothing;
    interpolate_direction_field(fm, constraints_from_constant_vector(fm, up, opt.field_min_projection), fo);
    auto dm = fm.property_map<FaceIndex, Vector3>(fo.direction_map).first;
    field_dir.resize(static_cast<std::size_t>(nf));
    for (FaceIndex f : fm.faces()) {
      const Vector3& v = dm[f];
      field_dir[f.idx()] = {v.x(), v.y(), v.z()};
    }
  }
  TriangleDistance tree(swatch.mesh);
  std::mt19937_64 rng(opt.seed);
  std::vector<Element> elements;
  std::vector<char> processed(nf, 0);
  std::vector<int> constrained(nf, 0);  // processed vertex-neighbours
  std::vector<int> stamp(nf, -1), vstamp(b.pts.size(), -1);
  std::vector<int> patch_slot(nf, -1);  // face -> index in the current patch
  // Where earlier swatch placements lie, at sub-face resolution: per base
  // face, the barycentric coordinates (b1, b2) of points of earlier footprints
  // (a lattice of spacing c/2 over each placed swatch's rectangle). A grid
  // cell of a later patch is processed iff such a point falls in it. (Marking
  // a cell processed when the base triangle under its centre is, as before,
  // mislabels every cell a footprint's rim crosses when base triangles are as
  // large as cells or larger -- on the 5K-face bunny they are about 1.5
  // cells: old elements there counted as "new", input elements there were
  // forced to stay on top of them, the cut opened no loop.)
  std::vector<std::vector<std::array<double, 2>>> cover(static_cast<std::size_t>(nf));
  // Per base face: the unit 3D tangent along which the swatch's +y ran in
  // the first placement that processed it (zero before), for the transported
  // orientation of later patches (step 4).
  std::vector<P3> face_dir(static_cast<std::size_t>(nf), P3{0, 0, 0});
  // Faces -> elements with a vertex on them (rebuilt lazily).
  int done = 0, step_id = 0;
  auto mark = [&](int f) {
    if (processed[f]) return;
    processed[f] = 1;
    ++done;
    for (int g : b.vertex_nb[f]) ++constrained[g];
  };

  while (done < nf) {
    // 1. Seed.
    int seed = -1, best = -1;
    for (int f = 0; f < nf; ++f)
      if (!processed[f] && constrained[f] > best) best = constrained[f], seed = f;
    report_progress(opt.progress, "quilt", static_cast<double>(done) / nf);
    Timer tp;
    // 2-3. Patch and flattening, shrunk for distortion.
    double R = opt.patch_radius * swatch_diag;
    Flat flat;
    bool ok = false;
    std::string err;
    for (int attempt = 0; attempt < 9; ++attempt) {
      const std::vector<int> faces =
          grow_patch(b, seed, R, cos_max, opt.max_patch_faces, stamp, step_id * 16 + attempt, vstamp);
      ok = flatten_patch(b, faces, flat, err);
      if (ok && (flat.max_distortion <= opt.max_area_distortion || faces.size() == 1)) break;
      if (faces.size() == 1) break;
      R *= 0.7;
      ++res.patches_shrunk;
    }
    if (!ok) throw SolverError("quilt_surface: cannot flatten the patch around face " + std::to_string(seed) + ": " + err);
    res.max_patch_distortion = std::max(res.max_patch_distortion, flat.max_distortion);
    const int r = std::max(1, std::min(r_full, static_cast<int>(std::lround(r_full * R / (opt.patch_radius * swatch_diag)))));
    // 4. Orientation, 5. frame (swatch units, seed centroid at the origin).
    const auto& st = b.faces[seed];
    const V2 q0 = flat.uv[flat.local[st[0]]], q1 = flat.uv[flat.local[st[1]]], q2 = flat.uv[flat.local[st[2]]];
    double rot_c = 1, rot_s = 0;
    // The guidance direction at the seed (the smooth field's, or the projected
    // up where it is long enough; zero: none) and the projected up (zero where
    // shorter than 0.2), for the drift diagnostics.
    P3 guide_at_seed{0, 0, 0}, up_at_seed{0, 0, 0};
    {
      // The tangent direction the swatch's +y should follow at the seed
      // (section 3.1: the guidance field aligns the grid). With Field::kUp it
      // is the projection of `up` on the seed's plane, but where that is
      // shorter than opt.transport_below (near the poles of the field, where
      // its direction turns fast and finally is undefined) the +y directions
      // of the earlier placements on this patch's faces are carried over
      // instead (projected on the seed's plane and averaged by area: a
      // discrete parallel transport from the neighbouring texture, our choice;
      // the paper leaves the field's singularities to the user). With
      // Field::kNone every patch takes the transported direction when there
      // is one. Without either the LSCM orientation is kept.
      const P3& n = b.normal[seed];
      P3 d{0, 0, 0};
      if (opt.field == SurfaceQuiltOptions::Field::kUp) {
        const double un = dot3(up, n);
        d = {up[0] - un * n[0], up[1] - un * n[1], up[2] - un * n[2]};
        if (norm3(d) >= 0.2) up_at_seed = d;
      }
      const double dl = norm3(d);
      const bool smooth = !field_dir.empty();
      if (smooth) {
        // The smooth field's cross at the seed; of its four directions the
        // one nearest the projected up (the swatch need not be 4-symmetric),
        // else the one nearest the earlier placements' directions.
        const P3& f0 = field_dir[static_cast<std::size_t>(seed)];
        const P3 f1 = cross3(n, f0);
        P3 ref = d;
        if (!(dl >= 0.2)) {
          ref = {0, 0, 0};
          for (int f : flat.faces) {
            const P3& g = face_dir[static_cast<std::size_t>(f)];
            for (int k = 0; k < 3; ++k) ref[k] += b.area[f] * g[k];
          }
        }
        const std::array<P3, 4> cand{f0, f1, P3{-f0[0], -f0[1], -f0[2]}, P3{-f1[0], -f1[1], -f1[2]}};
        int best_c = 0;
        for (int k = 1; k < 4; ++k)
          if (dot3(cand[k], ref) > dot3(cand[best_c], ref)) best_c = k;
        d = cand[static_cast<std::size_t>(best_c)];
        guide_at_seed = d;
      } else if (dl >= 0.2) {
        guide_at_seed = d;
      }
      const bool use_up = opt.field == SurfaceQuiltOptions::Field::kUp && (smooth || dl >= opt.transport_below);
      if (use_up && !smooth && dl <= 0.2) d = {0, 0, 0};  // (transport_below < 0.2) too short to orient by
      if (!use_up) {
        P3 t{0, 0, 0};
        for (int f : flat.faces) {
          const P3& g = face_dir[static_cast<std::size_t>(f)];
          const double gn = dot3(g, n);
          for (int k = 0; k < 3; ++k) t[k] += b.area[f] * (g[k] - gn * n[k]);
        }
        if (norm3(t) > 0) {
          d = t;
          ++res.patches_transported;
        } else if (dl <= 0.2) {
          d = {0, 0, 0};  // no neighbour yet and no usable field: LSCM orientation
        }
      }
      if (norm3(d) > 0) {
        // d = alpha e1 + beta e2 in the seed triangle, mapped to uv.
        const P3 e1 = sub3(b.pts[st[1]], b.pts[st[0]]), e2 = sub3(b.pts[st[2]], b.pts[st[0]]);
        const double g11 = dot3(e1, e1), g12 = dot3(e1, e2), g22 = dot3(e2, e2);
        const double r1 = dot3(d, e1), r2 = dot3(d, e2), det = g11 * g22 - g12 * g12;
        if (det > 0) {
          const double al = (r1 * g22 - r2 * g12) / det, be = (g11 * r2 - g12 * r1) / det;
          const V2 du{al * (q1[0] - q0[0]) + be * (q2[0] - q0[0]), al * (q1[1] - q0[1]) + be * (q2[1] - q0[1])};
          const double l = std::hypot(du[0], du[1]);
          if (l > 0) {  // rotate du onto +y
            const double ang = std::atan2(du[1], du[0]);
            const double target = kPi / 2 - ang;
            rot_c = std::cos(target), rot_s = std::sin(target);
          }
        }
      }
    }
    const V2 oc{(q0[0] + q1[0] + q2[0]) / 3, (q0[1] + q1[1] + q2[1]) / 3};
    // The flattening's scale where the match is made (SurfaceQuiltOptions::seed_scale).
    double sloc = 1;
    if (opt.seed_scale) {
      const double rad = (r + 0.5) * c * S * std::sqrt(2.0);
      double a3 = 0, a2 = 0;
      for (int f : flat.faces) {
        const P3 d = sub3(b.centroid[f], b.centroid[seed]);
        if (f != seed && dot3(d, d) > rad * rad) continue;
        const auto& t = b.faces[f];
        a3 += b.area[f];
        a2 += std::abs(area2(flat.uv[flat.local[t[0]]], flat.uv[flat.local[t[1]]], flat.uv[flat.local[t[2]]]));
      }
      if (a3 > 0 && a2 > 0) sloc = std::sqrt(a3 / a2);
    }
    res.seed_scale_min = res.steps == 0 ? sloc : std::min(res.seed_scale_min, sloc);
    res.seed_scale_max = res.steps == 0 ? sloc : std::max(res.seed_scale_max, sloc);
    for (auto& p : flat.uv) {
      const double x = (p[0] - oc[0]) * sloc / S, y = (p[1] - oc[1]) * sloc / S;
      p = {rot_c * x - rot_s * y, rot_s * x + rot_c * y};
    }
    // 4b. Orientation matched over the whole overlap (SurfaceQuiltOptions::
    // align_to_overlap): every patch face an earlier placement covered maps
    // that placement's +y (a 3D tangent) through this patch's flattening; the
    // frame is turned by the area- and distance-weighted circular mean of the
    // angles between those directions and +y, taken modulo a quarter turn
    // (mean of 4 * angle), so that the new threads run along the old ones
    // wherever the two overlap, not only at the seed.
    bool aligned = false;
    if (opt.align_to_overlap) {
      const double sigma = opt.align_sigma * std::hypot(swatch.length(), swatch.width());
      double sc = 0, ss = 0, wsum = 0, wall = 0;
      std::vector<std::pair<double, double>> angles;  // (4 * turn, weight) per covered face
      for (int f : flat.faces) {
        const auto& t = b.faces[f];
        const V2 u0 = flat.uv[flat.local[t[0]]], u1 = flat.uv[flat.local[t[1]]], u2 = flat.uv[flat.local[t[2]]];
        const double cx = (u0[0] + u1[0] + u2[0]) / 3, cy = (u0[1] + u1[1] + u2[1]) / 3;
        const double w = b.area[f] * std::exp(-(cx * cx + cy * cy) / (2 * sigma * sigma));
        wall += w;
        const P3& g = face_dir[static_cast<std::size_t>(f)];
        if (!(norm3(g) > 0)) continue;
        // g = al e1 + be e2 (least squares in the face's plane) -> uv = al (u1 - u0) + be (u2 - u0).
        const P3 e1 = sub3(b.pts[t[1]], b.pts[t[0]]), e2 = sub3(b.pts[t[2]], b.pts[t[0]]);
        const double g11 = dot3(e1, e1), g12 = dot3(e1, e2), g22 = dot3(e2, e2), det = g11 * g22 - g12 * g12;
        if (!(det > 0)) continue;
        const double r1 = dot3(g, e1), r2 = dot3(g, e2);
        const double al = (r1 * g22 - r2 * g12) / det, be = (g11 * r2 - g12 * r1) / det;
        const double dx = al * (u1[0] - u0[0]) + be * (u2[0] - u0[0]), dy = al * (u1[1] - u0[1]) + be * (u2[1] - u0[1]);
        if (!(std::hypot(dx, dy) > 0)) continue;
        const double a = 4 * (kPi / 2 - std::atan2(dy, dx));  // turn taking the old +y onto +y, times 4
        sc += w * std::cos(a);
        ss += w * std::sin(a);
        wsum += w;
        angles.emplace_back(a, w);
      }
      // Only with enough overlap near the seed, and old directions that agree
      // among themselves (resultant length of the quarter-turn mean).
      if (wall > 0 && wsum >= opt.align_min_overlap * wall && std::hypot(sc, ss) >= 0.3 * wsum) {
        double turn0 = std::atan2(ss, sc) / 4;
        // Bounded relative to the guidance field (SurfaceQuiltOptions::align_field_max_deg):
        // the frame before this turn follows the field at the seed.
        if (norm3(guide_at_seed) > 0 && opt.field == SurfaceQuiltOptions::Field::kUp) {
          const double lim = opt.align_field_max_deg * kPi / 180.0;
          if (std::abs(turn0) > lim) ++res.patches_align_bounded;
          turn0 = std::clamp(turn0, -lim, lim);
        }
        const double ca = std::cos(turn0), sa = std::sin(turn0);
        for (auto& p : flat.uv) p = {ca * p[0] - sa * p[1], sa * p[0] + ca * p[1]};
        ++res.patches_aligned;
        aligned = true;
        res.align_deg_sum += std::abs(turn0) * 180.0 / kPi;
        // What no rigid turn removes: the spread of the old directions in this flattening.
        for (const auto& [a, w] : angles) {
          const double d = std::remainder(a - 4 * turn0, 2 * kPi) / 4;
          res.align_residual_sum += w * std::abs(d) * 180.0 / kPi;
          res.align_residual_weight += w;
        }
      }
    }
    std::vector<std::array<V2, 3>> ftris(flat.faces.size());
    for (std::size_t k = 0; k < flat.faces.size(); ++k) {
      patch_slot[flat.faces[k]] = static_cast<int>(k);
      for (int j = 0; j < 3; ++j) ftris[k][j] = flat.uv[flat.local[b.faces[flat.faces[k]][j]]];
    }
    // The frame of the field's orientation (rotation 0 of step 5's search).
    const PatchLocator locator0(ftris, c);
    // Grid over the patch plus one swatch on each side, for the frame turned
    // by `ang` (radians, counter-clockwise) about the seed centroid: the
    // extent is the patch's radius (the same for every turn), the origin is a
    // cell centre, cells are located and the earlier footprints' points
    // mapped through the unturned frame.
    double ext = 0;
    for (const auto& p : flat.uv) ext = std::max(ext, std::hypot(p[0], p[1]));
    const int ilo = static_cast<int>(std::floor(-ext / c - 0.5)) - sx, ihi = static_cast<int>(std::ceil(ext / c + 0.5)) + sx;
    const int jlo = static_cast<int>(std::floor(-ext / c - 0.5)) - sy, jhi = static_cast<int>(std::ceil(ext / c + 0.5)) + sy;
    const int si = -ilo, sj = -jlo;  // the origin's cell
    auto make_grid = [&](double ang) {
      const double ca = std::cos(ang), sa = std::sin(ang);
      QuiltGrid g;
      g.cell = c;
      g.x0 = (ilo - 0.5) * c;
      g.y0 = (jlo - 0.5) * c;
      g.nx = ihi - ilo + 1;
      g.ny = jhi - jlo + 1;
      const std::size_t ncell = static_cast<std::size_t>(g.nx) * g.ny;
      g.processed.assign(ncell, 0);
      g.subpatch.assign(ncell, 0);
      // P_out: cells within r of the seed cell whose centre lies on the patch.
      for (int j = sj - r; j <= sj + r; ++j)
        for (int i = si - r; i <= si + r; ++i) {
          if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) continue;
          const double x = g.x0 + (i + 0.5) * c, y = g.y0 + (j + 0.5) * c;
          std::array<double, 3> w;
          if (locator0.locate({ca * x + sa * y, -sa * x + ca * y}, w) >= 0) g.subpatch[j * g.nx + i] = 1;
        }
      g.subpatch[sj * g.nx + si] = 1;
      // Processed cells: the earlier footprints' points on the patch, in the frame.
      for (std::size_t k = 0; k < flat.faces.size(); ++k) {
        const auto& t = ftris[k];
        for (const auto& bb : cover[static_cast<std::size_t>(flat.faces[k])]) {
          const double b0 = 1 - bb[0] - bb[1];
          const double x = b0 * t[0][0] + bb[0] * t[1][0] + bb[1] * t[2][0];
          const double y = b0 * t[0][1] + bb[0] * t[1][1] + bb[1] * t[2][1];
          const int cc = g.cell_of(ca * x - sa * y, sa * x + ca * y);
          if (cc >= 0) g.processed[static_cast<std::size_t>(cc)] = 1;
        }
      }
      return g;
    };
    res.seconds_patch += tp.seconds();

    // 6. Output elements touching the patch, in the frame.
    Timer ts;
    std::unordered_map<int, int> near_cache;
    // Index in flat.faces of the patch face whose centroid is nearest to base face f's.
    auto nearest_patch_face = [&](int f) {
      auto it = near_cache.find(f);
      if (it == near_cache.end()) {
        double bd = 1e300;
        int bk = 0;
        for (std::size_t q = 0; q < flat.faces.size(); ++q) {
          const P3 dd = sub3(b.centroid[flat.faces[q]], b.centroid[f]);
          const double d2 = dot3(dd, dd);
          if (d2 < bd) bd = d2, bk = static_cast<int>(q);
        }
        it = near_cache.emplace(f, bk).first;
      }
      return it->second;
    };
    auto frame_of_loc = [&](const SurfaceQuiltVertex& v) -> P3 {
      int k = patch_slot[v.face];
      if (k >= 0) {
        const auto& t = ftris[k];
        const double b0 = 1 - v.b1 - v.b2;
        return {b0 * t[0][0] + v.b1 * t[1][0] + v.b2 * t[2][0], b0 * t[0][1] + v.b1 * t[1][1] + v.b2 * t[2][1], v.z};
      }
      // Off the patch: project onto the plane of the patch face with the nearest centroid.
      k = nearest_patch_face(v.face);
      const int g = flat.faces[k];
      const P3 p = base_point(b, v);
      const auto& tg = b.faces[g];
      const P3 e1 = sub3(b.pts[tg[1]], b.pts[tg[0]]), e2 = sub3(b.pts[tg[2]], b.pts[tg[0]]), dp = sub3(p, b.pts[tg[0]]);
      const double g11 = dot3(e1, e1), g12 = dot3(e1, e2), g22 = dot3(e2, e2), det = g11 * g22 - g12 * g12;
      double w1 = 0, w2 = 0;
      if (det > 0) {
        const double r1 = dot3(dp, e1), r2 = dot3(dp, e2);
        w1 = (r1 * g22 - r2 * g12) / det;
        w2 = (g11 * r2 - g12 * r1) / det;
      }
      const auto& t = ftris[k];
      const double w0 = 1 - w1 - w2;
      return {w0 * t[0][0] + w1 * t[1][0] + w2 * t[2][0], w0 * t[0][1] + w1 * t[1][1] + w2 * t[2][1], v.z};
    };
    std::vector<int> ids;  // global element ids in the frame
    std::vector<ElementMesh> frame;
    std::map<P3, SurfaceQuiltVertex> keep_loc;  // frame point -> local coordinates it came from
    // Per frame element: empty inner = the whole element; else its inner
    // triangles (in the frame, numbered by `orig`) and outer ones (left in
    // local coordinates).
    struct Partial {
      std::vector<int> inner, outer, orig;
    };
    std::vector<Partial> partial;
    for (std::size_t e = 0; e < elements.size(); ++e) {
      Element& el = elements[e];
      if (!el.alive) continue;
      bool touches = false;
      for (const auto& v : el.loc)
        if (patch_slot[v.face] >= 0) {
          touches = true;
          break;
        }
      if (!touches) continue;
      // Section 3.1 converts "the part of M_out inside this patch" to the
      // frame. A vertex is expressible if it lies on the patch, or off it on a
      // face within 60 degrees of, and within 2R of, the nearest patch face
      // (farther vertices, projected onto the plane of a distant patch face,
      // would land at arbitrary frame points, possibly in the overlap, be
      // moved there and come back as long spikes). An element with vertices
      // that are not (a long stitched thread, an element across an ear)
      // enters the step with its triangles whose three vertices are
      // expressible (its inner part); the rest stays in local coordinates and
      // is joined back at the seam vertices afterwards (they lie far outside
      // the footprint: the step keeps them where they are, see below).
      // Leaving such elements out of the step entirely, as before, let the
      // new swatch be laid on top of them (duplicated threads).
      std::vector<char> ex(el.loc.size(), 1);
      bool all_ex = true;
      for (std::size_t v = 0; v < el.loc.size(); ++v) {
        const auto& lv = el.loc[v];
        if (patch_slot[lv.face] >= 0) continue;
        const int k = nearest_patch_face(lv.face);
        const int g = flat.faces[static_cast<std::size_t>(k)];
        const P3 d = sub3(base_point(b, lv), b.centroid[g]);
        if (dot3(b.normal[g], b.normal[lv.face]) < kFrameCos || dot3(d, d) > 4 * R * R) ex[v] = 0, all_ex = false;
      }
      Partial part;
      if (!all_ex) {
        ++res.elements_not_expressible;
        for (std::size_t t = 0; t < el.mesh.tris.size(); ++t) {
          const Tri& tr = el.mesh.tris[t];
          (ex[tr[0]] && ex[tr[1]] && ex[tr[2]] ? part.inner : part.outer).push_back(static_cast<int>(t));
        }
        if (part.inner.empty()) continue;
        ++res.elements_partial;
      }
      ElementMesh m;
      if (all_ex) {
        m.tris = el.mesh.tris;
        m.points.resize(el.loc.size());
        for (std::size_t v = 0; v < el.loc.size(); ++v) {
          m.points[v] = frame_of_loc(el.loc[v]);
          keep_loc.emplace(m.points[v], el.loc[v]);
        }
      } else {
        std::vector<int> sub(el.loc.size(), -1);
        for (int t : part.inner)
          for (int v : el.mesh.tris[static_cast<std::size_t>(t)]) {
            if (sub[v] < 0) {
              sub[v] = static_cast<int>(m.points.size());
              part.orig.push_back(v);
              m.points.push_back(frame_of_loc(el.loc[v]));
              keep_loc.emplace(m.points.back(), el.loc[v]);
            }
          }
        for (int t : part.inner) {
          const Tri& tr = el.mesh.tris[static_cast<std::size_t>(t)];
          m.tris.push_back({sub[tr[0]], sub[tr[1]], sub[tr[2]]});
        }
      }
      ids.push_back(static_cast<int>(e));
      partial.push_back(std::move(part));
      frame.push_back(std::move(m));
    }
    const std::size_t n_in = frame.size();
    std::vector<char> alive(n_in, 1);
    // 5b. Rotation of the placement (see SurfaceQuiltOptions::rotation_max_deg):
    // the frame turned about the seed centroid, the translation matched in
    // each turned frame (eq. 3 over at most rotation_match_vertices output
    // vertices of P_out; the field's frame searches every grid translation,
    // turned frames refine around its best one), the turn of lowest mean cost
    // per vertex kept. The turns are searched by steps away from the field's
    // direction, on the side that improves, while the cost decreases (ties:
    // the smaller turn).
    Timer tr;
    double turn = 0;
    const double turn_max = aligned ? std::min(opt.rotation_max_deg, opt.aligned_rotation_max_deg) : opt.rotation_max_deg;
    const int nturn = static_cast<int>(std::floor(turn_max / opt.rotation_step_deg + 1e-9));
    if (nturn > 0 && n_in > 0) {
      QuiltStepOptions so = opt.step;
      so.max_match_vertices = opt.rotation_match_vertices;
      std::vector<ElementMesh> turned = frame;
      QuiltPlacement at0;
      // Mean cost per vertex of turn k * step (infinity: no vertex in P_out).
      auto mean_cost = [&](int k) {
        const double ang = k * opt.rotation_step_deg * kPi / 180.0;
        const double ca = std::cos(ang), sa = std::sin(ang);
        for (std::size_t e = 0; e < n_in; ++e)
          for (std::size_t v = 0; v < frame[e].points.size(); ++v) {
            const P3& p = frame[e].points[v];
            turned[e].points[v] = {ca * p[0] - sa * p[1], sa * p[0] + ca * p[1], p[2]};
          }
        const QuiltGrid g = make_grid(ang);
        const QuiltMatch m = match_swatch_placement(swatch, tree, g, turned, alive, rng, so, k == 0 ? nullptr : &at0);
        res.stats.candidates += m.candidates;
        if (k == 0) at0 = m.placement;
        return m.vertices ? m.cost / static_cast<double>(m.vertices) : std::numeric_limits<double>::infinity();
      };
      const double c0 = mean_cost(0);
      if (std::isfinite(c0)) {
        const double cm = mean_cost(-1), cp = mean_cost(1);
        int best_k = 0;
        double best_c = c0;
        if (cm < best_c) best_c = cm, best_k = -1;
        if (cp < best_c) best_c = cp, best_k = 1;
        for (int k = 2 * best_k; best_k != 0 && std::abs(k) <= nturn; k += best_k > 0 ? 1 : -1) {
          const double ck = mean_cost(k);
          if (!(ck < best_c)) break;
          best_c = ck;
          best_k = k;
        }
        turn = best_k * opt.rotation_step_deg * kPi / 180.0;
      }
    }
    QuiltGrid grid = make_grid(turn);
    if (turn != 0) {
      ++res.patches_turned;
      const double ca = std::cos(turn), sa = std::sin(turn);
      auto rot = [&](double& x, double& y) {
        const double x2 = ca * x - sa * y;
        y = sa * x + ca * y;
        x = x2;
      };
      for (auto& p : flat.uv) rot(p[0], p[1]);
      for (auto& t : ftris)
        for (auto& p : t) rot(p[0], p[1]);
      for (ElementMesh& m : frame)
        for (P3& p : m.points) rot(p[0], p[1]);
      std::map<P3, SurfaceQuiltVertex> turned_loc;
      for (const auto& [p, l] : keep_loc) {
        P3 q = p;
        rot(q[0], q[1]);
        turned_loc.emplace(q, l);
      }
      keep_loc.swap(turned_loc);
    }
    res.turn_deg_sum += std::abs(turn) * 180.0 / kPi;
    {
      // Drift (a diagnostic): the angle between this placement's +y at the
      // seed and the guidance direction there, folded by a quarter turn.
      const auto& tk = ftris[static_cast<std::size_t>(patch_slot[seed])];
      const double m11 = tk[1][0] - tk[0][0], m12 = tk[2][0] - tk[0][0], m21 = tk[1][1] - tk[0][1], m22 = tk[2][1] - tk[0][1];
      const double det = m11 * m22 - m12 * m21;
      if (det != 0) {
        const double a1 = -m12 / det, a2 = m11 / det;  // M^-1 (0, 1)
        const P3 e1 = sub3(b.pts[st[1]], b.pts[st[0]]), e2 = sub3(b.pts[st[2]], b.pts[st[0]]);
        const P3 v{a1 * e1[0] + a2 * e2[0], a1 * e1[1] + a2 * e2[1], a1 * e1[2] + a2 * e2[2]};
        auto folded = [&](const P3& g) {
          const double cosang = std::clamp(dot3(v, g) / (norm3(v) * norm3(g)), -1.0, 1.0);
          const double a = std::fmod(std::acos(cosang) * 180.0 / kPi, 90.0);
          return std::min(a, 90.0 - a);
        };
        if (norm3(v) > 0 && norm3(guide_at_seed) > 0) {
          res.drift_deg_sum += folded(guide_at_seed);
          ++res.drift_count;
        }
        if (norm3(v) > 0 && norm3(up_at_seed) > 0) {
          res.drift_up_deg_sum += folded(up_at_seed);
          ++res.drift_up_count;
        }
      }
    }
    res.seconds_turn += tr.seconds();
    const PatchLocator locator = turn != 0 ? PatchLocator(ftris, c) : locator0;
    std::vector<ElementMesh> before = frame;
    QuiltStepStats stats;
    const QuiltPlacement placed = quilt_step(swatch, tree, grid, frame, alive, rng, opt.step, stats);
    res.stats.add(stats);

    auto to_loc = [&](const P3& p) {
      auto it = keep_loc.find(p);
      if (it != keep_loc.end()) return it->second;
      std::array<double, 3> w{1, 0, 0};
      const int k = locator.nearest({p[0], p[1]}, w);
      SurfaceQuiltVertex v;
      v.face = flat.faces[std::max(0, k)];
      v.b1 = w[1];
      v.b2 = w[2];
      v.z = p[2];
      return v;
    };
    for (std::size_t k = 0; k < frame.size(); ++k) {
      if (k < n_in) {
        Element& el = elements[ids[k]];
        if (!alive[k]) {
          // Replaced by an input element (entirely in the overlap, 2.7); a
          // partly expressed element keeps its outer part, so it stays whole.
          if (partial[k].inner.empty()) el.alive = false;
          continue;
        }
        if (frame[k].tris == before[k].tris && frame[k].points == before[k].points) continue;
        const Partial& pt = partial[k];
        if (pt.inner.empty()) {
          el.mesh.tris = frame[k].tris;
          el.loc.resize(frame[k].points.size());
          for (std::size_t v = 0; v < frame[k].points.size(); ++v) el.loc[v] = to_loc(frame[k].points[v]);
          continue;
        }
        // Join the outer triangles back: a seam vertex (an original vertex
        // of the inner part) is found in the new inner mesh at its unchanged
        // frame point (vertices outside the overlap are locked by the
        // deformations and kept by the cuts); one that was not is kept as it
        // was (a gap, counted).
        std::map<P3, int> at;
        for (std::size_t v = 0; v < frame[k].points.size(); ++v) at.emplace(frame[k].points[v], static_cast<int>(v));
        std::vector<int> now(el.loc.size(), -1);
        for (std::size_t s2 = 0; s2 < pt.orig.size(); ++s2) {
          auto it = at.find(before[k].points[s2]);
          if (it != at.end()) now[static_cast<std::size_t>(pt.orig[s2])] = it->second;
        }
        std::vector<SurfaceQuiltVertex> loc(frame[k].points.size());
        for (std::size_t v = 0; v < frame[k].points.size(); ++v) loc[v] = to_loc(frame[k].points[v]);
        const std::size_t n_inner_v = loc.size();
        std::vector<Tri> tris = frame[k].tris;
        std::vector<char> was_inner(el.loc.size(), 0);
        for (int ov : pt.orig) was_inner[static_cast<std::size_t>(ov)] = 1;
        for (int t : pt.outer) {
          Tri tr = el.mesh.tris[static_cast<std::size_t>(t)];
          for (int& v : tr) {
            if (now[static_cast<std::size_t>(v)] < 0) {
              now[static_cast<std::size_t>(v)] = static_cast<int>(loc.size());
              loc.push_back(el.loc[static_cast<std::size_t>(v)]);
            }
            v = now[static_cast<std::size_t>(v)];
          }
          tris.push_back(tr);
        }
        // The join is sound only if every inner triangle at a seam vertex
        // came back unchanged (the seam's fans are whole again); else (a
        // seam reached by the cut) the outer part becomes an element of its
        // own rather than a pinched one (counted as a broken seam).
        bool manifold = true;
        {
          std::vector<char> seam(el.loc.size(), 0);
          for (int t : pt.outer)
            for (int v : el.mesh.tris[static_cast<std::size_t>(t)])
              if (was_inner[static_cast<std::size_t>(v)]) seam[static_cast<std::size_t>(v)] = 1;
          std::set<std::array<int, 3>> have;
          auto canon = [](Tri t) {
            while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
            return std::array<int, 3>{t[0], t[1], t[2]};
          };
          for (const Tri& t : frame[k].tris) have.insert(canon(t));
          for (int t : pt.inner) {
            const Tri& tr = el.mesh.tris[static_cast<std::size_t>(t)];
            if (!seam[tr[0]] && !seam[tr[1]] && !seam[tr[2]]) continue;
            Tri m2;
            for (int q = 0; q < 3; ++q) {
              m2[q] = now[static_cast<std::size_t>(tr[q])];
              // (outer-only copies appended above have ids >= n_inner_v)
              if (m2[q] < 0 || m2[q] >= static_cast<int>(n_inner_v)) manifold = false;
            }
            if (manifold && !have.count(canon(m2))) manifold = false;
            if (!manifold) break;
          }
        }
        if (!manifold) {
          ++res.seams_broken;
          const std::size_t n_inner_t = frame[k].tris.size();
          Element rest;
          std::vector<int> again(loc.size(), -1);
          for (std::size_t t = n_inner_t; t < tris.size(); ++t) {
            Tri tr = tris[t];
            for (int& v : tr) {
              if (again[static_cast<std::size_t>(v)] < 0) {
                again[static_cast<std::size_t>(v)] = static_cast<int>(rest.loc.size());
                rest.loc.push_back(loc[static_cast<std::size_t>(v)]);
              }
              v = again[static_cast<std::size_t>(v)];
            }
            rest.mesh.tris.push_back(tr);
          }
          tris.resize(n_inner_t);
          loc.resize(n_inner_v);
          split_pinched_vertices(rest.mesh.tris, rest.loc);
          elements.push_back(std::move(rest));
        }
        split_pinched_vertices(tris, loc);
        Element& el2 = elements[static_cast<std::size_t>(ids[k])];  // (push_back may have moved it)
        el2.mesh.tris = std::move(tris);
        el2.loc = std::move(loc);
      } else {
        if (!alive[k] || frame[k].tris.empty()) continue;
        double cxs = 0, cys = 0;
        for (const P3& p : frame[k].points) cxs += p[0], cys += p[1];
        const double inv = 1.0 / static_cast<double>(frame[k].points.size());
        std::array<double, 3> w;
        if (locator.locate({cxs * inv, cys * inv}, w) < 0) {
          ++res.dropped_new;
          if (!opt.trim_new_to_patch) continue;
          // Its part on the patch is kept, the cut closed
          // (SurfaceQuiltOptions::trim_new_to_patch).
          std::vector<SurfaceQuiltVertex> locs(frame[k].points.size());
          std::vector<char> off(frame[k].points.size(), 0);
          for (std::size_t v = 0; v < frame[k].points.size(); ++v) {
            std::array<double, 3> wv;
            off[v] = locator.locate({frame[k].points[v][0], frame[k].points[v][1]}, wv) < 0;
            locs[v] = to_loc(frame[k].points[v]);
          }
          std::vector<char> drop(frame[k].tris.size(), 0);
          for (std::size_t t = 0; t < frame[k].tris.size(); ++t)
            for (int v : frame[k].tris[t]) drop[t] = drop[t] || off[static_cast<std::size_t>(v)];
          std::vector<std::pair<std::vector<Tri>, std::vector<SurfaceQuiltVertex>>> pieces;
          trim_element(b, frame[k].tris, locs, drop, S, swatch.bbox_min[2], 2 * (swatch.bbox_max[2] - swatch.bbox_min[2]) * S, 0.0, pieces);
          if (!pieces.empty()) ++res.new_trimmed;
          for (auto& [tris, pl] : pieces) {
            Element el;
            el.mesh.tris = std::move(tris);
            el.loc = std::move(pl);
            elements.push_back(std::move(el));
          }
          continue;
        }
        Element el;
        el.mesh.tris = frame[k].tris;
        el.loc.resize(frame[k].points.size());
        for (std::size_t v = 0; v < frame[k].points.size(); ++v) el.loc[v] = to_loc(frame[k].points[v]);
        elements.push_back(std::move(el));
      }
    }
    // Processed: patch faces whose frame centroid lies in the footprint, and the seed.
    const double fx0 = grid.x0 + placed.oi * c + placed.dx, fy0 = grid.y0 + placed.oj * c + placed.dy, fx1 = fx0 + sx * c, fy1 = fy0 + sy * c;
    for (std::size_t k = 0; k < flat.faces.size(); ++k) {
      const double cxp = (ftris[k][0][0] + ftris[k][1][0] + ftris[k][2][0]) / 3;
      const double cyp = (ftris[k][0][1] + ftris[k][1][1] + ftris[k][2][1]) / 3;
      if (cxp >= fx0 && cxp < fx1 && cyp >= fy0 && cyp < fy1) mark(flat.faces[k]);
    }
    mark(seed);
    // +y of this placement in 3D on every patch face it processed (first placement wins).
    for (std::size_t k = 0; k < flat.faces.size(); ++k) {
      const int f = flat.faces[k];
      P3& g = face_dir[static_cast<std::size_t>(f)];
      if (!processed[f]) continue;
      const bool old_dir = norm3(g) > 0;
      if (old_dir) {  // only faces under this footprint are compared (SurfaceQuiltResult::overlap_turn_deg)
        const double cxp = (ftris[k][0][0] + ftris[k][1][0] + ftris[k][2][0]) / 3;
        const double cyp = (ftris[k][0][1] + ftris[k][1][1] + ftris[k][2][1]) / 3;
        if (!(cxp >= fx0 && cxp < fx1 && cyp >= fy0 && cyp < fy1)) continue;
      }
      // 3D = p0 + E M^-1 (uv - q0), E = [e1 e2], M = [q1 - q0, q2 - q0]; direction of (0, 1).
      const auto& tk = ftris[k];
      const double m11 = tk[1][0] - tk[0][0], m12 = tk[2][0] - tk[0][0], m21 = tk[1][1] - tk[0][1], m22 = tk[2][1] - tk[0][1];
      const double det = m11 * m22 - m12 * m21;
      if (det == 0) continue;
      const double a1 = -m12 / det, a2 = m11 / det;  // M^-1 (0, 1)
      const auto& tri = b.faces[f];
      const P3 e1 = sub3(b.pts[tri[1]], b.pts[tri[0]]), e2 = sub3(b.pts[tri[2]], b.pts[tri[0]]);
      const P3 v{a1 * e1[0] + a2 * e2[0], a1 * e1[1] + a2 * e2[1], a1 * e1[2] + a2 * e2[2]};
      const double l = norm3(v);
      if (!(l > 0)) continue;
      if (old_dir) {
        // Angle between this placement's threads and the earlier ones, folded
        // by the weave's quarter-turn symmetry into [0, 45] degrees.
        const double cosang = std::clamp(dot3(v, g) / l, -1.0, 1.0);
        double a = std::fmod(std::acos(cosang) * 180.0 / kPi, 90.0);
        a = std::min(a, 90.0 - a);
        res.overlap_turn_sum += b.area[f] * a;
        res.overlap_area += b.area[f];
        if (a > 10) res.overlap_area_over10 += b.area[f];
      } else {
        g = {v[0] / l, v[1] / l, v[2] / l};
      }
    }
    // The footprint's points (section 2.3's processed cells, kept on the surface).
    for (double y = fy0 + 0.25 * c; y < fy1; y += 0.5 * c)
      for (double x = fx0 + 0.25 * c; x < fx1; x += 0.5 * c) {
        std::array<double, 3> w{1, 0, 0};
        const int k = locator.locate({x, y}, w);
        if (k >= 0) cover[static_cast<std::size_t>(flat.faces[static_cast<std::size_t>(k)])].push_back({w[1], w[2]});
      }
    for (int f : flat.faces) patch_slot[f] = -1;
    res.seconds_step += ts.seconds();
    ++res.steps;
    ++step_id;
  }
  // Output.
  double max_edge2 = 0;  // squared, mesh units (SurfaceQuiltOptions::max_edge_stretch)
  for (const Tri& t : swatch.mesh.tris)
    for (int k = 0; k < 3; ++k) {
      const P3 d = sub3(swatch.mesh.points[static_cast<std::size_t>(t[k])], swatch.mesh.points[static_cast<std::size_t>(t[(k + 1) % 3])]);
      max_edge2 = std::max(max_edge2, dot3(d, d));
    }
  max_edge2 *= opt.max_edge_stretch * opt.max_edge_stretch * S * S;
  out = SurfaceQuilt{};
  out.scale = S;
  out.z_min = swatch.bbox_min[2];
  out.z_max = swatch.bbox_max[2];
  const double swatch_h = swatch.bbox_max[2] - swatch.bbox_min[2];
  // Output of one element (or one trimmed piece of it): fitted into the z range, appended.
  auto emit = [&](const std::vector<Tri>& tris, std::vector<SurfaceQuiltVertex>& settled) {
    {
      // Heights past the output's z range (SurfaceQuiltOptions::max_z_growth):
      // the element is shifted in z into it, or squeezed if taller than it.
      const double lim_lo = swatch.bbox_min[2] - opt.max_z_growth * swatch_h, lim_hi = swatch.bbox_max[2] + opt.max_z_growth * swatch_h;
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (const SurfaceQuiltVertex& v : settled) lo = std::min(lo, v.z), hi = std::max(hi, v.z);
      if (lo < lim_lo || hi > lim_hi) {
        ++res.z_fitted_elements;
        res.z_fitted_vertices += settled.size();
        if (hi - lo <= lim_hi - lim_lo) {
          const double shift = lo < lim_lo ? lim_lo - lo : lim_hi - hi;
          for (SurfaceQuiltVertex& v : settled) v.z = std::clamp(v.z + shift, lim_lo, lim_hi);
        } else {
          for (SurfaceQuiltVertex& v : settled) v.z = std::clamp(lim_lo + (v.z - lo) * (lim_hi - lim_lo) / (hi - lo), lim_lo, lim_hi);
        }
      }
    }
    const int base_index = static_cast<int>(out.vertices.size());
    for (const SurfaceQuiltVertex& v : settled) out.vertices.push_back(v);
    for (const Tri& t : tris) {
      out.tris.push_back({t[0] + base_index, t[1] + base_index, t[2] + base_index});
      out.tri_element.push_back(out.elements);
    }
    ++out.elements;
  };
  // Largest diameter of a cut loop closed by trim_at_border (mesh units): two
  // swatch heights (an element is at most as thick as the swatch is high; a
  // longer loop runs along an element, not across it).
  const double cap_max = 2 * swatch_h * S;
  for (const Element& el : elements) {
    if (!el.alive || el.mesh.tris.empty()) continue;
    // Elements reaching past a border of the base mesh (issue #8; the paper
    // removes "visually-displeasing elements" in a postprocessing step,
    // section 4, and does not discuss borders): clamped onto the border they
    // were flat ribbons (the open cylinder of the tests: 7511 of 7544
    // intersecting face pairs within elements), extrapolated past it they
    // leave the shell (the concave valley test). An element with at most
    // opt.max_past_border of its vertices past a border keeps them, clamped
    // onto the border face (a short flattened tip); the others are trimmed at
    // the border (SurfaceQuiltOptions::trim_at_border) or removed.
    std::vector<SurfaceQuiltVertex> settled(el.loc.begin(), el.loc.end());
    std::vector<char> past_v(settled.size(), 0);
    std::size_t past = 0;
    for (std::size_t i = 0; i < settled.size(); ++i) {
      SurfaceQuiltVertex& v = settled[i];
      if (!settle_location(b, v)) {
        ++past;
        past_v[i] = 1;
        std::array<double, 3> w{std::max(0.0, 1 - v.b1 - v.b2), std::max(0.0, v.b1), std::max(0.0, v.b2)};
        const double sum = w[0] + w[1] + w[2];
        if (sum > 0) v.b1 = w[1] / sum, v.b2 = w[2] / sum;
      }
    }
    const bool too_far = static_cast<double>(past) > opt.max_past_border * static_cast<double>(settled.size());
    if (too_far && !opt.trim_at_border) {
      ++res.elements_past_border;
      continue;
    }
    // Stretched triangles (SurfaceQuiltOptions::max_edge_stretch): an edge
    // whose feet on the base mesh lie far apart.
    std::vector<char> drop(el.mesh.tris.size(), 0);
    bool any_stretched = false, any_past = false;
    for (std::size_t t = 0; t < el.mesh.tris.size(); ++t) {
      const Tri& tr = el.mesh.tris[t];
      if (too_far && (past_v[static_cast<std::size_t>(tr[0])] || past_v[static_cast<std::size_t>(tr[1])] || past_v[static_cast<std::size_t>(tr[2])]))
        drop[t] = 1, any_past = true;
      if (opt.max_edge_stretch > 0 && !drop[t])  // (not the triangles trimmed off anyway)
        for (int k = 0; k < 3; ++k) {
          const SurfaceQuiltVertex &v0 = settled[static_cast<std::size_t>(tr[k])], &v1 = settled[static_cast<std::size_t>(tr[(k + 1) % 3])];
          const P3 d = sub3(base_point(b, v0), base_point(b, v1));
          const double dz = (v0.z - v1.z) * S;
          if (dot3(d, d) + dz * dz > max_edge2) {
            drop[t] = 1, any_stretched = true;
            break;
          }
        }
    }
    if (!any_past && !any_stretched) {
      emit(el.mesh.tris, settled);
      continue;
    }
    if (any_stretched) {
      ++res.elements_stretched;
      continue;
    }
    // Trimmed at the border (issue #8, session 6): removing such elements
    // whole bared the open cylinder's ends along every oblique thread.
    // (Trimming the stretched ones likewise, their triangles with a stretched
    // edge removed, was tried on the 5K-face bunny: 48 trimmed instead of
    // removed, no less bare on the ears, intersecting pairs between elements
    // 83,070 -> 94,194: not kept.)
    std::vector<std::pair<std::vector<Tri>, std::vector<SurfaceQuiltVertex>>> pieces;
    trim_element(b, el.mesh.tris, settled, drop, S, swatch.bbox_min[2], cap_max, opt.max_edge_stretch > 0 ? max_edge2 : 0.0, pieces);
    if (pieces.empty()) {
      ++res.elements_past_border;
      continue;
    }
    ++res.elements_trimmed;
    for (auto& [tris, locs] : pieces) emit(tris, locs);
  }
  {
    // The z range (SurfaceQuiltOptions::max_z_growth): widened to the
    // vertices' heights (each element was fitted within the limits above).
    double lo = out.z_min, hi = out.z_max;
    for (const SurfaceQuiltVertex& v : out.vertices) lo = std::min(lo, v.z), hi = std::max(hi, v.z);
    res.z_grown_below = out.z_min - lo;
    res.z_grown_above = hi - out.z_max;
    out.z_min = lo;
    out.z_max = hi;
  }
  res.elements = out.elements;
  res.faces = out.tris.size();
  res.vertices = out.vertices.size();
  res.seconds = timer.seconds();
  report_progress(opt.progress, "quilt", 1.0);
  return res;
}

namespace {
std::vector<ElementMesh> quilt_elements(const SurfaceQuilt& q, const std::function<P3(const SurfaceQuiltVertex&)>& pos) {
  std::vector<ElementMesh> els(static_cast<std::size_t>(q.elements));
  std::vector<int> local(q.vertices.size(), -1);
  for (std::size_t t = 0; t < q.tris.size(); ++t) {
    ElementMesh& m = els[static_cast<std::size_t>(q.tri_element[t])];
    Tri tri;
    for (int k = 0; k < 3; ++k) {
      const int v = q.tris[t][k];
      if (local[v] < 0) {
        local[v] = static_cast<int>(m.points.size());
        m.points.push_back(pos(q.vertices[v]));
      }
      tri[k] = local[v];
    }
    m.tris.push_back(tri);
  }
  return els;
}
}  // namespace

void surface_quilt_to_texture(const Mesh& base, const SurfaceQuilt& q, Mesh& out) {
  auto [uv, found] = base.property_map<HalfedgeIndex, UV>(kCornerUV.name);
  if (!found) throw InvalidInputError("surface_quilt_to_texture: the base mesh has no kCornerUV (compute an atlas first)");
  const double dz = q.z_max - q.z_min;
  if (!(dz > 0)) throw InvalidInputError("surface_quilt_to_texture: the swatch has zero height");
  const std::size_t nf = base.number_of_faces();
  auto pos = [&](const SurfaceQuiltVertex& v) -> P3 {
    if (v.face < 0 || static_cast<std::size_t>(v.face) >= nf)
      throw InvalidInputError("surface_quilt_to_texture: face index " + std::to_string(v.face) + " out of range");
    const FaceIndex f(static_cast<Mesh::size_type>(v.face));
    UV c[3];
    int k = 0;
    for (HalfedgeIndex h : base.halfedges_around_face(base.halfedge(f))) {
      if (k < 3) c[k] = uv[h];
      ++k;
    }
    const double b0 = 1 - v.b1 - v.b2;
    return {b0 * c[0][0] + v.b1 * c[1][0] + v.b2 * c[2][0], b0 * c[0][1] + v.b1 * c[1][1] + v.b2 * c[2][1],
            (v.z - q.z_min) / dz};
  };
  mesh_from_elements(quilt_elements(q, pos), out);
}

void surface_quilt_displaced(const Mesh& base, const SurfaceQuilt& q, double height, Mesh& out) {
  const Base b = make_base(base);
  const double dz = q.z_max - q.z_min;
  if (!(dz > 0)) throw InvalidInputError("surface_quilt_displaced: the swatch has zero height");
  auto pos = [&](const SurfaceQuiltVertex& v) -> P3 {
    if (v.face < 0 || static_cast<std::size_t>(v.face) >= b.faces.size())
      throw InvalidInputError("surface_quilt_displaced: face index " + std::to_string(v.face) + " out of range");
    const P3& n = b.normal[v.face];
    const P3 p = base_point(b, v);
    const double w = (v.z - q.z_min) / dz * height;
    return {p[0] + w * n[0], p[1] + w * n[1], p[2] + w * n[2]};
  };
  mesh_from_elements(quilt_elements(q, pos), out);
}

}  // namespace surftex
