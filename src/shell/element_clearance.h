// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Interpenetration between quilted elements (issue 17; Zhou et al. 2006's
// elements keep their integrity, but 2.7 adds uncorresponded elements as
// they are). ElementCollider finds exact triangle-triangle hits (AABB tree,
// filtered exact predicates) and vertices within a clearance; trim_and_cap
// removes the hits plus rings and caps every cut loop with a fan.
// Throws InvalidInputError for indices out of range.
#include <cstddef>
#include <memory>
#include <vector>

#include "shell/element_mesh.h"

namespace surftex {

class ElementCollider {
 public:
  /// The triangles of elements[e] with use[e] != 0 (use empty: all), tagged
  /// with e. Degenerate triangles (collinear corners) are left out.
  ElementCollider(const std::vector<ElementMesh>& elements, const std::vector<char>& use);
  /// The same, keeping only the triangles whose bounding box meets the box
  /// [lo, hi]: exact for queries (with their clearance) inside that box.
  ElementCollider(const std::vector<ElementMesh>& elements, const std::vector<char>& use, const P3& lo, const P3& hi);
  ~ElementCollider();
  ElementCollider(ElementCollider&&) noexcept;
  ElementCollider& operator=(ElementCollider&&) noexcept;
  /// Per triangle of `m`: 1 if it intersects a collider triangle of another
  /// element than `skip` (-1: none), or (clearance > 0, no skip) a corner lies
  /// within `clearance` of one; elements in `dead` are ignored.
  std::vector<char> hits(const ElementMesh& m, int skip, double clearance, const std::vector<char>* dead = nullptr) const;
  /// Whether any triangle of `m` hits (as hits() would mark one), stopping
  /// at the first: for the tests that only accept or reject a placement.
  bool any_hit(const ElementMesh& m, int skip, double clearance, const std::vector<char>* dead = nullptr) const;
  /// Smallest distance from any of `points` to a triangle of the collider, or `limit` if none is closer.
  double nearest_distance(const std::vector<P3>& points, double limit) const;
  /// Adds the triangles of `m`, tagged `id` (so that later queries see it).
  void add(const ElementMesh& m, int id);
  bool empty() const;

 private:
  std::vector<char> collide(const ElementMesh& m, int skip, double clearance, const std::vector<char>* dead, bool first) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// `m` without the `drop` triangles and `rings` rings around them, split into
/// pieces; each piece of simple border loops is capped by fans and returned
/// if it had at least min_faces triangles and is closed and oriented. `m`
/// should be closed.
std::vector<ElementMesh> trim_and_cap(const ElementMesh& m, const std::vector<char>& drop, int rings, std::size_t min_faces);

/// An element is compact if the larger side of its xy bounding box is at
/// most `ratio` times the smaller one (a ring, a pebble; not a thread).
bool is_compact_element(const ElementMesh& m, double ratio = 2.5);
/// The same rule for an xy bounding box of sides a and b.
bool is_compact_extent(double a, double b, double ratio = 2.5);

/// The smallest distance between two different elements of `elements`
/// (vertex to triangle); 0 if there are fewer than two or two intersect;
/// at most `limit`.
double smallest_element_gap(const std::vector<ElementMesh>& elements, double limit);

}  // namespace surftex
