// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/surface_quilting.h"
#include "geometry/constants.h"

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
#include "geometry/disc_chart.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"
#include "geometry/timer.h"
#include "geometry/vec3.h"
#include "shell/element_clearance.h"
#include "shell/quilting/foot_grid.h"
#include "shell/triangle_distance.h"

namespace surftex {

namespace {
using V2 = std::array<double, 2>;
// Cosine of the largest angle between an off-patch vertex's face and its
// nearest patch face for the element to be expressed in the patch frame.
constexpr double kFrameCos = 0.5;

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
    P3 n = vec3::cross(vec3::sub(c1, a), vec3::sub(c2, a));
    const double l = vec3::norm(n);
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

struct Flat {
  std::vector<int> faces;
  std::unordered_map<int, int> local;  // base vertex -> flat vertex
  std::vector<V2> uv;                  // per flat vertex (mesh units, then frame units)
  double max_distortion = 0;
};

// The patch's flattening (geometry/disc_chart.h: LSCM, oriented, scaled to
// the 3D area) and its largest per-face area distortion.
bool flatten_patch(const Mesh& mesh, const Base& b, const std::vector<int>& faces, Flat& out, std::string& err) {
  DiscChartFlattening fl = flatten_disc_chart(mesh, faces);
  if (fl.status != DiscChartFlattening::Status::kOk) {
    err = fl.error;
    return false;
  }
  out.faces = faces;
  out.local.clear();
  for (std::size_t i = 0; i < fl.vertices.size(); ++i) out.local[fl.vertices[i]] = static_cast<int>(i);
  out.uv = std::move(fl.uv);
  out.max_distortion = 1;
  for (int f : out.faces) {
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
  bool compact = false;                 // is_compact_element in the frame it was last placed in
  bool finished = false;                // through finish() and unchanged since (a refill round skips it)
};

P3 base_point(const Base& b, const SurfaceQuiltVertex& v) {
  const auto& t = b.faces[v.face];
  const double b0 = 1 - v.b1 - v.b2;
  P3 p;
  for (int d = 0; d < 3; ++d) p[d] = b0 * b.pts[t[0]][d] + v.b1 * b.pts[t[1]][d] + v.b2 * b.pts[t[2]][d];
  return p;
}

// Area-weighted unit vertex normals of the base (zero at a vertex without area).
std::vector<P3> vertex_normals(const Base& b) {
  std::vector<P3> vn(b.pts.size(), P3{0, 0, 0});
  for (std::size_t f = 0; f < b.faces.size(); ++f)
    for (int v : b.faces[f])
      for (int d = 0; d < 3; ++d) vn[v][d] += b.area[f] * b.normal[f][d];
  for (P3& n : vn) {
    const double ln = vec3::norm(n);
    if (ln > 0) n = {n[0] / ln, n[1] / ln, n[2] / ln};
  }
  return vn;
}

// A quilt vertex lifted: its foot plus (z - z0) * scale along the vertex
// normals interpolated over its face, normalised.
P3 lift_point(const Base& b, const std::vector<P3>& vn, const SurfaceQuiltVertex& v, double z0, double scale) {
  const auto& t = b.faces[v.face];
  const double w[3] = {1 - v.b1 - v.b2, v.b1, v.b2};
  P3 n{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d) n[d] += w[k] * vn[t[k]][d];
  const double ln = vec3::norm(n);
  const P3 p = base_point(b, v);
  const double h = (v.z - z0) * scale / (ln > 0 ? ln : 1);
  return {p[0] + h * n[0], p[1] + h * n[1], p[2] + h * n[2]};
}

// The lowest and highest z of the locations.
std::pair<double, double> z_extent(const std::vector<SurfaceQuiltVertex>& loc) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const SurfaceQuiltVertex& v : loc) lo = std::min(lo, v.z), hi = std::max(hi, v.z);
  return {lo, hi};
}

// Barycentric coordinates of the projection of p on the plane of face f.
std::array<double, 3> project_bary(const Base& b, int f, const P3& p) {
  const auto& t = b.faces[f];
  const P3 e1 = vec3::sub(b.pts[t[1]], b.pts[t[0]]), e2 = vec3::sub(b.pts[t[2]], b.pts[t[0]]), dp = vec3::sub(p, b.pts[t[0]]);
  const double g11 = vec3::dot(e1, e1), g12 = vec3::dot(e1, e2), g22 = vec3::dot(e2, e2), det = g11 * g22 - g12 * g12;
  if (!(det > 0)) return {1.0 / 3, 1.0 / 3, 1.0 / 3};
  const double r1 = vec3::dot(dp, e1), r2 = vec3::dot(dp, e2);
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
          if (vec3::dot(vec3::sub(q[i], q[j]), vec3::sub(q[i], q[j])) > cap_max * cap_max) {
            ok = false;
            break;
          }
      // The cap's edges (from the loop's first vertex) obey the stretch limit too.
      for (std::size_t i = 2; i + 1 < l.size() && ok && max_edge2 > 0; ++i) {
        const SurfaceQuiltVertex &v0 = pl[static_cast<std::size_t>(l[0])], &v1 = pl[static_cast<std::size_t>(l[i])];
        const P3 d = vec3::sub(base_point(b, v0), base_point(b, v1));
        const double dz = (v0.z - v1.z) * scale;
        if (vec3::dot(d, d) + dz * dz > max_edge2) ok = false;
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
  if (!(o.max_thread_stretch >= 0) || !std::isfinite(o.max_thread_stretch))
    bad("max_thread_stretch must be >= 0", o.max_thread_stretch);
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
  if (o.refill_rounds < -1 || o.refill_rounds > 8) bad("refill_rounds must be in [-1, 8]", o.refill_rounds);
  if (o.lift_crossing_rings < -1 || o.lift_crossing_rings > 1)
    bad("lift_crossing_rings must be -1, 0 or 1", o.lift_crossing_rings);
  if (!(o.max_shape_ratio >= 0) || !std::isfinite(o.max_shape_ratio)) bad("max_shape_ratio must be >= 0", o.max_shape_ratio);
  if (o.scatter_attempts < 0 || o.scatter_attempts > 64) bad("scatter_attempts must be in [0, 64]", o.scatter_attempts);
  if (o.scatter_bare_samples < 1 || o.scatter_bare_samples > 4)
    bad("scatter_bare_samples must be in [1, 4]", o.scatter_bare_samples);
  if (o.scatter_thread_parts < 0 || o.scatter_thread_parts > 16)
    bad("scatter_thread_parts must be in [0, 16]", o.scatter_thread_parts);
  if (!(o.min_piece_fraction >= 0 && o.min_piece_fraction <= 1))
    bad("min_piece_fraction must be in [0, 1]", o.min_piece_fraction);
  if (!(o.blob_loop_gap >= 0) || !std::isfinite(o.blob_loop_gap))
    bad("blob_loop_gap must be >= 0", o.blob_loop_gap);
  if (!(o.scatter_max_stretch >= 1 && o.scatter_max_stretch <= 10))
    bad("scatter_max_stretch must be in [1, 10]", o.scatter_max_stretch);
  if (!(o.scatter_max_normal_angle_deg >= 1 && o.scatter_max_normal_angle_deg <= 180))
    bad("scatter_max_normal_angle_deg must be in [1, 180]", o.scatter_max_normal_angle_deg);
  if (o.scatter_swatch_elements < 0 || o.scatter_swatch_elements > 64)
    bad("scatter_swatch_elements must be in [0, 64]", o.scatter_swatch_elements);
  if (o.scatter_passes < 1 || o.scatter_passes > 16) bad("scatter_passes must be in [1, 16]", o.scatter_passes);
  if (o.scatter_alone_attempts < 1 || o.scatter_alone_attempts > 64)
    bad("scatter_alone_attempts must be in [1, 64]", o.scatter_alone_attempts);
  if (!(o.scatter_alone_max_stretch >= 1 && o.scatter_alone_max_stretch <= 10))
    bad("scatter_alone_max_stretch must be in [1, 10]", o.scatter_alone_max_stretch);
  if (!(o.scatter_skip_near_failed >= 0 && o.scatter_skip_near_failed <= 1))
    bad("scatter_skip_near_failed must be in [0, 1]", o.scatter_skip_near_failed);
  if (!(o.scatter_clearance >= 0 && o.scatter_clearance <= 1))
    bad("scatter_clearance must be in [0, 1]", o.scatter_clearance);
  if (o.field == SurfaceQuiltOptions::Field::kUp && !(vec3::norm(o.up) > 0) )
    throw InvalidInputError("quilt_surface: the up vector must be non-zero");
}

// Of four sample points of a base face (its centroid and its corner
// triangles' centroids), how many have no foot within the grid's radius: a
// quarter of the face's area each in the bare area; the face is bare (to be
// refilled) if two or more are; the scatter fill tries faces with
// scatter_bare_samples of them.
int bare_samples(const Base& b, int f, const FootGrid& feet) {
  const auto& t = b.faces[f];
  return bare_samples_of(b.pts[t[0]], b.pts[t[1]], b.pts[t[2]], feet);
}

// The largest extent of `pts` along 13 directions (the axes, the face and
// the body diagonals of a cube): the diameter within about 10%, whatever the
// points' orientation.
double spread13(const std::vector<P3>& pts) {
  static const double r2 = 1 / std::sqrt(2.0), r3 = 1 / std::sqrt(3.0);
  static const P3 dirs[13] = {{1, 0, 0},   {0, 1, 0},    {0, 0, 1},    {r2, r2, 0},  {r2, -r2, 0},  {r2, 0, r2},  {r2, 0, -r2},
                              {0, r2, r2}, {0, r2, -r2}, {r3, r3, r3}, {r3, r3, -r3}, {r3, -r3, r3}, {-r3, r3, r3}};
  double best = 0;
  for (const P3& d : dirs) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const P3& q : pts) {
      const double t = vec3::dot(q, d);
      lo = std::min(lo, t), hi = std::max(hi, t);
    }
    if (hi > lo) best = std::max(best, hi - lo);
  }
  return best;
}

// `m` moved so that the mean of its vertices' xy is the origin (z kept).
void centre_xy(ElementMesh& m) {
  double cx = 0, cy = 0;
  for (const P3& q : m.points) cx += q[0], cy += q[1];
  cx /= static_cast<double>(m.points.size());
  cy /= static_cast<double>(m.points.size());
  for (P3& q : m.points) q[0] -= cx, q[1] -= cy;
}

// One surface patch of the loop (steps 2-5 of the header).
struct Patch {
  int seed = -1;
  double R = 0;  // growth radius (mesh units)
  int r = 1;     // P_out half-size (cells)
  Flat flat;     // uv in frame units after orient()
  std::vector<std::array<V2, 3>> ftris;  // frame triangle per patch face
  P3 guide_at_seed{0, 0, 0}, up_at_seed{0, 0, 0};
  bool aligned = false;
  double turn = 0;
  int ilo = 0, ihi = 0, jlo = 0, jhi = 0;  // grid extent (cells)
};

// Output elements touching a patch, expressed in its frame (step 6).
struct FrameElements {
  // Per frame element: empty inner = the whole element; else its inner
  // triangles (in the frame, numbered by `orig`) and outer ones (left in
  // local coordinates).
  struct Partial {
    std::vector<int> inner, outer, orig;
  };
  std::vector<int> ids;  // global element ids
  std::vector<ElementMesh> mesh;
  std::map<P3, SurfaceQuiltVertex> keep_loc;  // frame point -> local coordinates it came from
  std::vector<Partial> partial;
};

// Whether the bounding boxes of two swatch elements overlap: rings that
// interlink (chain mail) or threads that interweave reach into each other's
// box; separate rings and pebbles do not.
bool element_boxes_overlap(const Swatch& sw) {
  const auto& els = sw.elements;
  for (std::size_t i = 0; i < els.size(); ++i)
    for (std::size_t j = i + 1; j < els.size(); ++j) {
      bool meet = true;
      for (int d = 0; d < 3; ++d)
        meet = meet && els[i].bbox_min[d] < els[j].bbox_max[d] && els[j].bbox_min[d] < els[i].bbox_max[d];
      if (meet) return true;
    }
  return false;
}

// The staged driver of quilt_surface (see the header): find_seed,
// grow_and_flatten, orient, align, express, search_turn, merge, and, after
// the loop, finish (settle, trim at borders and stretch bound, resolve
// crossings), refill (bare faces quilted again) and emit.
class SurfaceQuilter {
 public:
  SurfaceQuilter(const Mesh& mesh, const Swatch& swatch, const SurfaceQuiltOptions& opt);
  SurfaceQuiltResult run(SurfaceQuilt& out);

  // Stages (public for the tests through quilt_surface's results only; see the header).
  int find_seed() const;
  void grow_and_flatten(int seed, Patch& p, double radius, double cos_max);
  void orient(Patch& p);
  void align(Patch& p);
  void frame_triangles(Patch& p);
  FrameElements express(const Patch& p);
  double search_turn(const Patch& p, const FrameElements& fe, const PatchLocator& loc0);
  void apply_turn(Patch& p, FrameElements& fe, double turn);
  void merge(Patch& p, FrameElements& fe, QuiltGrid& grid, const PatchLocator& loc);
  void quilt_unprocessed();
  void finish();
  std::size_t refill();
  void scatter_into_bare();
  void quilt_and_refill();
  void scatter_whole_elements();
  void remove_broken_elements();
  void emit(SurfaceQuilt& out);

 private:
  QuiltGrid make_grid(const Patch& p, double ang, const PatchLocator& loc0) const;
  P3 frame_point(const Patch& p, const SurfaceQuiltVertex& v, std::unordered_map<int, int>& near) const;
  int nearest_patch_face(const Patch& p, int f, std::unordered_map<int, int>& cache) const;
  void write_back_old(std::size_t k, FrameElements& fe, const std::vector<ElementMesh>& before,
                      const std::vector<char>& alive, const std::function<SurfaceQuiltVertex(const P3&)>& to_loc);
  void add_new(const ElementMesh& m, const PatchLocator& loc, const Patch& p,
               const std::function<SurfaceQuiltVertex(const P3&)>& to_loc);
  void mark_processed(const Patch& p, const QuiltGrid& grid, const QuiltPlacement& placed, const PatchLocator& loc);
  void mark(int f);
  void drift(const Patch& p);
  P3 lifted(const SurfaceQuiltVertex& v) const;
  ElementMesh lifted_mesh(const Element& el) const;
  FootGrid element_feet(bool without_fragments = false) const;
  bool place_scatter_element(const Patch& p, const PatchLocator& loc, const ElementMesh& tpl, int quarter, const V2& offset,
                             ElementCollider& coll, Element& el);
  void fit_z(Element& el);
  std::vector<double> z_lifts(const Element& el) const;
  void settle_and_trim(std::size_t from);
  void resolve_crossings_lifted();
  bool lift_clear(Element& el, int i, ElementCollider& coll, std::vector<char>& dead);
  void remove_misshapen();
  std::vector<char> bare_faces(bool without_fragments = false) const;  // bare_samples per face
  bool is_fragment(const Element& el) const;
  double bare_area_fraction(const std::vector<char>& bare) const;

  const Mesh& mesh_;
  const Swatch& swatch_;
  const SurfaceQuiltOptions& opt_;
  Base b_;
  int nf_ = 0;
  double S_ = 0, c_ = 0, swatch_diag_ = 0, cos_max_ = 0, swatch_h_ = 0, scatter_cos_max_ = 0;
  int sx_ = 0, sy_ = 0, r_full_ = 0;
  P3 up_{0, 1, 0};
  std::vector<P3> field_dir_;
  std::vector<P3> vertex_normal_;
  TriangleDistance tree_;
  std::mt19937_64 rng_;
  std::vector<Element> elements_;
  std::vector<char> processed_;
  std::string progress_stage_ = "quilt";  // the stage quilt_unprocessed reports, from progress_from_ faces done
  int progress_from_ = 0;
  std::vector<int> constrained_;
  DiscGrowthState growth_;
  std::vector<int> patch_slot_;
  // Where earlier swatch placements lie, at sub-face resolution: per base
  // face, the barycentric coordinates (b1, b2) of points of earlier
  // footprints (a lattice of spacing c/2 over each placed swatch's
  // rectangle). A grid cell of a later patch is processed iff such a point
  // falls in it. (Marking a cell processed when the base triangle under its
  // centre is, as before, mislabels every cell a footprint's rim crosses when
  // base triangles are as large as cells or larger.)
  std::vector<std::vector<std::array<double, 2>>> cover_;
  // Per base face: the unit 3D tangent along which the swatch's +y ran in the
  // first placement that processed it (zero before), for the transported
  // orientation and the alignment of later patches (step 4).
  std::vector<P3> face_dir_;
  int done_ = 0;
  bool refilling_ = false;
  double stretch_bound2_ = 0;  // squared (mesh units); 0 = none (settle_and_trim)
  double thread_bound2_ = 0;   // the same for threads (max_thread_stretch)
  std::vector<ElementMesh> compact_;  // compact_swatch_elements: what the scatter places
  double compact_spread_ = 0;  // the largest compact swatch element's spread13 (swatch units; 0 = none)
  bool lift_rings_ = false;    // lift_crossing_rings, resolved
  std::vector<ElementMesh> thread_pieces_;  // the scatter fill's templates without compact elements
  bool all_compact_ = false;   // every swatch element is compact (so must every output element be)
  bool scatter_only_ = false;  // few compact elements: placed by the scatter fill alone
  double scatter_clearance_ = 0;  // the scatter's gap to elements already placed (mesh units)
  int ring_handles_ = 0;       // the fewest handles of a compact swatch element (rings: 1)
  QuiltStepOptions merge_step_;  // opt_.step, with blob_loop_gap for a swatch of pebbles
  std::size_t fragment_faces_ = 0;  // elements with fewer faces are fragments (constructor)
  SurfaceQuiltResult res_;
};

SurfaceQuilter::SurfaceQuilter(const Mesh& mesh, const Swatch& swatch, const SurfaceQuiltOptions& opt)
    : mesh_(mesh), swatch_(swatch), opt_(opt), b_(make_base(mesh)), tree_(swatch.mesh), rng_(opt.seed), growth_(mesh) {
  check_options(opt);
  // The matching (2.4) asks the swatch's closest points for every vertex of
  // every candidate placement: cell lists answer most without a tree walk.
  tree_.build_cell_lists(0.5 * swatch.mean_edge_length, std::size_t(1) << 19);
  nf_ = static_cast<int>(b_.faces.size());
  S_ = surface_quilt_scale(mesh, swatch, opt.relative_size);  // relative_size > 0 (check_options)
  if (!(S_ > 0)) throw InvalidInputError("quilt_surface: the base mesh has a zero-size bounding box");
  c_ = opt.cell_size > 0 ? opt.cell_size : std::max(swatch.length(), swatch.width()) / 10.0;
  swatch_cells(swatch, c_, "quilt_surface", sx_, sy_);
  r_full_ = opt.subpatch_radius > 0 ? opt.subpatch_radius : std::max(1, std::min(sx_, sy_) / 4);
  if (2 * r_full_ + 1 > std::min(sx_, sy_))
    throw InvalidInputError("quilt_surface: subpatch_radius " + std::to_string(r_full_) + " too large for a swatch of " +
                            std::to_string(sx_) + "x" + std::to_string(sy_) + " cells");
  swatch_diag_ = std::hypot(swatch.length(), swatch.width()) * S_;
  swatch_h_ = swatch.bbox_max[2] - swatch.bbox_min[2];
  cos_max_ = std::cos(opt.max_normal_angle_deg * kPi / 180.0);
  scatter_cos_max_ = std::cos(opt.scatter_max_normal_angle_deg * kPi / 180.0);
  const double l = vec3::norm(opt.up);
  if (l > 0) up_ = {opt.up[0] / l, opt.up[1] / l, opt.up[2] / l};
  if (opt.field == SurfaceQuiltOptions::Field::kUp && opt.smooth_field) {
    // The smooth guidance field: a 4-symmetric direction per base face interpolated from the projected up.
    DirectionFieldOptions fo;
    fo.symmetry = 4;
    fo.smoothing = opt.field_smoothing;
    std::vector<Vector3> dirs(mesh.num_faces(), Vector3(0, 0, 0));
    interpolate_direction_field(mesh, constraints_from_constant_vector(mesh, up_, opt.field_min_projection), dirs, fo);
    field_dir_.resize(static_cast<std::size_t>(nf_));
    for (FaceIndex f : mesh.faces()) field_dir_[f.idx()] = {dirs[f.idx()].x(), dirs[f.idx()].y(), dirs[f.idx()].z()};
  }
  vertex_normal_ = vertex_normals(b_);  // for the lifted positions (finish)
  compact_ = compact_swatch_elements(swatch);
  thread_pieces_ = thread_fill_templates(swatch, opt);  // (none with compact elements)
  for (const ElementMesh& m : compact_) compact_spread_ = std::max(compact_spread_, spread13(m.points));
  all_compact_ = !compact_.empty() && compact_.size() == swatch.elements.size();
  lift_rings_ = opt.lift_crossing_rings < 0 ? !compact_.empty() && element_boxes_overlap(swatch) : opt.lift_crossing_rings > 0;
  res_.lift_crossing_rings = lift_rings_ ? 1 : 0;
  scatter_only_ = scattered_alone(swatch, opt);
  scatter_clearance_ = scatter_gap(swatch, opt) * S_;
  ring_handles_ = compact_.empty() ? 0 : std::numeric_limits<int>::max();
  int most_handles = 0;
  for (const ElementMesh& m : compact_) {
    const int g = element_genus(m.tris);
    ring_handles_ = std::min(ring_handles_, g);
    most_handles = std::max(most_handles, g);
  }
  // Fragments (pieces of cut elements, outer parts split off at a broken
  // seam) smaller than a tenth of the swatch's smallest element are no
  // elements. At least 4 faces, never more than the smallest element has (a
  // one-triangle swatch's elements stay).
  std::size_t smallest = std::numeric_limits<std::size_t>::max();
  for (const SwatchElement& e : swatch.elements) smallest = std::min(smallest, e.faces);
  fragment_faces_ = std::min(smallest, std::max<std::size_t>(4, smallest / 10));
  // A swatch of pebbles: its merges zip only close loops (blob_loop_gap).
  merge_step_ = opt.step;
  if (all_compact_ && most_handles == 0 && opt.blob_loop_gap > 0) merge_step_.merge.max_loop_gap = opt.blob_loop_gap;
  processed_.assign(nf_, 0);
  constrained_.assign(nf_, 0);
  patch_slot_.assign(nf_, -1);
  cover_.resize(static_cast<std::size_t>(nf_));
  face_dir_.assign(static_cast<std::size_t>(nf_), P3{0, 0, 0});
}

void SurfaceQuilter::mark(int f) {
  if (processed_[f]) return;
  processed_[f] = 1;
  ++done_;
  for (int g : b_.vertex_nb[f]) ++constrained_[g];
}

// 1. Seed: the unprocessed face with the most processed vertex neighbours.
int SurfaceQuilter::find_seed() const {
  int seed = -1, best = -1;
  for (int f = 0; f < nf_; ++f)
    if (!processed_[f] && constrained_[f] > best) best = constrained_[f], seed = f;
  return seed;
}

// 2-3. Surface patch (the faces within `radius` whose normals are within
// acos(cos_max) of the seed's) and its flattening, shrunk while the area
// distortion exceeds the bound.
void SurfaceQuilter::grow_and_flatten(int seed, Patch& p, double radius, double cos_max) {
  p.seed = seed;
  p.R = radius;
  bool ok = false;
  std::string err;
  const P3 c0 = b_.centroid[seed], n0 = b_.normal[seed];
  for (int attempt = 0; attempt < 9; ++attempt) {
    const double r2 = p.R * p.R;
    auto accept = [&](int f) {
      const P3 d = vec3::sub(b_.centroid[f], c0);
      return vec3::dot(d, d) <= r2 && vec3::dot(b_.normal[f], n0) >= cos_max;
    };
    const std::vector<int> faces = grow_disc_chart(mesh_, seed, accept, static_cast<std::size_t>(opt_.max_patch_faces), growth_);
    ok = flatten_patch(mesh_, b_, faces, p.flat, err);
    if (ok && (p.flat.max_distortion <= opt_.max_area_distortion || faces.size() == 1)) break;
    if (faces.size() == 1) break;
    p.R *= 0.7;
    ++res_.patches_shrunk;
  }
  if (!ok) throw SolverError("quilt_surface: cannot flatten the patch around face " + std::to_string(seed) + ": " + err);
  res_.max_patch_distortion = std::max(res_.max_patch_distortion, p.flat.max_distortion);
  p.r = std::max(1, std::min(r_full_, static_cast<int>(std::lround(r_full_ * p.R / (opt_.patch_radius * swatch_diag_)))));
}

// 4. Orientation (section 3.1's guidance field) and 5. frame: the patch's uv
// turned so that the field's direction at the seed runs along +y, the seed
// centroid moved to the origin, divided by the swatch scale.
void SurfaceQuilter::orient(Patch& p) {
  Flat& flat = p.flat;
  const int seed = p.seed;
  const auto& st = b_.faces[seed];
  const V2 q0 = flat.uv[flat.local[st[0]]], q1 = flat.uv[flat.local[st[1]]], q2 = flat.uv[flat.local[st[2]]];
  double rot_c = 1, rot_s = 0;
  // The tangent direction the swatch's +y should follow at the seed. With
  // Field::kUp: the projection of `up` on the seed's plane, but where that is
  // shorter than opt.transport_below (near the field's poles) the +y
  // directions of the earlier placements on this patch's faces, projected on
  // the seed's plane and averaged by area (a discrete parallel transport, our
  // choice); with Field::kNone the transported direction where there is one;
  // else the LSCM orientation. With the smooth field: of its cross at the
  // seed, the direction nearest the projected up (else the earlier ones').
  const P3& n = b_.normal[seed];
  P3 d{0, 0, 0};
  if (opt_.field == SurfaceQuiltOptions::Field::kUp) {
    const double un = vec3::dot(up_, n);
    d = {up_[0] - un * n[0], up_[1] - un * n[1], up_[2] - un * n[2]};
    if (vec3::norm(d) >= 0.2) p.up_at_seed = d;
  }
  const double dl = vec3::norm(d);
  const bool smooth = !field_dir_.empty();
  if (smooth) {
    const P3& f0 = field_dir_[static_cast<std::size_t>(seed)];
    const P3 f1 = vec3::cross(n, f0);
    P3 ref = d;
    if (!(dl >= 0.2)) {
      ref = {0, 0, 0};
      for (int f : flat.faces)
        for (int k = 0; k < 3; ++k) ref[k] += b_.area[f] * face_dir_[static_cast<std::size_t>(f)][k];
    }
    const std::array<P3, 4> cand{f0, f1, P3{-f0[0], -f0[1], -f0[2]}, P3{-f1[0], -f1[1], -f1[2]}};
    int best_c = 0;
    for (int k = 1; k < 4; ++k)
      if (vec3::dot(cand[k], ref) > vec3::dot(cand[best_c], ref)) best_c = k;
    d = cand[static_cast<std::size_t>(best_c)];
    p.guide_at_seed = d;
  } else if (dl >= 0.2) {
    p.guide_at_seed = d;
  }
  const bool use_up = opt_.field == SurfaceQuiltOptions::Field::kUp && (smooth || dl >= opt_.transport_below);
  if (use_up && !smooth && dl <= 0.2) d = {0, 0, 0};  // (transport_below < 0.2) too short to orient by
  if (!use_up) {
    P3 t{0, 0, 0};
    for (int f : flat.faces) {
      const P3& g = face_dir_[static_cast<std::size_t>(f)];
      const double gn = vec3::dot(g, n);
      for (int k = 0; k < 3; ++k) t[k] += b_.area[f] * (g[k] - gn * n[k]);
    }
    if (vec3::norm(t) > 0) {
      d = t;
      ++res_.patches_transported;
    } else if (dl <= 0.2) {
      d = {0, 0, 0};  // no neighbour yet and no usable field: LSCM orientation
    }
  }
  if (vec3::norm(d) > 0) {
    // d = alpha e1 + beta e2 in the seed triangle, mapped to uv, turned onto +y.
    const P3 e1 = vec3::sub(b_.pts[st[1]], b_.pts[st[0]]), e2 = vec3::sub(b_.pts[st[2]], b_.pts[st[0]]);
    const double g11 = vec3::dot(e1, e1), g12 = vec3::dot(e1, e2), g22 = vec3::dot(e2, e2);
    const double r1 = vec3::dot(d, e1), r2 = vec3::dot(d, e2), det = g11 * g22 - g12 * g12;
    if (det > 0) {
      const double al = (r1 * g22 - r2 * g12) / det, be = (g11 * r2 - g12 * r1) / det;
      const V2 du{al * (q1[0] - q0[0]) + be * (q2[0] - q0[0]), al * (q1[1] - q0[1]) + be * (q2[1] - q0[1])};
      if (std::hypot(du[0], du[1]) > 0) {
        const double target = kPi / 2 - std::atan2(du[1], du[0]);
        rot_c = std::cos(target), rot_s = std::sin(target);
      }
    }
  }
  const V2 oc{(q0[0] + q1[0] + q2[0]) / 3, (q0[1] + q1[1] + q2[1]) / 3};
  // The flattening's scale where the match is made (SurfaceQuiltOptions::seed_scale).
  double sloc = 1;
  if (opt_.seed_scale) {
    const double rad = (p.r + 0.5) * c_ * S_ * std::sqrt(2.0);
    double a3 = 0, a2 = 0;
    for (int f : flat.faces) {
      const P3 dd = vec3::sub(b_.centroid[f], b_.centroid[seed]);
      if (f != seed && vec3::dot(dd, dd) > rad * rad) continue;
      const auto& t = b_.faces[f];
      a3 += b_.area[f];
      a2 += std::abs(area2(flat.uv[flat.local[t[0]]], flat.uv[flat.local[t[1]]], flat.uv[flat.local[t[2]]]));
    }
    if (a3 > 0 && a2 > 0) sloc = std::sqrt(a3 / a2);
  }
  res_.seed_scale_min = res_.steps == 0 ? sloc : std::min(res_.seed_scale_min, sloc);
  res_.seed_scale_max = res_.steps == 0 ? sloc : std::max(res_.seed_scale_max, sloc);
  for (auto& q : flat.uv) {
    const double x = (q[0] - oc[0]) * sloc / S_, y = (q[1] - oc[1]) * sloc / S_;
    q = {rot_c * x - rot_s * y, rot_s * x + rot_c * y};
  }
}

// 4b. Orientation matched over the whole overlap (SurfaceQuiltOptions::
// align_to_overlap): every patch face an earlier placement covered maps that
// placement's +y through this patch's flattening; the frame is turned by the
// area- and distance-weighted circular mean (mod a quarter turn) of the
// angles between those directions and +y. Then the frame triangles, the
// patch slots and the grid extent are set.
void SurfaceQuilter::align(Patch& p) {
  Flat& flat = p.flat;
  if (opt_.align_to_overlap) {
    const double sigma = opt_.align_sigma * std::hypot(swatch_.length(), swatch_.width());
    double sc = 0, ss = 0, wsum = 0, wall = 0;
    std::vector<std::pair<double, double>> angles;  // (4 * turn, weight) per covered face
    for (int f : flat.faces) {
      const auto& t = b_.faces[f];
      const V2 u0 = flat.uv[flat.local[t[0]]], u1 = flat.uv[flat.local[t[1]]], u2 = flat.uv[flat.local[t[2]]];
      const double cx = (u0[0] + u1[0] + u2[0]) / 3, cy = (u0[1] + u1[1] + u2[1]) / 3;
      const double w = b_.area[f] * std::exp(-(cx * cx + cy * cy) / (2 * sigma * sigma));
      wall += w;
      const P3& g = face_dir_[static_cast<std::size_t>(f)];
      if (!(vec3::norm(g) > 0)) continue;
      // g = al e1 + be e2 (least squares in the face's plane) -> uv = al (u1 - u0) + be (u2 - u0).
      const P3 e1 = vec3::sub(b_.pts[t[1]], b_.pts[t[0]]), e2 = vec3::sub(b_.pts[t[2]], b_.pts[t[0]]);
      const double g11 = vec3::dot(e1, e1), g12 = vec3::dot(e1, e2), g22 = vec3::dot(e2, e2), det = g11 * g22 - g12 * g12;
      if (!(det > 0)) continue;
      const double r1 = vec3::dot(g, e1), r2 = vec3::dot(g, e2);
      const double al = (r1 * g22 - r2 * g12) / det, be = (g11 * r2 - g12 * r1) / det;
      const double dx = al * (u1[0] - u0[0]) + be * (u2[0] - u0[0]), dy = al * (u1[1] - u0[1]) + be * (u2[1] - u0[1]);
      if (!(std::hypot(dx, dy) > 0)) continue;
      const double a = 4 * (kPi / 2 - std::atan2(dy, dx));  // turn taking the old +y onto +y, times 4
      sc += w * std::cos(a);
      ss += w * std::sin(a);
      wsum += w;
      angles.emplace_back(a, w);
    }
    // Only with enough overlap near the seed, and old directions that agree.
    if (wall > 0 && wsum >= opt_.align_min_overlap * wall && std::hypot(sc, ss) >= 0.3 * wsum) {
      double turn0 = std::atan2(ss, sc) / 4;
      if (vec3::norm(p.guide_at_seed) > 0 && opt_.field == SurfaceQuiltOptions::Field::kUp) {
        const double lim = opt_.align_field_max_deg * kPi / 180.0;  // bounded relative to the field
        if (std::abs(turn0) > lim) ++res_.patches_align_bounded;
        turn0 = std::clamp(turn0, -lim, lim);
      }
      const double ca = std::cos(turn0), sa = std::sin(turn0);
      for (auto& q : flat.uv) q = {ca * q[0] - sa * q[1], sa * q[0] + ca * q[1]};
      ++res_.patches_aligned;
      p.aligned = true;
      res_.align_deg_sum += std::abs(turn0) * 180.0 / kPi;
      for (const auto& [a, w] : angles) {  // what no rigid turn removes
        const double dd = std::remainder(a - 4 * turn0, 2 * kPi) / 4;
        res_.align_residual_sum += w * std::abs(dd) * 180.0 / kPi;
        res_.align_residual_weight += w;
      }
    }
  }
  frame_triangles(p);
}

// The frame triangles of the patch, its faces' slots, and the grid extent:
// the patch plus one swatch on each side (the same for every turn).
void SurfaceQuilter::frame_triangles(Patch& p) {
  Flat& flat = p.flat;
  p.ftris.resize(flat.faces.size());
  for (std::size_t k = 0; k < flat.faces.size(); ++k) {
    patch_slot_[flat.faces[k]] = static_cast<int>(k);
    for (int j = 0; j < 3; ++j) p.ftris[k][j] = flat.uv[flat.local[b_.faces[flat.faces[k]][j]]];
  }
  double ext = 0;
  for (const auto& q : flat.uv) ext = std::max(ext, std::hypot(q[0], q[1]));
  p.ilo = static_cast<int>(std::floor(-ext / c_ - 0.5)) - sx_, p.ihi = static_cast<int>(std::ceil(ext / c_ + 0.5)) + sx_;
  p.jlo = static_cast<int>(std::floor(-ext / c_ - 0.5)) - sy_, p.jhi = static_cast<int>(std::ceil(ext / c_ + 0.5)) + sy_;
}

// The grid of step 5 for the frame turned by `ang` (radians) about the seed
// centroid: the origin a cell centre, P_out the cells within r of the seed
// cell whose centre lies on the patch, processed cells those where earlier
// footprints' points fall (located and mapped through the unturned frame).
QuiltGrid SurfaceQuilter::make_grid(const Patch& p, double ang, const PatchLocator& loc0) const {
  const double ca = std::cos(ang), sa = std::sin(ang);
  const int si = -p.ilo, sj = -p.jlo;  // the origin's cell
  QuiltGrid g;
  g.cell = c_;
  g.x0 = (p.ilo - 0.5) * c_;
  g.y0 = (p.jlo - 0.5) * c_;
  g.nx = p.ihi - p.ilo + 1;
  g.ny = p.jhi - p.jlo + 1;
  const std::size_t ncell = static_cast<std::size_t>(g.nx) * g.ny;
  g.processed.assign(ncell, 0);
  g.subpatch.assign(ncell, 0);
  for (int j = sj - p.r; j <= sj + p.r; ++j)
    for (int i = si - p.r; i <= si + p.r; ++i) {
      if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) continue;
      const double x = g.x0 + (i + 0.5) * c_, y = g.y0 + (j + 0.5) * c_;
      std::array<double, 3> w;
      if (loc0.locate({ca * x + sa * y, -sa * x + ca * y}, w) >= 0) g.subpatch[j * g.nx + i] = 1;
    }
  g.subpatch[sj * g.nx + si] = 1;
  for (std::size_t k = 0; k < p.flat.faces.size(); ++k) {
    const auto& t = p.ftris[k];
    for (const auto& bb : cover_[static_cast<std::size_t>(p.flat.faces[k])]) {
      const double b0 = 1 - bb[0] - bb[1];
      const double x = b0 * t[0][0] + bb[0] * t[1][0] + bb[1] * t[2][0];
      const double y = b0 * t[0][1] + bb[0] * t[1][1] + bb[1] * t[2][1];
      const int cc = g.cell_of(ca * x - sa * y, sa * x + ca * y);
      if (cc >= 0) g.processed[static_cast<std::size_t>(cc)] = 1;
    }
  }
  return g;
}

// Index in p.flat.faces of the patch face whose centroid is nearest to base face f's.
int SurfaceQuilter::nearest_patch_face(const Patch& p, int f, std::unordered_map<int, int>& cache) const {
  auto it = cache.find(f);
  if (it != cache.end()) return it->second;
  double bd = 1e300;
  int bk = 0;
  for (std::size_t q = 0; q < p.flat.faces.size(); ++q) {
    const P3 dd = vec3::sub(b_.centroid[p.flat.faces[q]], b_.centroid[f]);
    const double d2 = vec3::dot(dd, dd);
    if (d2 < bd) bd = d2, bk = static_cast<int>(q);
  }
  return cache.emplace(f, bk).first->second;
}

// A location in the patch frame: through its face's frame triangle on the
// patch; off it, projected onto the plane of the nearest patch face
// (barycentric coordinates extrapolated).
P3 SurfaceQuilter::frame_point(const Patch& p, const SurfaceQuiltVertex& v, std::unordered_map<int, int>& near) const {
  int k = patch_slot_[v.face];
  if (k >= 0) {
    const auto& t = p.ftris[k];
    const double b0 = 1 - v.b1 - v.b2;
    return {b0 * t[0][0] + v.b1 * t[1][0] + v.b2 * t[2][0], b0 * t[0][1] + v.b1 * t[1][1] + v.b2 * t[2][1], v.z};
  }
  k = nearest_patch_face(p, v.face, near);
  const auto w = project_bary(b_, p.flat.faces[k], base_point(b_, v));
  const auto& t = p.ftris[k];
  return {w[0] * t[0][0] + w[1] * t[1][0] + w[2] * t[2][0], w[0] * t[0][1] + w[1] * t[1][1] + w[2] * t[2][1], v.z};
}

// 6a. The output elements with a vertex on the patch, in its frame (section
// 3.1 converts "the part of M_out inside this patch" to the frame). A vertex
// is expressible if it lies on the patch, or off it on a face within 60
// degrees of, and within 2R of, the nearest patch face (farther vertices,
// projected onto a distant patch face's plane, would land at arbitrary frame
// points and come back as long spikes). An element with vertices that are
// not (a long thread, an element across an ear) enters with its triangles
// whose three vertices are expressible; the rest stays in local coordinates
// and is joined back at the seam vertices afterwards (write_back_old).
FrameElements SurfaceQuilter::express(const Patch& p) {
  FrameElements fe;
  std::unordered_map<int, int> near;
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    Element& el = elements_[e];
    if (!el.alive) continue;
    bool touches = false;
    for (const auto& v : el.loc)
      if (patch_slot_[v.face] >= 0) {
        touches = true;
        break;
      }
    if (!touches) continue;
    std::vector<char> ex(el.loc.size(), 1);
    bool all_ex = true;
    for (std::size_t v = 0; v < el.loc.size(); ++v) {
      const auto& lv = el.loc[v];
      if (patch_slot_[lv.face] >= 0) continue;
      const int g = p.flat.faces[static_cast<std::size_t>(nearest_patch_face(p, lv.face, near))];
      const P3 d = vec3::sub(base_point(b_, lv), b_.centroid[g]);
      if (vec3::dot(b_.normal[g], b_.normal[lv.face]) < kFrameCos || vec3::dot(d, d) > 4 * p.R * p.R) ex[v] = 0, all_ex = false;
    }
    FrameElements::Partial part;
    if (!all_ex) {
      ++res_.elements_not_expressible;
      for (std::size_t t = 0; t < el.mesh.tris.size(); ++t) {
        const Tri& tr = el.mesh.tris[t];
        (ex[tr[0]] && ex[tr[1]] && ex[tr[2]] ? part.inner : part.outer).push_back(static_cast<int>(t));
      }
      if (part.inner.empty()) {
        ++res_.elements_not_expressed;
        continue;
      }
      ++res_.elements_partial;
    }
    ElementMesh m;
    if (all_ex) {
      m.tris = el.mesh.tris;
      m.points.resize(el.loc.size());
      for (std::size_t v = 0; v < el.loc.size(); ++v) {
        m.points[v] = frame_point(p, el.loc[v], near);
        fe.keep_loc.emplace(m.points[v], el.loc[v]);
      }
    } else {
      std::vector<int> sub(el.loc.size(), -1);
      for (int t : part.inner)
        for (int v : el.mesh.tris[static_cast<std::size_t>(t)])
          if (sub[v] < 0) {
            sub[v] = static_cast<int>(m.points.size());
            part.orig.push_back(v);
            m.points.push_back(frame_point(p, el.loc[v], near));
            fe.keep_loc.emplace(m.points.back(), el.loc[v]);
          }
      for (int t : part.inner) {
        const Tri& tr = el.mesh.tris[static_cast<std::size_t>(t)];
        m.tris.push_back({sub[tr[0]], sub[tr[1]], sub[tr[2]]});
      }
    }
    fe.ids.push_back(static_cast<int>(e));
    fe.partial.push_back(std::move(part));
    fe.mesh.push_back(std::move(m));
  }
  return fe;
}

// 5b. Rotation of the placement (SurfaceQuiltOptions::rotation_max_deg): the
// frame turned about the seed centroid, the translation matched in each
// turned frame (eq. 3 over at most rotation_match_vertices vertices of
// P_out; the field's frame searches every grid translation, turned frames
// refine around its best one); turns searched by steps away from the field's
// direction on the side that improves, while the mean cost per vertex
// decreases (ties: the smaller turn). Returns the turn (radians).
double SurfaceQuilter::search_turn(const Patch& p, const FrameElements& fe, const PatchLocator& loc0) {
  const double turn_max = p.aligned ? std::min(opt_.rotation_max_deg, opt_.aligned_rotation_max_deg) : opt_.rotation_max_deg;
  const int nturn = static_cast<int>(std::floor(turn_max / opt_.rotation_step_deg + 1e-9));
  const std::size_t n_in = fe.mesh.size();
  if (nturn <= 0 || n_in == 0) return 0;
  QuiltStepOptions so = opt_.step;
  so.max_match_vertices = opt_.rotation_match_vertices;
  std::vector<ElementMesh> turned = fe.mesh;
  const std::vector<char> alive(n_in, 1);
  QuiltPlacement at0;
  auto mean_cost = [&](int k) {
    const double ang = k * opt_.rotation_step_deg * kPi / 180.0;
    const double ca = std::cos(ang), sa = std::sin(ang);
    for (std::size_t e = 0; e < n_in; ++e)
      for (std::size_t v = 0; v < fe.mesh[e].points.size(); ++v) {
        const P3& q = fe.mesh[e].points[v];
        turned[e].points[v] = {ca * q[0] - sa * q[1], sa * q[0] + ca * q[1], q[2]};
      }
    const QuiltGrid g = make_grid(p, ang, loc0);
    const QuiltMatch m = match_swatch_placement(swatch_, tree_, g, turned, alive, rng_, so, k == 0 ? nullptr : &at0);
    res_.stats.candidates += m.candidates;
    if (k == 0) at0 = m.placement;
    return m.vertices ? m.cost / static_cast<double>(m.vertices) : std::numeric_limits<double>::infinity();
  };
  const double c0 = mean_cost(0);
  if (!std::isfinite(c0)) return 0;
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
  return best_k * opt_.rotation_step_deg * kPi / 180.0;
}

// Turns the frame (uv, frame triangles, expressed elements) by `turn`.
void SurfaceQuilter::apply_turn(Patch& p, FrameElements& fe, double turn) {
  p.turn = turn;
  res_.turn_deg_sum += std::abs(turn) * 180.0 / kPi;
  if (turn == 0) return;
  ++res_.patches_turned;
  const double ca = std::cos(turn), sa = std::sin(turn);
  auto rot = [&](double& x, double& y) {
    const double x2 = ca * x - sa * y;
    y = sa * x + ca * y;
    x = x2;
  };
  for (auto& q : p.flat.uv) rot(q[0], q[1]);
  for (auto& t : p.ftris)
    for (auto& q : t) rot(q[0], q[1]);
  for (ElementMesh& m : fe.mesh)
    for (P3& q : m.points) rot(q[0], q[1]);
  std::map<P3, SurfaceQuiltVertex> turned_loc;
  for (const auto& [q, l] : fe.keep_loc) {
    P3 t = q;
    rot(t[0], t[1]);
    turned_loc.emplace(t, l);
  }
  fe.keep_loc.swap(turned_loc);
}

// Drift (a diagnostic): the angle between this placement's +y at the seed
// and the guidance direction there (and the projected up), folded by a quarter turn.
void SurfaceQuilter::drift(const Patch& p) {
  const auto& st = b_.faces[p.seed];
  const auto& tk = p.ftris[static_cast<std::size_t>(patch_slot_[p.seed])];
  const double m11 = tk[1][0] - tk[0][0], m12 = tk[2][0] - tk[0][0], m21 = tk[1][1] - tk[0][1], m22 = tk[2][1] - tk[0][1];
  const double det = m11 * m22 - m12 * m21;
  if (det == 0) return;
  const double a1 = -m12 / det, a2 = m11 / det;  // M^-1 (0, 1)
  const P3 e1 = vec3::sub(b_.pts[st[1]], b_.pts[st[0]]), e2 = vec3::sub(b_.pts[st[2]], b_.pts[st[0]]);
  const P3 v{a1 * e1[0] + a2 * e2[0], a1 * e1[1] + a2 * e2[1], a1 * e1[2] + a2 * e2[2]};
  if (!(vec3::norm(v) > 0)) return;
  auto folded = [&](const P3& g) {
    const double cosang = std::clamp(vec3::dot(v, g) / (vec3::norm(v) * vec3::norm(g)), -1.0, 1.0);
    const double a = std::fmod(std::acos(cosang) * 180.0 / kPi, 90.0);
    return std::min(a, 90.0 - a);
  };
  if (vec3::norm(p.guide_at_seed) > 0) {
    res_.drift_deg_sum += folded(p.guide_at_seed);
    ++res_.drift_count;
  }
  if (vec3::norm(p.up_at_seed) > 0) {
    res_.drift_up_deg_sum += folded(p.up_at_seed);
    ++res_.drift_up_count;
  }
}

// 6b. The planar step (quilt_step.h: sections 2.4-2.7) in the frame, and its
// result expressed again in local coordinates: vertices that did not move
// keep theirs exactly; others go to the flattening's triangle containing
// their frame point (outside the patch: the one whose extrapolated
// barycentric coordinates are least negative), height = the swatch z.
void SurfaceQuilter::merge(Patch& p, FrameElements& fe, QuiltGrid& grid, const PatchLocator& loc) {
  std::vector<ElementMesh> before = fe.mesh;
  const std::size_t n_in = fe.mesh.size();
  std::vector<char> alive(n_in, 1);
  QuiltStepStats stats;
  const QuiltPlacement placed = quilt_step(swatch_, tree_, grid, fe.mesh, alive, rng_, merge_step_, stats);
  res_.stats.add(stats);
  auto to_loc = [&](const P3& q) {
    auto it = fe.keep_loc.find(q);
    if (it != fe.keep_loc.end()) return it->second;
    std::array<double, 3> w{1, 0, 0};
    const int k = loc.nearest({q[0], q[1]}, w);
    SurfaceQuiltVertex v;
    v.face = p.flat.faces[std::max(0, k)];
    v.b1 = w[1];
    v.b2 = w[2];
    v.z = q[2];
    return v;
  };
  for (std::size_t k = 0; k < fe.mesh.size(); ++k) {
    if (k < n_in)
      write_back_old(k, fe, before, alive, to_loc);
    else if (alive[k] && !fe.mesh[k].tris.empty())
      add_new(fe.mesh[k], loc, p, to_loc);
  }
  mark_processed(p, grid, placed, loc);
}

// An old element after the step: removed if replaced (2.7), else its
// triangles and locations updated; a partly expressed element gets its outer
// triangles joined back at the seam vertices (found at their unchanged frame
// points); if the step reached the seam, the outer part becomes an element
// of its own (counted as a broken seam) rather than a pinched one.
void SurfaceQuilter::write_back_old(std::size_t k, FrameElements& fe, const std::vector<ElementMesh>& before,
                                    const std::vector<char>& alive,
                                    const std::function<SurfaceQuiltVertex(const P3&)>& to_loc) {
  Element& el = elements_[static_cast<std::size_t>(fe.ids[k])];
  const FrameElements::Partial& pt = fe.partial[k];
  const ElementMesh& now_m = fe.mesh[k];
  if (!alive[k]) {
    if (pt.inner.empty()) el.alive = false;  // a partly expressed element keeps its outer part
    return;
  }
  if (now_m.tris == before[k].tris && now_m.points == before[k].points) return;
  el.finished = false;
  if (pt.inner.empty()) {
    el.compact = is_compact_element(now_m);
    el.mesh.tris = now_m.tris;
    el.loc.resize(now_m.points.size());
    for (std::size_t v = 0; v < now_m.points.size(); ++v) el.loc[v] = to_loc(now_m.points[v]);
    return;
  }
  std::map<P3, int> at;
  for (std::size_t v = 0; v < now_m.points.size(); ++v) at.emplace(now_m.points[v], static_cast<int>(v));
  std::vector<int> now(el.loc.size(), -1);
  for (std::size_t s2 = 0; s2 < pt.orig.size(); ++s2) {
    auto it = at.find(before[k].points[s2]);
    if (it != at.end()) now[static_cast<std::size_t>(pt.orig[s2])] = it->second;
  }
  std::vector<SurfaceQuiltVertex> loc(now_m.points.size());
  for (std::size_t v = 0; v < now_m.points.size(); ++v) loc[v] = to_loc(now_m.points[v]);
  const std::size_t n_inner_v = loc.size();
  std::vector<Tri> tris = now_m.tris;
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
  // Sound only if every inner triangle at a seam vertex came back unchanged.
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
    for (const Tri& t : now_m.tris) have.insert(canon(t));
    for (int t : pt.inner) {
      const Tri& tr = el.mesh.tris[static_cast<std::size_t>(t)];
      if (!seam[tr[0]] && !seam[tr[1]] && !seam[tr[2]]) continue;
      Tri m2;
      for (int q = 0; q < 3; ++q) {
        m2[q] = now[static_cast<std::size_t>(tr[q])];
        if (m2[q] < 0 || m2[q] >= static_cast<int>(n_inner_v)) manifold = false;  // (outer-only copies have ids >= n_inner_v)
      }
      if (manifold && !have.count(canon(m2))) manifold = false;
      if (!manifold) break;
    }
  }
  if (!manifold) {
    ++res_.seams_broken;
    const std::size_t n_inner_t = now_m.tris.size();
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
    elements_.push_back(std::move(rest));
  }
  split_pinched_vertices(tris, loc);
  Element& el2 = elements_[static_cast<std::size_t>(fe.ids[k])];  // (push_back may have moved it)
  el2.mesh.tris = std::move(tris);
  el2.loc = std::move(loc);
}

// A new element of the step: kept if its vertex centroid lies on the patch;
// else dropped (its base faces are quilted later), or, with
// trim_new_to_patch (and in the refill rounds), its part on the patch kept,
// the cuts closed.
void SurfaceQuilter::add_new(const ElementMesh& m, const PatchLocator& loc, const Patch& p,
                             const std::function<SurfaceQuiltVertex(const P3&)>& to_loc) {
  double cxs = 0, cys = 0;
  for (const P3& q : m.points) cxs += q[0], cys += q[1];
  const double inv = 1.0 / static_cast<double>(m.points.size());
  std::array<double, 3> w;
  Element el;
  el.loc.resize(m.points.size());
  for (std::size_t v = 0; v < m.points.size(); ++v) el.loc[v] = to_loc(m.points[v]);
  el.compact = is_compact_element(m);
  if (loc.locate({cxs * inv, cys * inv}, w) >= 0) {
    el.mesh.tris = m.tris;
    elements_.push_back(std::move(el));
    return;
  }
  ++res_.dropped_new;
  if ((!opt_.trim_new_to_patch && !refilling_) || el.compact) return;  // (a cut ring or pebble is no element)
  std::vector<char> off(m.points.size(), 0);
  for (std::size_t v = 0; v < m.points.size(); ++v) off[v] = loc.locate({m.points[v][0], m.points[v][1]}, w) < 0;
  std::vector<char> drop(m.tris.size(), 0);
  for (std::size_t t = 0; t < m.tris.size(); ++t)
    for (int v : m.tris[t]) drop[t] = drop[t] || off[static_cast<std::size_t>(v)];
  std::vector<std::pair<std::vector<Tri>, std::vector<SurfaceQuiltVertex>>> pieces;
  trim_element(b_, m.tris, el.loc, drop, S_, swatch_.bbox_min[2], 2 * swatch_h_ * S_, 0.0, pieces);
  if (!pieces.empty()) ++res_.new_trimmed;
  (void)p;
  for (auto& [tris, pl] : pieces) {
    Element e2;
    e2.compact = el.compact;
    e2.mesh.tris = std::move(tris);
    e2.loc = std::move(pl);
    elements_.push_back(std::move(e2));
  }
}

// After a step: patch faces whose frame centroid lies in the footprint, and
// the seed, become processed; the placement's +y is recorded on the faces it
// processed (first placement wins; the orientation jump against an earlier
// one measured); the footprint's points are kept on the surface (cover_).
void SurfaceQuilter::mark_processed(const Patch& p, const QuiltGrid& grid, const QuiltPlacement& placed, const PatchLocator& loc) {
  const double fx0 = grid.x0 + placed.oi * c_ + placed.dx, fy0 = grid.y0 + placed.oj * c_ + placed.dy;
  const double fx1 = fx0 + sx_ * c_, fy1 = fy0 + sy_ * c_;
  auto in_footprint = [&](std::size_t k) {
    const double cxp = (p.ftris[k][0][0] + p.ftris[k][1][0] + p.ftris[k][2][0]) / 3;
    const double cyp = (p.ftris[k][0][1] + p.ftris[k][1][1] + p.ftris[k][2][1]) / 3;
    return cxp >= fx0 && cxp < fx1 && cyp >= fy0 && cyp < fy1;
  };
  for (std::size_t k = 0; k < p.flat.faces.size(); ++k)
    if (in_footprint(k)) mark(p.flat.faces[k]);
  mark(p.seed);
  for (std::size_t k = 0; k < p.flat.faces.size(); ++k) {
    const int f = p.flat.faces[k];
    P3& g = face_dir_[static_cast<std::size_t>(f)];
    if (!processed_[f]) continue;
    const bool old_dir = vec3::norm(g) > 0;
    if (old_dir && !in_footprint(k)) continue;
    // 3D = p0 + E M^-1 (uv - q0), E = [e1 e2], M = [q1 - q0, q2 - q0]; direction of (0, 1).
    const auto& tk = p.ftris[k];
    const double m11 = tk[1][0] - tk[0][0], m12 = tk[2][0] - tk[0][0], m21 = tk[1][1] - tk[0][1], m22 = tk[2][1] - tk[0][1];
    const double det = m11 * m22 - m12 * m21;
    if (det == 0) continue;
    const double a1 = -m12 / det, a2 = m11 / det;
    const auto& tri = b_.faces[f];
    const P3 e1 = vec3::sub(b_.pts[tri[1]], b_.pts[tri[0]]), e2 = vec3::sub(b_.pts[tri[2]], b_.pts[tri[0]]);
    const P3 v{a1 * e1[0] + a2 * e2[0], a1 * e1[1] + a2 * e2[1], a1 * e1[2] + a2 * e2[2]};
    const double l = vec3::norm(v);
    if (!(l > 0)) continue;
    if (old_dir) {  // the jump against the earlier placement, folded by a quarter turn
      const double cosang = std::clamp(vec3::dot(v, g) / l, -1.0, 1.0);
      double a = std::fmod(std::acos(cosang) * 180.0 / kPi, 90.0);
      a = std::min(a, 90.0 - a);
      res_.overlap_turn_sum += b_.area[f] * a;
      res_.overlap_area += b_.area[f];
      if (a > 10) res_.overlap_area_over10 += b_.area[f];
    } else {
      g = {v[0] / l, v[1] / l, v[2] / l};
    }
  }
  for (double y = fy0 + 0.25 * c_; y < fy1; y += 0.5 * c_)
    for (double x = fx0 + 0.25 * c_; x < fx1; x += 0.5 * c_) {
      std::array<double, 3> w{1, 0, 0};
      const int k = loc.locate({x, y}, w);
      if (k >= 0) cover_[static_cast<std::size_t>(p.flat.faces[static_cast<std::size_t>(k)])].push_back({w[1], w[2]});
    }
}

// The quilt's main loop (section 3.1): until every base face is processed.
void SurfaceQuilter::quilt_unprocessed() {
  while (done_ < nf_) {
    const int seed = find_seed();
    report_progress(opt_.progress, progress_stage_, static_cast<double>(done_ - progress_from_) / (nf_ - progress_from_));
    Timer tp;
    Patch p;
    grow_and_flatten(seed, p, opt_.patch_radius * swatch_diag_, cos_max_);
    orient(p);
    align(p);
    const PatchLocator loc0(p.ftris, c_);
    res_.seconds_patch += tp.seconds();
    Timer ts;
    FrameElements fe = express(p);
    Timer tr;
    const double turn = search_turn(p, fe, loc0);
    QuiltGrid grid = make_grid(p, turn, loc0);
    apply_turn(p, fe, turn);
    drift(p);
    res_.seconds_turn += tr.seconds();
    const PatchLocator loc = turn != 0 ? PatchLocator(p.ftris, c_) : loc0;
    merge(p, fe, grid, loc);
    for (int f : p.flat.faces) patch_slot_[f] = -1;
    res_.seconds_step += ts.seconds();
    ++res_.steps;
  }
  report_progress(opt_.progress, progress_stage_, 1.0);
}

// A location lifted to where the shell puts it, roughly: its foot on the
// base plus its height above the swatch's bottom along the interpolated
// vertex normal (the shell's offset direction).
P3 SurfaceQuilter::lifted(const SurfaceQuiltVertex& v) const {
  return lift_point(b_, vertex_normal_, v, swatch_.bbox_min[2], S_);
}

namespace {
// Marks, besides the triangles in `drop`, `rings` rings of triangles around them.
void grow_drop(const std::vector<Tri>& tris, std::size_t nv, std::vector<char>& drop, int rings) {
  for (int r = 0; r < rings; ++r) {
    std::vector<char> vd(nv, 0);
    for (std::size_t t = 0; t < tris.size(); ++t)
      if (drop[t])
        for (int v : tris[t]) vd[static_cast<std::size_t>(v)] = 1;
    for (std::size_t t = 0; t < tris.size(); ++t)
      for (int v : tris[t]) drop[t] = drop[t] || vd[static_cast<std::size_t>(v)];
  }
}
}  // namespace

// The element shifted in z into the output's z range (the swatch's, widened
// by max_z_growth swatch heights), squeezed if taller than it: the
// deformations and stitches of sections 2.6-2.7 move vertices a little past it.
void SurfaceQuilter::fit_z(Element& el) {
  const double lim_lo = swatch_.bbox_min[2] - opt_.max_z_growth * swatch_h_, lim_hi = swatch_.bbox_max[2] + opt_.max_z_growth * swatch_h_;
  const auto [lo, hi] = z_extent(el.loc);
  if (!(lo < lim_lo || hi > lim_hi)) return;
  ++res_.z_fitted_elements;
  res_.z_fitted_vertices += el.loc.size();
  if (hi - lo <= lim_hi - lim_lo) {
    const double shift = lo < lim_lo ? lim_lo - lo : lim_hi - hi;
    for (SurfaceQuiltVertex& v : el.loc) v.z = std::clamp(v.z + shift, lim_lo, lim_hi);
  } else {
    for (SurfaceQuiltVertex& v : el.loc) v.z = std::clamp(lim_lo + (v.z - lo) * (lim_hi - lim_lo) / (hi - lo), lim_lo, lim_hi);
  }
}

// Finish, first part: every location moved onto the base face containing it;
// elements past a border of the base mesh trimmed there (or removed), and
// stretched triangles (an edge longer, lifted, than max_edge_stretch times
// the swatch's longest edge, scaled: a shard) cut out of non-compact
// elements, whose pieces are capped (trim_element), and compact elements
// with one removed (issue 17 item 2: their space is refilled, refill()).
void SurfaceQuilter::settle_and_trim(std::size_t from) {
  const double max_edge = longest_edge_length(swatch_.mesh);
  const double bound = opt_.max_edge_stretch * max_edge * S_, cap_max = 2 * swatch_h_ * S_;
  stretch_bound2_ = opt_.max_edge_stretch > 0 ? bound * bound : 0.0;
  const double thread_bound = (opt_.max_thread_stretch > 0 ? opt_.max_thread_stretch : opt_.max_edge_stretch) * max_edge * S_;
  thread_bound2_ = thread_bound * thread_bound;
  // (The pieces appended are checked in turn: a cap's edges, lifted along
  // the vertex normals, may pass the bound where they diverge, at a rim.)
  for (std::size_t e = from; e < elements_.size(); ++e) {
    if (!elements_[e].alive || elements_[e].mesh.tris.empty() || elements_[e].finished) continue;
    Element& el = elements_[e];
    fit_z(el);
    std::vector<char> past_v(el.loc.size(), 0);
    std::size_t past = 0;
    for (std::size_t i = 0; i < el.loc.size(); ++i) {
      SurfaceQuiltVertex& v = el.loc[i];
      if (settle_location(b_, v)) continue;
      ++past;
      past_v[i] = 1;
      std::array<double, 3> w{std::max(0.0, 1 - v.b1 - v.b2), std::max(0.0, v.b1), std::max(0.0, v.b2)};
      const double sum = w[0] + w[1] + w[2];
      if (sum > 0) v.b1 = w[1] / sum, v.b2 = w[2] / sum;
    }
    const bool too_far = static_cast<double>(past) > opt_.max_past_border * static_cast<double>(el.loc.size());
    if (too_far && !opt_.trim_at_border) {
      ++res_.elements_past_border;
      el.alive = false;
      continue;
    }
    std::vector<P3> lp(el.loc.size());
    for (std::size_t i = 0; i < el.loc.size(); ++i) lp[i] = lifted(el.loc[i]);
    std::vector<char> drop(el.mesh.tris.size(), 0);
    bool any_stretched = false, any_past = false;
    for (std::size_t t = 0; t < el.mesh.tris.size(); ++t) {
      const Tri& tr = el.mesh.tris[t];
      if (too_far && (past_v[tr[0]] || past_v[tr[1]] || past_v[tr[2]])) drop[t] = 1, any_past = true;
      const double b = el.compact ? bound : thread_bound;
      for (int k = 0; k < 3 && b > 0; ++k) {
        const double len = vec3::norm(vec3::sub(lp[tr[k]], lp[tr[(k + 1) % 3]]));
        if (len > b) drop[t] = 1, any_stretched = true;
      }
    }
    if (!any_past && !any_stretched) continue;
    if (any_stretched) ++res_.elements_stretched;
    if (any_stretched && el.compact) {
      el.alive = false;
      continue;
    }
    if (any_stretched) grow_drop(el.mesh.tris, el.loc.size(), drop, 1);
    std::vector<std::pair<std::vector<Tri>, std::vector<SurfaceQuiltVertex>>> pieces;
    trim_element(b_, el.mesh.tris, el.loc, drop, S_, swatch_.bbox_min[2], cap_max, any_stretched ? thread_bound2_ : 0.0,
                 pieces);
    el.alive = false;
    if (pieces.empty()) {
      if (any_past && !any_stretched) ++res_.elements_past_border;
      continue;
    }
    if (any_past) ++res_.elements_trimmed;
    const bool compact = el.compact;
    for (auto& [tris, locs] : pieces) {
      Element piece;
      piece.mesh.tris = std::move(tris);
      piece.loc = std::move(locs);
      piece.compact = compact;
      elements_.push_back(std::move(piece));  // (invalidates el)
    }
  }
}

// Finish, second part (issue 17 item 1, the safety net of quilt_step's
// resolve_crossings, which sees only what a patch's frame holds): the
// elements lifted (lifted()) and tested against each other (exact
// triangle-triangle tests, element_clearance.h); from the last element to
// the first, one that hits an earlier one yields: removed if compact, else
// the triangles that hit (and opt.step.trim_rings rings) cut out and the
// pieces capped; a piece that still hits is removed. Elements a previous
// finish checked and nothing changed since (Element::finished) cross none
// of each other, so only the others are tested (against all).
void SurfaceQuilter::resolve_crossings_lifted() {
  std::vector<ElementMesh> lifted_els;
  std::vector<int> id;  // element index per lifted element
  for (std::size_t e = 0; e < elements_.size(); ++e) {
    if (!elements_[e].alive || elements_[e].mesh.tris.empty()) continue;
    lifted_els.push_back(lifted_mesh(elements_[e]));
    id.push_back(static_cast<int>(e));
  }
  ElementCollider coll(lifted_els, {});
  std::vector<char> dead(lifted_els.size(), 0);
  const double cap_max = 2 * swatch_h_ * S_;
  for (std::size_t i = lifted_els.size(); i-- > 0;) {
    if (elements_[static_cast<std::size_t>(id[i])].finished) continue;
    ++res_.finish_elements_checked;
    const std::vector<char> hit = coll.hits(lifted_els[i], static_cast<int>(i), 0.0, &dead);
    if (std::find(hit.begin(), hit.end(), 1) == hit.end()) continue;
    ++res_.crossings_resolved;
    Element& el = elements_[static_cast<std::size_t>(id[i])];
    if (el.compact && lift_rings_ && lift_clear(el, static_cast<int>(i), coll, dead)) continue;
    dead[i] = 1;
    el.alive = false;
    if (el.compact) continue;
    std::vector<char> drop = hit;
    grow_drop(el.mesh.tris, el.loc.size(), drop, opt_.step.trim_rings);
    std::vector<std::pair<std::vector<Tri>, std::vector<SurfaceQuiltVertex>>> pieces;
    trim_element(b_, el.mesh.tris, el.loc, drop, S_, swatch_.bbox_min[2], cap_max, thread_bound2_, pieces);
    for (auto& [tris, locs] : pieces) {
      ElementMesh m;
      m.tris = tris;
      for (const auto& v : locs) m.points.push_back(lifted(v));
      if (coll.any_hit(m, -1, 0.0, &dead)) continue;
      const int nid = static_cast<int>(dead.size());
      dead.push_back(0);
      coll.add(m, nid);
      Element piece;
      piece.mesh.tris = std::move(tris);
      piece.loc = std::move(locs);
      elements_.push_back(std::move(piece));  // (invalidates el)
    }
  }
}

// The height changes (swatch units) an interlinked swatch's element is tried
// at where it crosses (lift_crossing_rings): 0.1, -0.1, 0.2, -0.2 swatch
// heights, those that keep it within the swatch's z range.
std::vector<double> SurfaceQuilter::z_lifts(const Element& el) const {
  const auto [lo, hi] = z_extent(el.loc);
  std::vector<double> out;
  for (const double step : {0.1, -0.1, 0.2, -0.2}) {
    const double dz = step * swatch_h_;
    if (lo + dz >= swatch_.bbox_min[2] && hi + dz <= swatch_.bbox_max[2]) out.push_back(dz);
  }
  return out;
}

// A crossing compact element moved and kept at the first move where it
// crosses nothing: along the normal (0.1, -0.1, 0.2, -0.2 swatch heights,
// within the swatch's z range), then along the surface (0.1 and 0.2 of its
// width in 8 directions; each vertex walked over the base from its foot). In
// an interlinked swatch (chain mail) a ring that meets a neighbour's tilted
// ring often clears it a little higher, lower or aside. Its old triangles are
// retired from the collider, its new ones added.
bool SurfaceQuilter::lift_clear(Element& el, int i, ElementCollider& coll, std::vector<char>& dead) {
  auto accept = [&](Element& moved) {
    const ElementMesh m = lifted_mesh(moved);
    if (coll.any_hit(m, i, 0.0, &dead)) return false;
    el.loc = std::move(moved.loc);
    dead[static_cast<std::size_t>(i)] = 1;
    const int nid = static_cast<int>(dead.size());
    dead.push_back(0);
    coll.add(m, nid);
    ++res_.crossings_lifted_clear;
    return true;
  };
  for (const double dz : z_lifts(el)) {
    Element moved = el;
    for (SurfaceQuiltVertex& v : moved.loc) v.z += dz;
    if (accept(moved)) return true;
  }
  // A tangent frame at the element's feet: their mean normal and its extent.
  P3 n{0, 0, 0}, c{0, 0, 0};
  std::vector<P3> feet(el.loc.size());
  for (std::size_t k = 0; k < el.loc.size(); ++k) {
    feet[k] = base_point(b_, el.loc[k]);
    for (int d = 0; d < 3; ++d) n[d] += b_.normal[el.loc[k].face][d], c[d] += feet[k][d] / el.loc.size();
  }
  double width = 0;
  for (const P3& f : feet) width = std::max(width, 2 * vec3::norm(vec3::sub(f, c)));
  if (!(vec3::norm(n) > 0) || !(width > 0)) return false;
  const double ln = vec3::norm(n);
  n = {n[0] / ln, n[1] / ln, n[2] / ln};
  P3 e1 = std::abs(n[0]) < 0.9 ? vec3::cross(n, P3{1, 0, 0}) : vec3::cross(n, P3{0, 1, 0});
  const double le = vec3::norm(e1);
  e1 = {e1[0] / le, e1[1] / le, e1[2] / le};
  const P3 e2 = vec3::cross(n, e1);
  for (const double frac : {0.1, 0.2})
    for (int dir = 0; dir < 8; ++dir) {
      const double a = dir * kPi / 4, len = frac * width;
      const P3 t{len * (std::cos(a) * e1[0] + std::sin(a) * e2[0]), len * (std::cos(a) * e1[1] + std::sin(a) * e2[1]),
                 len * (std::cos(a) * e1[2] + std::sin(a) * e2[2])};
      Element moved = el;
      bool ok = true;
      for (std::size_t k = 0; k < moved.loc.size() && ok; ++k) {
        SurfaceQuiltVertex& v = moved.loc[k];
        const P3 q{feet[k][0] + t[0], feet[k][1] + t[1], feet[k][2] + t[2]};
        const auto w = project_bary(b_, v.face, q);
        v.b1 = w[1];
        v.b2 = w[2];
        ok = settle_location(b_, v);
      }
      if (ok && accept(moved)) return true;
    }
  return false;
}

// Finish: compact elements that lost their shape (issue 17 item 2; Zhou
// 2006's elements keep theirs): merged with a neighbour (2.7) or deformed
// (2.6) so that, lifted, they spread wider than max_shape_ratio times the
// swatch's largest compact element, scaled (spread13), are removed; their
// space is refilled and scattered. When every swatch element is compact,
// every output element is held to it (a doubled pebble is no thread).
void SurfaceQuilter::remove_misshapen() {
  if (!(opt_.max_shape_ratio > 0) || !(compact_spread_ > 0)) return;
  const double lim = opt_.max_shape_ratio * compact_spread_ * S_;
  for (Element& el : elements_) {
    if (!el.alive || el.finished || el.mesh.tris.empty() || !(el.compact || all_compact_)) continue;
    if (spread13(lifted_mesh(el).points) <= lim) continue;
    el.alive = false;
    ++res_.elements_misshapen;
  }
}

// Finish: broken compact elements. A ring or torus cut open (at a patch
// border, by a crossing or a refused merge) is capped into a C-shaped piece
// with no handle (remove_broken_rings); a small piece of any compact element
// is a crumpled cap more than a pebble (min_piece_fraction). Zhou 2.7 merges
// elements or keeps them whole, so both are shards: removed, their space
// refilled and scattered like any bare space.
void SurfaceQuilter::remove_broken_elements() {
  if (compact_.empty()) return;
  std::size_t smallest = std::numeric_limits<std::size_t>::max();
  for (const ElementMesh& m : compact_) smallest = std::min(smallest, m.tris.size());
  const double min_faces = opt_.min_piece_fraction * static_cast<double>(smallest);
  const bool rings = opt_.remove_broken_rings && ring_handles_ > 0;
  for (Element& el : elements_) {
    if (!el.alive || el.finished || !(el.compact || all_compact_) || el.mesh.tris.empty()) continue;
    if (static_cast<double>(el.mesh.tris.size()) < min_faces) {
      el.alive = false;
      ++res_.small_pieces_removed;
    } else if (rings && element_genus(el.mesh.tris) < ring_handles_) {
      el.alive = false;
      ++res_.broken_rings_removed;
    }
  }
}

void SurfaceQuilter::finish() {
  Timer t;
  settle_and_trim(0);
  remove_misshapen();
  if (opt_.resolve_crossings) {
    const std::size_t n = elements_.size();
    resolve_crossings_lifted();
    settle_and_trim(n);  // the pieces it cut, against the stretch bound
  }
  remove_broken_elements();
  for (Element& el : elements_) el.finished = el.alive;
  res_.seconds_finish += t.seconds();
}

// The feet of the live elements' vertices, for bare_samples: radius half the
// swatch's element spacing (swatch_element_spacing, scaled).
FootGrid SurfaceQuilter::element_feet(bool without_fragments) const {
  FootGrid feet(0.5 * swatch_element_spacing(swatch_) * S_);
  for (const Element& el : elements_)
    if (el.alive && !(without_fragments && is_fragment(el)))
      for (const auto& v : el.loc) feet.add(base_point(b_, v));
  return feet;
}

// Fragments: emit leaves them out, and they cover nothing (fragment_faces_).
bool SurfaceQuilter::is_fragment(const Element& el) const { return el.mesh.tris.size() < fragment_faces_; }

double SurfaceQuilter::bare_area_fraction(const std::vector<char>& bare) const {
  double a = 0, ab = 0;
  for (int f = 0; f < nf_; ++f) a += b_.area[f], ab += 0.25 * bare[static_cast<std::size_t>(f)] * b_.area[f];
  return a > 0 ? ab / a : 0;
}

std::vector<char> SurfaceQuilter::bare_faces(bool without_fragments) const {
  const FootGrid feet = element_feet(without_fragments);
  std::vector<char> bare(static_cast<std::size_t>(nf_), 0);
  for (int f = 0; f < nf_; ++f) bare[static_cast<std::size_t>(f)] = static_cast<char>(bare_samples(b_, f, feet));
  return bare;
}

// Refill (issue 17 items 2 and 4): the bare faces (where elements were
// dropped, trimmed or removed, or never placed: a thin ear's threads fall off
// their small patches) become unprocessed again, their footprint points
// forgotten, so that the loop quilts them once more (with new elements off
// their patch kept trimmed to it). Returns the number of faces reopened.
std::size_t SurfaceQuilter::refill() {
  const std::vector<char> bare = bare_faces();
  std::size_t n = 0;
  for (int f = 0; f < nf_; ++f) {
    if (bare[static_cast<std::size_t>(f)] < 2 || !processed_[f]) continue;
    processed_[f] = 0;
    --done_;
    for (int g : b_.vertex_nb[f]) --constrained_[g];
    cover_[static_cast<std::size_t>(f)].clear();
    ++n;
  }
  res_.faces_refilled += n;
  return n;
}

// An element's vertices lifted (lifted()), its triangles.
ElementMesh SurfaceQuilter::lifted_mesh(const Element& el) const {
  ElementMesh m;
  m.tris = el.mesh.tris;
  m.points.reserve(el.loc.size());
  for (const auto& v : el.loc) m.points.push_back(lifted(v));
  return m;
}

// One scatter candidate: the template turned by `quarter` quarter turns,
// moved by `offset` (frame units) from the patch's seed. Kept (in `el`) only
// if every vertex lies on the patch (no extrapolation), no lifted edge is
// stretched past scatter_max_stretch times its swatch length (nor past the
// shard bound, SurfaceQuiltOptions::max_edge_stretch), and the lifted
// element neither crosses nor comes within half the swatch's smallest gap of
// an element already placed.
bool SurfaceQuilter::place_scatter_element(const Patch& p, const PatchLocator& loc, const ElementMesh& tpl, int quarter,
                                           const V2& offset, ElementCollider& coll, Element& el) {
  static constexpr int kCos[4] = {1, 0, -1, 0}, kSin[4] = {0, 1, 0, -1};
  const int c = kCos[quarter & 3], sn = kSin[quarter & 3];
  el = Element{};
  el.compact = true;
  el.mesh.tris = tpl.tris;
  el.loc.resize(tpl.points.size());
  for (std::size_t v = 0; v < tpl.points.size(); ++v) {
    const P3& q = tpl.points[v];
    std::array<double, 3> w{1, 0, 0};
    const int k = loc.locate({c * q[0] - sn * q[1] + offset[0], sn * q[0] + c * q[1] + offset[1]}, w);
    if (k < 0) return false;
    el.loc[v] = {p.flat.faces[static_cast<std::size_t>(k)], w[1], w[2], q[2]};
  }
  const double stretch = scatter_only_ ? opt_.scatter_alone_max_stretch : opt_.scatter_max_stretch;
  const double lim2 = stretch * stretch * S_ * S_;
  // Where it would cross, an interlinked swatch's element is tried a little
  // higher and lower too (z_lifts).
  std::vector<double> shifts{0};
  if (lift_rings_)
    for (const double dz : z_lifts(el)) shifts.push_back(dz);
  for (const double dz : shifts) {
    Element at = el;
    for (SurfaceQuiltVertex& v : at.loc) v.z += dz;
    const ElementMesh m = lifted_mesh(at);
    for (const Tri& t : tpl.tris)
      for (int k = 0; k < 3; ++k) {
        const P3 d0 = vec3::sub(tpl.points[static_cast<std::size_t>(t[k])], tpl.points[static_cast<std::size_t>(t[(k + 1) % 3])]);
        const P3 d1 = vec3::sub(m.points[static_cast<std::size_t>(t[k])], m.points[static_cast<std::size_t>(t[(k + 1) % 3])]);
        if (vec3::dot(d1, d1) > lim2 * vec3::dot(d0, d0) || (stretch_bound2_ > 0 && vec3::dot(d1, d1) > stretch_bound2_)) return false;
      }
    if (coll.any_hit(m, -1, scatter_clearance_)) continue;
    coll.add(m, static_cast<int>(elements_.size()));
    el.loc = std::move(at.loc);
    if (dz != 0) ++res_.scatter_lifted;
    return true;
  }
  return false;
}

// Scatter fill (issue 17 item 4): the refill rounds quilt bare faces with
// whole swatch patches, whose compact elements then cross their neighbours
// and are removed again, so holes of about one element stay. Here each face
// with a bare point (scatter_bare_samples) gets, on a small patch around it
// (flattened and oriented as a quilting patch, section 3.1), one of the
// swatch's compact elements at a time: tried in four quarter turns at the
// face (a swatch scattered alone: in the field's orientation only), then
// moved by up to half the element spacing, and kept where it fits
// (place_scatter_element). A swatch of threads alone (a weave) scatters
// pieces of its threads (thread_pieces_): where a fin or a lobe is too small
// for whole threads, the quilting's trimmed threads leave it bare.
void SurfaceQuilter::scatter_into_bare() {
  const std::vector<ElementMesh>& tpl = compact_.empty() ? thread_pieces_ : compact_;
  if (tpl.empty()) return;
  // Scattered alone, copies go where the face is bare (two points): started
  // at faces with one, they packed worse (bunny + rock_1: 0.18% -> 0.75% bare).
  const int min_bare = scatter_only_ ? 2 : opt_.scatter_bare_samples;
  double reach = 0;  // the largest template's xy radius (swatch units)
  for (const ElementMesh& m : tpl)
    for (const P3& q : m.points) reach = std::max(reach, std::hypot(q[0], q[1]));
  std::vector<ElementMesh> lifted_els;
  for (const Element& el : elements_)
    if (el.alive && !el.mesh.tris.empty()) lifted_els.push_back(lifted_mesh(el));
  ElementCollider coll(lifted_els, {});
  FootGrid feet = element_feet();
  const double jitter = 0.5 * swatch_element_spacing(swatch_);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  // Faces whose tries all failed: a face next to one (its centroid within
  // scatter_skip_near_failed of the jitter) is not tried in this pass.
  const double skip = opt_.scatter_skip_near_failed * jitter * S_;
  CellGrid<int> failed(skip > 0 ? skip : 1.0);
  auto near_failed = [&](int f) {
    const P3& c = b_.centroid[f];
    return skip > 0 && failed.any_near(c, [&](const P3& q, int) {
      const P3 d = vec3::sub(q, c);
      return vec3::dot(d, d) < skip * skip;
    });
  };
  for (int f = 0; f < nf_; ++f) {
    if (f % 256 == 0) report_progress(opt_.progress, "scatter", static_cast<double>(f) / nf_);
    if (bare_samples(b_, f, feet) < min_bare) continue;
    if (near_failed(f)) {
      ++res_.scatter_faces_skipped;
      continue;
    }
    ++res_.scatter_faces_tried;
    Patch p;
    grow_and_flatten(f, p, 2 * reach * S_, scatter_cos_max_);
    orient(p);
    frame_triangles(p);
    const PatchLocator loc(p.ftris, c_);
    Element el;
    bool placed = false;
    const int attempts = scatter_only_ ? opt_.scatter_alone_attempts : opt_.scatter_attempts;
    // Scattered alone, elements keep the field's orientation, as a quilted
    // swatch does (tubes in rows, not turned every which way); only moved.
    const int turns = scatter_only_ ? 1 : 4;
    for (int a = 0; a < attempts && !placed; ++a) {
      const ElementMesh& t = tpl[static_cast<std::size_t>(rng_() % tpl.size())];
      const V2 off = a < turns ? V2{0, 0} : V2{jitter * unit(rng_), jitter * unit(rng_)};
      placed = place_scatter_element(p, loc, t, scatter_only_ ? 0 : a, off, coll, el);
    }
    for (int g : p.flat.faces) patch_slot_[g] = -1;
    if (!placed) {
      if (skip > 0) failed.add(b_.centroid[f], f);
      continue;
    }
    for (const auto& v : el.loc) feet.add(base_point(b_, v));
    elements_.push_back(std::move(el));
    ++res_.scatter_placed;
  }
  report_progress(opt_.progress, "scatter", 1.0);
}

// The output: every live element (fitted into the z range by finish)
// appended, fragments left out; the z range widened to the vertices' heights.
void SurfaceQuilter::emit(SurfaceQuilt& out) {
  out = SurfaceQuilt{};
  out.scale = S_;
  out.z_min = swatch_.bbox_min[2];
  out.z_max = swatch_.bbox_max[2];
  for (Element& el : elements_) {
    if (!el.alive || el.mesh.tris.empty()) continue;
    if (is_fragment(el)) {
      ++res_.fragments_removed;
      continue;
    }
    const std::vector<SurfaceQuiltVertex>& settled = el.loc;
    const int base_index = static_cast<int>(out.vertices.size());
    for (const SurfaceQuiltVertex& v : settled) out.vertices.push_back(v);
    for (const Tri& t : el.mesh.tris) {
      out.tris.push_back({t[0] + base_index, t[1] + base_index, t[2] + base_index});
      out.tri_element.push_back(out.elements);
    }
    out.element_compact.push_back(el.compact ? 1 : 0);
    ++out.elements;
  }
  double lo = out.z_min, hi = out.z_max;
  for (const SurfaceQuiltVertex& v : out.vertices) lo = std::min(lo, v.z), hi = std::max(hi, v.z);
  res_.z_grown_below = out.z_min - lo;
  res_.z_grown_above = hi - out.z_max;
  out.z_min = lo;
  out.z_max = hi;
  // The longest element edge (lifted) over the swatch's longest edge, scaled.
  const double max_edge = longest_edge_length(swatch_.mesh);
  double longest = 0;
  for (const Tri& t : out.tris)
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, vec3::norm(vec3::sub(lifted(out.vertices[static_cast<std::size_t>(t[k])]),
                                             lifted(out.vertices[static_cast<std::size_t>(t[(k + 1) % 3])]))));
  res_.edge_stretch_max = max_edge > 0 ? longest / (max_edge * S_) : 0;
}

// Zhou's loop (3.1) over every unprocessed face, then the refill rounds.
void SurfaceQuilter::quilt_and_refill() {
  quilt_unprocessed();
  finish();
  res_.refill_rounds = opt_.refill_rounds >= 0 ? opt_.refill_rounds : compact_.empty() ? 6 : 3;
  for (int round = 0; round < res_.refill_rounds; ++round) {
    if (refill() == 0) break;
    ++res_.refill_rounds_run;
    // (Each round its own progress stage: the faces it reopened, from 0%.)
    progress_stage_ = "quilt refill " + std::to_string(round + 1) + "/" + std::to_string(res_.refill_rounds);
    progress_from_ = done_;
    refilling_ = true;
    quilt_unprocessed();
    finish();
  }
}

// A swatch of few compact elements (scatter_swatch_elements): the scatter
// fill alone places whole copies, pass after pass while a pass still places
// some (at most scatter_passes), the copies kept scatter_clearance of the
// swatch's larger side apart (the shell map moves touching copies into each
// other).
void SurfaceQuilter::scatter_whole_elements() {
  Timer ts;
  res_.scatter_only = true;
  for (int pass = 0; pass < opt_.scatter_passes; ++pass) {
    const std::size_t before = res_.scatter_placed;
    scatter_into_bare();
    if (res_.scatter_placed == before) break;
  }
  res_.seconds_finish += ts.seconds();
}

SurfaceQuiltResult SurfaceQuilter::run(SurfaceQuilt& out) {
  Timer timer;
  if (scatter_only_) {
    scatter_whole_elements();
  } else {
    quilt_and_refill();
    if (opt_.scatter_attempts > 0) {
      Timer ts;
      scatter_into_bare();
      res_.seconds_finish += ts.seconds();
    }
  }
  // Of the output: without the fragments emit leaves out.
  res_.bare_fraction = bare_area_fraction(bare_faces(true));
  emit(out);
  res_.elements = out.elements;
  res_.faces = out.tris.size();
  res_.vertices = out.vertices.size();
  res_.seconds = timer.seconds();
  return res_;
}

}  // namespace

double surface_quilt_scale(const Mesh& base, const Swatch& swatch, double relative_size) {
  P3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (VertexIndex v : base.vertices()) {
    const Point3& p = base.point(v);
    const P3 q{p.x(), p.y(), p.z()};
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], q[d]), hi[d] = std::max(hi[d], q[d]);
  }
  const double diag = base.is_empty() ? 0.0 : vec3::norm(vec3::sub(hi, lo));
  return relative_size * diag / std::max(swatch.length(), swatch.width());
}

namespace {
// The larger xy side of the swatch's longest thread (an element that is not
// compact), from the element boxes make_swatch keeps; 0 when there is none.
double longest_thread(const Swatch& s) {
  double longest = 0;
  for (const SwatchElement& el : s.elements) {
    const double a = el.bbox_max[0] - el.bbox_min[0], b = el.bbox_max[1] - el.bbox_min[1];
    if (!is_compact_extent(a, b)) longest = std::max({longest, a, b});
  }
  return longest;
}
}  // namespace

std::vector<ElementMesh> compact_swatch_elements(const Swatch& s) {
  std::vector<ElementMesh> out;
  for (ElementMesh& m : swatch_element_meshes(s)) {
    if (m.points.empty() || !is_compact_element(m)) continue;
    centre_xy(m);
    out.push_back(std::move(m));
  }
  return out;
}

bool scattered_alone(const Swatch& swatch, const SurfaceQuiltOptions& opt) {
  const std::vector<ElementMesh> compact = compact_swatch_elements(swatch);
  return opt.scatter_attempts > 0 && !compact.empty() && compact.size() == swatch.elements.size() &&
         compact.size() <= static_cast<std::size_t>(opt.scatter_swatch_elements);
}

double scatter_gap(const Swatch& swatch, const SurfaceQuiltOptions& opt) {
  return scattered_alone(swatch, opt) ? opt.scatter_clearance * std::max(swatch.length(), swatch.width())
                                      : 0.5 * swatch.min_gap;
}

std::vector<ElementMesh> thread_fill_templates(const Swatch& swatch, const SurfaceQuiltOptions& opt) {
  if (opt.scatter_attempts <= 0 || !compact_swatch_elements(swatch).empty()) return {};
  return thread_scatter_pieces(swatch, opt.scatter_thread_parts);
}

std::vector<ElementMesh> thread_scatter_pieces(const Swatch& swatch, int parts) {
  std::vector<ElementMesh> out;
  if (parts < 1) return out;
  const std::vector<ElementMesh> meshes = swatch_element_meshes(swatch);
  for (std::size_t e = 0; e < meshes.size() && e < swatch.elements.size(); ++e) {
    const ElementMesh& m = meshes[e];
    const SwatchElement& el = swatch.elements[e];
    const double side[2] = {el.bbox_max[0] - el.bbox_min[0], el.bbox_max[1] - el.bbox_min[1]};
    // (A ring cut into arcs is the broken ring remove_broken_elements removes.)
    if (m.points.empty() || is_compact_extent(side[0], side[1]) || element_genus(m.tris) > 0) continue;
    const int axis = side[0] >= side[1] ? 0 : 1;
    const double len = side[axis] / parts;
    for (int k = 0; k < parts; ++k) {
      // The slab [w0, w1] along the thread: every triangle with a vertex outside it dropped.
      const double w0 = el.bbox_min[axis] + k * len, w1 = w0 + len;
      std::vector<char> drop(m.tris.size(), 0);
      for (std::size_t t = 0; t < m.tris.size(); ++t)
        for (int v : m.tris[t]) {
          const double x = m.points[static_cast<std::size_t>(v)][axis];
          drop[t] = drop[t] || x < w0 || x > w1;
        }
      for (ElementMesh& piece : trim_and_cap(m, drop, 0, 8)) {
        centre_xy(piece);
        out.push_back(std::move(piece));
      }
    }
  }
  return out;
}

double default_surface_quilt_size(const Swatch& swatch) {
  constexpr double kSize = 0.25, kElementSize = 1.0 / 16, kElementHeight = 1.0 / 32, kThreadLength = 1.0 / 8;
  const double whole = std::max(swatch.length(), swatch.width());
  if (!(whole > 0)) return kSize;
  double size = kSize;
  // Threads: the longest at most 1/8 of the diagonal, so that it follows a
  // patch it can be expressed in (decision 102, session 24).
  const double longest = longest_thread(swatch);
  if (longest > 0) size = std::min(size, kThreadLength * whole / longest);
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  // Every element's height (z extent) at most 1/32 of the diagonal: standing
  // chain-mail rings too, which are neither compact nor long (session 30).
  std::vector<double> heights;
  for (const SwatchElement& e : swatch.elements) heights.push_back(std::max(0.0, e.bbox_max[2] - e.bbox_min[2]));
  if (!heights.empty()) {
    const double h = median(heights);
    if (h > 0) size = std::min(size, kElementHeight * whole / h);
  }
  std::vector<double> sides;  // larger xy side of each compact element
  for (const ElementMesh& m : compact_swatch_elements(swatch)) {
    double lo[2], hi[2];
    for (int d = 0; d < 2; ++d) lo[d] = std::numeric_limits<double>::infinity(), hi[d] = -lo[d];
    for (const P3& q : m.points)
      for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], q[d]), hi[d] = std::max(hi[d], q[d]);
    const double side = std::max(hi[0] - lo[0], hi[1] - lo[1]);
    if (side > 0) sides.push_back(side);
  }
  if (!sides.empty()) size = std::min(size, kElementSize * whole / median(sides));
  return size;
}

double surface_quilt_placements(const Mesh& base, const Swatch& swatch, double relative_size) {
  double area = 0;
  for (FaceIndex f : base.faces()) area += face_area(base, f);
  const double S = surface_quilt_scale(base, swatch, relative_size);
  const double swatch_area = swatch.length() * swatch.width() * S * S;
  return swatch_area > 0 ? area / swatch_area : 0.0;
}

SurfaceQuiltResult quilt_surface(const Mesh& mesh, const Swatch& swatch, SurfaceQuilt& out, const SurfaceQuiltOptions& opt) {
  SurfaceQuilter q(mesh, swatch, opt);
  return q.run(out);
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

void surface_quilt_lifted(const Mesh& base, const SurfaceQuilt& q, double z0, Mesh& out) {
  const Base b = make_base(base);
  const std::vector<P3> vn = vertex_normals(b);
  auto pos = [&](const SurfaceQuiltVertex& v) -> P3 {
    if (v.face < 0 || static_cast<std::size_t>(v.face) >= b.faces.size())
      throw InvalidInputError("surface_quilt_lifted: face index " + std::to_string(v.face) + " out of range");
    return lift_point(b, vn, v, z0, q.scale);
  };
  mesh_from_elements(quilt_elements(q, pos), out);
}

}  // namespace surftex
