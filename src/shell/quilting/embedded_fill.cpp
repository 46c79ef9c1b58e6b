// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/embedded_fill.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "geometry/errors.h"
#include "geometry/vec3.h"
#include "shell/element_clearance.h"
#include "shell/quilting/foot_grid.h"
#include "shell/quilting/quilt_coverage.h"
#include "shell/triangle_distance.h"

namespace surftex {

namespace {

constexpr double kPi = 3.14159265358979323846;

void check_options(const EmbeddedFillOptions& o) {
  auto bad = [](const std::string& what) { throw InvalidInputError("fill_embedded_bare: " + what); };
  if (o.templates.empty()) return;
  if (!(o.scale > 0) || !std::isfinite(o.scale)) bad("scale must be > 0");
  if (!(o.radius > 0) || !std::isfinite(o.radius)) bad("radius must be > 0");
  if (!std::isfinite(o.z0)) bad("z0 must be finite");
  if (o.attempts < 1 || o.attempts > 64) bad("attempts must be in 1..64");
  if (!(o.max_stretch >= 1) || !std::isfinite(o.max_stretch)) bad("max_stretch must be >= 1");
  if (!(o.max_edge >= 0) || !std::isfinite(o.max_edge)) bad("max_edge must be >= 0");
  if (!(o.max_normal_angle_deg > 0 && o.max_normal_angle_deg <= 180)) bad("max_normal_angle_deg must be in (0, 180]");
  if (!(o.max_float >= 0) || !std::isfinite(o.max_float)) bad("max_float must be >= 0");
  if (!(o.clearance >= 0) || !std::isfinite(o.clearance)) bad("clearance must be >= 0");
  if (o.turns != 1 && o.turns != 4) bad("turns must be 1 or 4");
  for (double u : o.up)
    if (!std::isfinite(u)) bad("up must be finite");
}

// An element's long axis: the principal direction of its points (power
// iteration on the covariance; the xy-free start avoids a zero vector).
P3 long_axis(const ElementMesh& m) {
  P3 c{0, 0, 0};
  for (const P3& p : m.points) c = vec3::add(c, p);
  c = vec3::mul(c, 1.0 / static_cast<double>(std::max<std::size_t>(1, m.points.size())));
  double cov[3][3] = {};
  for (const P3& p : m.points) {
    const P3 d = vec3::sub(p, c);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) cov[i][j] += d[i] * d[j];
  }
  P3 v{1, 0.7, 0.3};
  for (int it = 0; it < 32; ++it) {
    P3 w{0, 0, 0};
    for (int i = 0; i < 3; ++i) w[i] = cov[i][0] * v[0] + cov[i][1] * v[1] + cov[i][2] * v[2];
    const double n = vec3::norm(w);
    if (!(n > 0)) return {0, 0, 0};
    v = vec3::mul(w, 1.0 / n);
  }
  return v;
}

// The base and what the fill needs of it and of the elements.
struct FillState {
  const ElementMesh& base;
  std::vector<P3> vn, fn;
  TriangleDistance tree;
  CellGrid<int> near;  // element vertices tagged with their element, cells of 2 radii
  std::vector<P3> axis;
  FillState(const ElementMesh& b, double radius) : base(b), vn(vertex_normals(b)), fn(face_normals(b)), tree(b), near(2 * radius) {}
  void add_element(const ElementMesh& m, int id) {
    axis.push_back(long_axis(m));
    for (const P3& p : m.points) near.add(p, id);
  }
};

// The tangent direction at `c` (normal n) of `up`, else of the nearest
// element's long axis within about two radii, else of the face's first edge.
P3 local_direction(const FillState& s, const P3& c, const P3& n, const P3& edge, const P3& up) {
  double best = std::numeric_limits<double>::infinity();
  int id = -1;
  s.near.any_near(c, [&](const P3& q, int e) {
    const double d = vec3::dot(vec3::sub(q, c), vec3::sub(q, c));
    if (d < best) best = d, id = e;
    return false;
  });
  for (const P3& a : {up, id >= 0 ? s.axis[static_cast<std::size_t>(id)] : edge, edge}) {
    const P3 t = vec3::sub(a, vec3::mul(n, vec3::dot(a, n)));
    const double l = vec3::norm(t);
    if (l > 1e-6 * vec3::norm(a)) return vec3::mul(t, 1.0 / l);
  }
  return {0, 0, 0};
}

// Template point q's offset in the plane spanned by (e1, e2), scaled.
P3 planar_offset(const EmbeddedFillOptions& o, const P3& q, const P3& e1, const P3& e2) {
  return vec3::add(vec3::mul(e1, o.scale * q[0]), vec3::mul(e2, o.scale * q[1]));
}

// Whether a point `d` off its foot (`along` the foot face's normal fn) lies
// beside it more than over it: past an open border (or a rim), where it
// would be squashed onto the border.
bool beside_foot(const EmbeddedFillOptions& o, const P3& d, const P3& fn, double along) {
  return vec3::norm(vec3::sub(d, vec3::mul(fn, along))) > std::max(1e-9 * o.radius, std::abs(along));
}

// One placement of `tpl` at `c` in the frame (e1, e2, n): the planar points
// projected to the base and lifted; false when a foot's face leaves the
// normal cone, a point lies beside its foot rather than over it (past an
// open border) or an edge is over its bound. `feet` gets the feet.
bool place(const FillState& s, const EmbeddedFillOptions& o, const ElementMesh& tpl, const P3& c, const P3& e1,
           const P3& e2, const P3& n, double cos_max, ElementMesh& m, std::vector<P3>& feet) {
  m.tris = tpl.tris;
  m.points.resize(tpl.points.size());
  feet.resize(tpl.points.size());
  int hint = -1;
  for (std::size_t v = 0; v < tpl.points.size(); ++v) {
    const P3& q = tpl.points[v];
    const P3 x = vec3::add(c, planar_offset(o, q, e1, e2));
    const TriangleDistance::Hit h = s.tree.closest(x, hint);
    if (h.tri < 0) return false;
    const P3& fn = s.fn[static_cast<std::size_t>(h.tri)];
    if (vec3::dot(fn, n) < cos_max) return false;
    const P3 d = vec3::sub(x, h.point);
    if (beside_foot(o, d, fn, vec3::dot(d, fn))) return false;
    hint = h.tri;
    const Tri& t = s.base.tris[static_cast<std::size_t>(h.tri)];
    P3 nv{0, 0, 0};
    for (int k = 0; k < 3; ++k) nv = vec3::add(nv, vec3::mul(s.vn[static_cast<std::size_t>(t[k])], h.bary[k]));
    const double l = vec3::norm(nv);
    if (!(l > 0)) return false;
    feet[v] = h.point;
    m.points[v] = vec3::add(h.point, vec3::mul(nv, (q[2] - o.z0) * o.scale / l));
  }
  const double lim2 = o.max_stretch * o.max_stretch * o.scale * o.scale;
  for (const Tri& t : tpl.tris)
    for (int k = 0; k < 3; ++k) {
      const std::size_t a = static_cast<std::size_t>(t[k]), b = static_cast<std::size_t>(t[(k + 1) % 3]);
      const P3 d0 = vec3::sub(tpl.points[a], tpl.points[b]), d1 = vec3::sub(m.points[a], m.points[b]);
      const double l1 = vec3::dot(d1, d1);
      if (l1 > lim2 * vec3::dot(d0, d0) || (o.max_edge > 0 && l1 > o.max_edge * o.max_edge)) return false;
    }
  return true;
}

// One rigid copy of `tpl` at `c` in the frame (e1, e2, n), rested on the
// base: lifted along n until no vertex lies below its height over the base
// (measured to its closest point); false when a foot's face leaves the normal
// cone, a vertex lies beside its foot (past an open border) or floats more
// than max_float over its height. `feet` gets the feet.
bool place_rigid(const FillState& s, const EmbeddedFillOptions& o, const ElementMesh& tpl, const P3& c, const P3& e1,
                 const P3& e2, const P3& n, double cos_max, ElementMesh& m, std::vector<P3>& feet) {
  m.tris = tpl.tris;
  m.points.resize(tpl.points.size());
  feet.resize(tpl.points.size());
  const double eps = 1e-3 * o.radius;  // off the base, so that resting on it is no crossing
  double rest = 0;
  for (int pass = 0; pass < 2; ++pass) {
    int hint = -1;
    double sink = 0;
    for (std::size_t v = 0; v < tpl.points.size(); ++v) {
      const P3& q = tpl.points[v];
      const double height = (q[2] - o.z0) * o.scale;
      const P3 x = vec3::add(c, vec3::add(planar_offset(o, q, e1, e2), vec3::mul(n, height + rest)));
      const TriangleDistance::Hit h = s.tree.closest(x, hint);
      if (h.tri < 0) return false;
      hint = h.tri;
      const P3& fn = s.fn[static_cast<std::size_t>(h.tri)];
      const P3 d = vec3::sub(x, h.point);
      const double along = vec3::dot(d, fn);
      sink = std::max(sink, height + eps - along);
      if (pass == 0) continue;
      if (vec3::dot(fn, n) < cos_max) return false;
      if (beside_foot(o, d, fn, along)) return false;
      if (along - height > o.max_float + eps) return false;
      feet[v] = h.point;
      m.points[v] = x;
    }
    rest += std::max(0.0, sink);
  }
  return true;
}

}  // namespace

EmbeddedFillResult fill_embedded_bare(const ElementMesh& base, std::vector<ElementMesh>& els,
                                      const EmbeddedFillOptions& opt) {
  check_options(opt);
  EmbeddedFillResult res;
  if (opt.templates.empty() || base.tris.empty()) return res;
  FillState s(base, opt.radius);
  for (std::size_t e = 0; e < els.size(); ++e) s.add_element(els[e], static_cast<int>(e));
  std::vector<P3> pts;
  for (const ElementMesh& m : els) pts.insert(pts.end(), m.points.begin(), m.points.end());
  FootGrid feet = feet_on_base(s.tree, pts, opt.radius);
  ElementCollider coll(els, {});
  // Rigid copies must not cross the base either (exact, as between elements).
  const ElementCollider base_coll = opt.rigid ? ElementCollider({base}, {}) : ElementCollider({}, {});
  std::mt19937_64 rng(opt.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double cos_max = std::cos(opt.max_normal_angle_deg * kPi / 180.0);
  ElementMesh m;
  std::vector<P3> placed_feet;
  for (std::size_t f = 0; f < base.tris.size(); ++f) {
    const Tri& t = base.tris[f];
    const P3 &a = base.points[static_cast<std::size_t>(t[0])], &b = base.points[static_cast<std::size_t>(t[1])],
             &c2 = base.points[static_cast<std::size_t>(t[2])];
    if (bare_samples_of(a, b, c2, feet) == 0) continue;
    const P3 n = s.fn[f];
    if (!(vec3::norm(n) > 0)) continue;
    ++res.faces_tried;
    const P3 c{(a[0] + b[0] + c2[0]) / 3, (a[1] + b[1] + c2[1]) / 3, (a[2] + b[2] + c2[2]) / 3};
    const P3 d = local_direction(s, c, n, vec3::sub(b, a), opt.up);
    if (!(vec3::norm(d) > 0)) continue;
    bool ok = false;
    for (int k = 0; k < opt.attempts && !ok; ++k) {
      const ElementMesh& tpl = opt.templates[static_cast<std::size_t>(rng() % opt.templates.size())];
      // Quarter turns at the centroid first, then moved by up to a radius.
      const int turn = opt.turns == 1 ? 0 : k & 3;
      const P3 e1 = (turn & 1) ? vec3::cross(n, d) : d, e1s = (turn & 2) ? vec3::mul(e1, -1.0) : e1;
      const P3 e2 = vec3::cross(n, e1s);
      P3 at = c;
      if (k >= opt.turns) {  // (the draws named, so their order is fixed: a call's arguments have none)
        const double along_e2 = unit(rng), along_e1 = unit(rng);
        at = vec3::add(c, vec3::add(vec3::mul(e1s, opt.radius * along_e1), vec3::mul(e2, opt.radius * along_e2)));
      }
      if (opt.rigid) {
        if (!place_rigid(s, opt, tpl, at, e1s, e2, n, cos_max, m, placed_feet)) continue;
        if (base_coll.any_hit(m, -1, 0) || coll.any_hit(m, -1, opt.clearance)) continue;
      } else {
        if (!place(s, opt, tpl, at, e1s, e2, n, cos_max, m, placed_feet)) continue;
        if (coll.any_hit(m, -1, opt.clearance)) continue;
        if (element_self_crossings(m, false).size() > opt.own_crossings) continue;
      }
      ok = true;
    }
    if (!ok) continue;
    const int id = static_cast<int>(els.size());
    coll.add(m, id);
    s.add_element(m, id);
    for (const P3& p : placed_feet) feet.add(p);
    els.push_back(m);
    ++res.placed;
  }
  return res;
}

}  // namespace surftex
