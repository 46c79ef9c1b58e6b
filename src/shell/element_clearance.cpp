// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/element_clearance.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <iterator>
#include <limits>
#include <memory>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"

namespace surftex {
namespace {
using Triangle3 = Kernel::Triangle_3;
using Iterator = std::vector<Triangle3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Point3 pt(const P3& p) { return Point3(p[0], p[1], p[2]); }

// (sign * infinity) in each coordinate: the corners of a box holding everything.
P3 collider_corner(double sign) {
  const double i = sign * std::numeric_limits<double>::infinity();
  return {i, i, i};
}

// Whether the bounding box of triangle t meets the box [lo, hi] (closed).
bool meets_box(const ElementMesh& m, const Tri& t, const P3& lo, const P3& hi) {
  for (int k = 0; k < 3; ++k) {
    const double a = m.points[static_cast<std::size_t>(t[0])][k], b = m.points[static_cast<std::size_t>(t[1])][k],
                 c = m.points[static_cast<std::size_t>(t[2])][k];
    if (std::max({a, b, c}) < lo[k] || std::min({a, b, c}) > hi[k]) return false;
  }
  return true;
}

// One batch of triangles (a tree is built once; later additions get their own).
struct Batch {
  std::vector<Triangle3> tris;
  std::vector<int> element;
  Tree tree;
  void build() {
    if (tris.empty()) return;
    tree.insert(tris.cbegin(), tris.cend());
    tree.build();
  }
  // Squared distance from p to the nearest triangle if it is below c2 (the
  // box of half-side c around p meets some triangle's box first), else c2.
  // (No kd-tree of distance hints: most points are far from every triangle,
  // and the box test settles them; the hint is a corner of a triangle the box meets.)
  double near2(const Point3& p, double c, double c2) const {
    const CGAL::Bbox_3 box(p.x() - c, p.y() - c, p.z() - c, p.x() + c, p.y() + c, p.z() + c);
    const auto hit = tree.any_intersected_primitive(box);
    if (!hit) return c2;
    return std::min(c2, CGAL::squared_distance(p, tree.closest_point(p, (*hit)->vertex(0))));
  }
  void push(const ElementMesh& m, int id, const P3* lo = nullptr, const P3* hi = nullptr) {
    for (const Tri& t : m.tris) {
      if (lo && !meets_box(m, t, *lo, *hi)) continue;
      const Point3 a = pt(m.points[static_cast<std::size_t>(t[0])]), b = pt(m.points[static_cast<std::size_t>(t[1])]),
                   c = pt(m.points[static_cast<std::size_t>(t[2])]);
      if (CGAL::collinear(a, b, c)) continue;
      tris.emplace_back(a, b, c);
      element.push_back(id);
    }
  }
};

// Traversal of a batch's tree that stops at the first triangle of a counted
// element meeting the query; the element's tag is read before the exact
// triangle test, so the triangles of the query's own element (which touch it
// at shared corners, where the filtered predicates fall back to exact
// arithmetic) are never tested. Same answer as listing every intersected
// triangle and filtering the list.
template <class Counts>
struct CountedHit {
  using Node = CGAL::AABB_node<Tree::AABB_traits>;
  const Tree::AABB_traits& traits;
  const Batch& batch;
  const Counts& counts;
  bool found = false;
  CountedHit(const Tree::AABB_traits& tr, const Batch& b, const Counts& c) : traits(tr), batch(b), counts(c) {}
  bool go_further() const { return !found; }
  void intersection(const Triangle3& query, const Primitive& primitive) {
    if (!counts(batch.element[static_cast<std::size_t>(primitive.id() - batch.tris.cbegin())])) return;
    if (traits.do_intersect_object()(query, primitive)) found = true;
  }
  bool do_intersect(const Triangle3& query, const Node& node) const {
    return traits.do_intersect_object()(query, node.bbox());
  }
};
}  // namespace

struct ElementCollider::Impl {
  std::vector<std::unique_ptr<Batch>> batches;
};

ElementCollider::ElementCollider(const std::vector<ElementMesh>& elements, const std::vector<char>& use)
    : ElementCollider(elements, use, collider_corner(-1.0), collider_corner(1.0)) {}
ElementCollider::ElementCollider(const std::vector<ElementMesh>& elements, const std::vector<char>& use, const P3& lo,
                                 const P3& hi)
    : impl_(std::make_unique<Impl>()) {
  if (!use.empty() && use.size() != elements.size())
    throw InvalidInputError("ElementCollider: use has " + std::to_string(use.size()) + " entries for " +
                            std::to_string(elements.size()) + " elements");
  auto b = std::make_unique<Batch>();
  for (std::size_t e = 0; e < elements.size(); ++e)
    if (use.empty() || use[e]) b->push(elements[e], static_cast<int>(e), &lo, &hi);
  b->build();
  impl_->batches.push_back(std::move(b));
}
ElementCollider::~ElementCollider() = default;
ElementCollider::ElementCollider(ElementCollider&&) noexcept = default;
ElementCollider& ElementCollider::operator=(ElementCollider&&) noexcept = default;

void ElementCollider::add(const ElementMesh& m, int id) {
  auto b = std::make_unique<Batch>();
  b->push(m, id);
  b->build();
  if (!b->tris.empty()) impl_->batches.push_back(std::move(b));
}

double ElementCollider::nearest_distance(const std::vector<P3>& points, double limit) const {
  double best = limit * limit;
  for (const P3& p : points)
    for (const auto& b : impl_->batches)
      if (!b->tris.empty()) best = b->near2(pt(p), std::sqrt(best), best);
  return std::sqrt(best);
}

bool ElementCollider::empty() const {
  for (const auto& b : impl_->batches)
    if (!b->tris.empty()) return false;
  return true;
}

namespace {
// One triangle of hits(): near a collider triangle (clearance), or meeting
// one of a counted element.
template <class Counts>
bool triangle_hits(const ElementMesh& m, const Tri& tr, const std::vector<char>& near, int skip,
                   const std::vector<char>* dead, const Counts& counts,
                   const std::vector<std::unique_ptr<Batch>>& batches) {
  if (near[static_cast<std::size_t>(tr[0])] || near[static_cast<std::size_t>(tr[1])] || near[static_cast<std::size_t>(tr[2])])
    return true;
  const Point3 a = pt(m.points[static_cast<std::size_t>(tr[0])]), b = pt(m.points[static_cast<std::size_t>(tr[1])]),
               c = pt(m.points[static_cast<std::size_t>(tr[2])]);
  if (CGAL::collinear(a, b, c)) return false;
  const Triangle3 q(a, b, c);
  for (const auto& bt : batches) {
    if (bt->tris.empty()) continue;
    if (skip < 0 && !dead) {
      if (bt->tree.do_intersect(q)) return true;
      continue;
    }
    CountedHit<Counts> traits(bt->tree.traits(), *bt, counts);
    bt->tree.traversal(q, traits);
    if (traits.found) return true;
  }
  return false;
}
}  // namespace

// hits() and any_hit(): each vertex and each triangle tested on its own (the
// trees are only read), in parallel; the answer does not depend on the thread
// count. With `first`, triangles after a hit is known are skipped (their
// entries left 0; only "any" is then meaningful: which triangles were tested
// depends on the threads, the answer does not).
std::vector<char> ElementCollider::collide(const ElementMesh& m, int skip, double clearance, const std::vector<char>* dead,
                                           bool first) const {
  auto counts = [&](int tag) {
    if (tag == skip && skip >= 0) return false;
    return !(dead && tag >= 0 && static_cast<std::size_t>(tag) < dead->size() && (*dead)[static_cast<std::size_t>(tag)]);
  };
  for (const Tri& tr : m.tris)
    for (int v : tr)
      if (v < 0 || static_cast<std::size_t>(v) >= m.points.size())
        throw InvalidInputError("ElementCollider::hits: vertex index " + std::to_string(v) + " out of range");
  std::vector<char> hit(m.tris.size(), 0);
  std::vector<char> near(m.points.size(), 0);
  if (clearance > 0 && skip < 0 && !dead)
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m.points.size(), 64), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t v = r.begin(); v < r.end(); ++v)
        for (const auto& b : impl_->batches) {
          if (b->tris.empty()) continue;
          if (b->near2(pt(m.points[v]), clearance, clearance * clearance) < clearance * clearance) {
            near[v] = 1;
            break;
          }
        }
    });
  std::atomic<bool> found{false};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m.tris.size(), 32), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t t = r.begin(); t < r.end(); ++t) {
      if (first && found.load(std::memory_order_relaxed)) return;
      hit[t] = triangle_hits(m, m.tris[t], near, skip, dead, counts, impl_->batches) ? 1 : 0;
      if (hit[t]) found.store(true, std::memory_order_relaxed);
    }
  });
  return hit;
}

std::vector<char> ElementCollider::hits(const ElementMesh& m, int skip, double clearance, const std::vector<char>* dead) const {
  return collide(m, skip, clearance, dead, false);
}

bool ElementCollider::any_hit(const ElementMesh& m, int skip, double clearance, const std::vector<char>* dead) const {
  const std::vector<char> hit = collide(m, skip, clearance, dead, true);
  return std::find(hit.begin(), hit.end(), 1) != hit.end();
}

std::vector<ElementMesh> trim_and_cap(const ElementMesh& m, const std::vector<char>& drop, int rings, std::size_t min_faces) {
  std::vector<ElementMesh> out;
  if (drop.size() != m.tris.size())
    throw InvalidInputError("trim_and_cap: drop has " + std::to_string(drop.size()) + " entries for " +
                            std::to_string(m.tris.size()) + " triangles");
  if (count_border_edges(m) != 0) return out;
  std::vector<char> gone = drop;
  for (int r = 0; r < rings; ++r) {
    std::vector<char> vgone(m.points.size(), 0);
    for (std::size_t t = 0; t < m.tris.size(); ++t)
      if (gone[t])
        for (int v : m.tris[t]) vgone[static_cast<std::size_t>(v)] = 1;
    for (std::size_t t = 0; t < m.tris.size(); ++t)
      for (int v : m.tris[t]) gone[t] = gone[t] || vgone[static_cast<std::size_t>(v)];
  }
  std::vector<int> kept;
  for (std::size_t t = 0; t < m.tris.size(); ++t)
    if (!gone[t]) kept.push_back(static_cast<int>(t));
  if (kept.empty()) return out;
  const ElementMesh part = extract_triangles(m, kept);
  std::vector<int> comp;
  const int nc = triangle_components(part, comp);
  std::vector<std::vector<int>> by(static_cast<std::size_t>(nc));
  for (std::size_t t = 0; t < comp.size(); ++t) by[static_cast<std::size_t>(comp[t])].push_back(static_cast<int>(t));
  for (const auto& ct : by) {
    if (ct.size() < std::max<std::size_t>(min_faces, 1)) continue;
    ElementMesh e = extract_triangles(part, ct);
    std::vector<std::vector<int>> loops;
    if (!boundary_loops(e, loops)) continue;
    bool ok = true;
    for (const std::vector<int>& l : loops) {
      if (l.size() < 3) {
        ok = false;
        break;
      }
      cap_loop(e, l);
    }
    if (ok && is_closed_oriented(e)) out.push_back(std::move(e));
  }
  return out;
}

bool is_compact_extent(double a, double b, double ratio) { return std::max(a, b) <= ratio * std::min(a, b); }

bool is_compact_element(const ElementMesh& m, double ratio) {
  if (m.points.empty()) return true;
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const P3& p : m.points)
    for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  return is_compact_extent(hi[0] - lo[0], hi[1] - lo[1], ratio);
}

double smallest_element_gap(const std::vector<ElementMesh>& elements, double limit) {
  if (elements.size() < 2) return 0;
  std::vector<std::array<double, 6>> box(elements.size());
  for (std::size_t e = 0; e < elements.size(); ++e) {
    box[e] = {1e300, 1e300, 1e300, -1e300, -1e300, -1e300};
    for (const P3& p : elements[e].points)
      for (int d = 0; d < 3; ++d) box[e][d] = std::min(box[e][d], p[d]), box[e][3 + d] = std::max(box[e][3 + d], p[d]);
  }
  double best = limit;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    // The other elements whose boxes come within `best` of this one's.
    std::vector<char> use(elements.size(), 0);
    bool any = false;
    for (std::size_t f = 0; f < elements.size(); ++f) {
      if (f == e) continue;
      bool near = true;
      for (int d = 0; d < 3; ++d)
        near = near && box[f][d] <= box[e][3 + d] + best && box[e][d] <= box[f][3 + d] + best;
      if (near) use[f] = 1, any = true;
    }
    if (!any) continue;
    const ElementCollider others(elements, use);
    if (others.empty()) continue;
    const std::vector<char> h = others.hits(elements[e], -1, 0.0);
    if (std::find(h.begin(), h.end(), 1) != h.end()) return 0;
    best = std::min(best, others.nearest_distance(elements[e].points, best));
  }
  return best;
}

}  // namespace surftex
