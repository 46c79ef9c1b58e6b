// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/embedded_fill.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "geometry/constants.h"
#include "geometry/errors.h"
#include "geometry/vec3.h"
#include "shell/element_clearance.h"
#include "shell/quilting/foot_grid.h"
#include "shell/quilting/quilt_coverage.h"
#include "shell/triangle_distance.h"

namespace surftex {

namespace {

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
  for (double f : o.smaller)
    if (!(f > 0 && f < 1)) bad("smaller factors must be in (0, 1)");
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

// A rigid template's proxy: at most ~48 of its vertices (evenly taken, and
// the extremes along each axis), placed first to reject a place cheaply:
// nearly every failed attempt fails on it already, and the full copy is
// checked whenever it passes (decision 102, session 46).
ElementMesh rigid_proxy(const ElementMesh& tpl) {
  ElementMesh p;
  const std::size_t n = tpl.points.size(), step = std::max<std::size_t>(1, n / 48);
  std::vector<char> take(n, 0);
  for (std::size_t v = 0; v < n; v += step) take[v] = 1;
  for (int d = 0; d < 3 && n > 0; ++d) {
    std::size_t lo = 0, hi = 0;
    for (std::size_t v = 1; v < n; ++v) {
      if (tpl.points[v][d] < tpl.points[lo][d]) lo = v;
      if (tpl.points[v][d] > tpl.points[hi][d]) hi = v;
    }
    take[lo] = take[hi] = 1;
  }
  for (std::size_t v = 0; v < n; ++v)
    if (take[v]) p.points.push_back(tpl.points[v]);
  return p;
}

// One fill: the base's state, the elements placed so far (their feet and
// exact collider) and the generator, over passes at decreasing sizes.
class Filler {
 public:
  Filler(const ElementMesh& base, std::vector<ElementMesh>& els, const EmbeddedFillOptions& opt)
      : opt_(opt), po_(without_templates(opt)), s_(base, opt.radius), els_(els),
        feet_(feet_on_base(s_.tree, all_points(els), opt.radius)), coll_(els, {}),
        base_coll_(opt.rigid ? ElementCollider({base}, {}) : ElementCollider({}, {})), rng_(opt.seed),
        cos_max_(std::cos(opt.max_normal_angle_deg * kPi / 180.0)) {
    for (std::size_t e = 0; e < els.size(); ++e) s_.add_element(els[e], static_cast<int>(e));
    if (opt.rigid)
      for (const ElementMesh& tpl : opt.templates) proxies_.push_back(rigid_proxy(tpl));
  }

  // Every base face with a bare sample tried once, with templates scaled by
  // `factor` (rigid copies: their float bound and gap too).
  void pass(double factor, EmbeddedFillResult& res) {
    po_.scale = opt_.scale * factor, po_.max_float = opt_.max_float * factor, po_.clearance = opt_.clearance * factor;
    const ElementMesh& base = s_.base;
    for (std::size_t f = 0; f < base.tris.size(); ++f) {
      const Tri& t = base.tris[f];
      const P3 &a = base.points[static_cast<std::size_t>(t[0])], &b = base.points[static_cast<std::size_t>(t[1])],
               &c = base.points[static_cast<std::size_t>(t[2])];
      if (bare_samples_of(a, b, c, feet_) == 0 || !(vec3::norm(s_.fn[f]) > 0)) continue;
      ++res.faces_tried;
      if (!fill_face(f, a, b, c)) continue;
      add_placed();
      ++res.placed;
      if (factor < 1) ++res.placed_smaller;
    }
  }

 private:
  // Up to `attempts` placements on face f: quarter turns at its centroid
  // first, then moved by up to a radius; true with m_ placed.
  bool fill_face(std::size_t f, const P3& a, const P3& b, const P3& c2) {
    const P3 n = s_.fn[f];
    const P3 c{(a[0] + b[0] + c2[0]) / 3, (a[1] + b[1] + c2[1]) / 3, (a[2] + b[2] + c2[2]) / 3};
    const P3 d = local_direction(s_, c, n, vec3::sub(b, a), opt_.up);
    if (!(vec3::norm(d) > 0)) return false;
    for (int k = 0; k < opt_.attempts; ++k) {
      const std::size_t which = static_cast<std::size_t>(rng_() % opt_.templates.size());
      const int turn = opt_.turns == 1 ? 0 : k & 3;
      const P3 e1 = (turn & 1) ? vec3::cross(n, d) : d, e1s = (turn & 2) ? vec3::mul(e1, -1.0) : e1;
      const P3 e2 = vec3::cross(n, e1s);
      P3 at = c;
      if (k >= opt_.turns) {  // (the draws named, so their order is fixed: a call's arguments have none)
        const double along_e2 = unit_(rng_), along_e1 = unit_(rng_);
        at = vec3::add(c, vec3::add(vec3::mul(e1s, opt_.radius * along_e1), vec3::mul(e2, opt_.radius * along_e2)));
      }
      if (attempt(which, at, e1s, e2, n)) return true;
    }
    return false;
  }

  // One placement of template `which` at `at` in the frame (e1, e2, n):
  // rigid copies are placed as its proxy first (a cheap rejection), then
  // whole; both must cross nothing.
  bool attempt(std::size_t which, const P3& at, const P3& e1, const P3& e2, const P3& n) {
    const ElementMesh& tpl = opt_.templates[which];
    if (opt_.rigid) {
      if (!place_rigid(s_, po_, proxies_[which], at, e1, e2, n, cos_max_, proxy_, placed_feet_)) return false;
      if (!place_rigid(s_, po_, tpl, at, e1, e2, n, cos_max_, m_, placed_feet_)) return false;
      return !base_coll_.any_hit(m_, -1, 0) && !coll_.any_hit(m_, -1, po_.clearance);
    }
    if (!place(s_, po_, tpl, at, e1, e2, n, cos_max_, m_, placed_feet_)) return false;
    if (coll_.any_hit(m_, -1, po_.clearance)) return false;
    return element_self_crossings(m_, false).size() <= opt_.own_crossings;
  }

  static EmbeddedFillOptions without_templates(EmbeddedFillOptions o) {
    o.templates.clear();  // (each placement is given its template)
    return o;
  }
  static std::vector<P3> all_points(const std::vector<ElementMesh>& els) {
    std::vector<P3> pts;
    for (const ElementMesh& m : els) pts.insert(pts.end(), m.points.begin(), m.points.end());
    return pts;
  }

  void add_placed() {
    const int id = static_cast<int>(els_.size());
    coll_.add(m_, id);
    s_.add_element(m_, id);
    for (const P3& p : placed_feet_) feet_.add(p);
    els_.push_back(m_);
  }

  const EmbeddedFillOptions& opt_;
  EmbeddedFillOptions po_;  // opt_ with the pass's sizes (scale, max_float, clearance), no templates
  FillState s_;
  std::vector<ElementMesh>& els_;
  FootGrid feet_;
  ElementCollider coll_;
  const ElementCollider base_coll_;  // rigid copies must not cross the base either (exact)
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> unit_{-1.0, 1.0};
  double cos_max_;
  std::vector<ElementMesh> proxies_;
  ElementMesh m_, proxy_;
  std::vector<P3> placed_feet_;
};

}  // namespace

EmbeddedFillResult fill_embedded_bare(const ElementMesh& base, std::vector<ElementMesh>& els,
                                      const EmbeddedFillOptions& opt) {
  check_options(opt);
  EmbeddedFillResult res;
  if (opt.templates.empty() || base.tris.empty()) return res;
  Filler filler(base, els, opt);
  // The full size first everywhere, then (rigid copies) smaller ones where
  // it is still bare.
  filler.pass(1.0, res);
  if (opt.rigid)
    for (const double factor : opt.smaller) filler.pass(factor, res);
  return res;
}

}  // namespace surftex
