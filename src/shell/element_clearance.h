// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Interpenetration between quilted elements (issue 17). In Zhou et al. 2006
// the elements "keep their integrity" and do not pass through each other:
// where a new patch's element corresponds to an old one the two are merged
// (sections 2.5-2.7); an element that corresponds to none is added as it is
// (2.7, first rule), which on curved or re-covered ground can put it through
// an old element. ElementCollider finds such hits exactly (CGAL's
// triangle-triangle do_intersect over an AABB tree, Epick's filtered exact
// predicates) and, optionally, vertices closer than a clearance to another
// element (the swatch's own spacing; element-triangle distance through the
// tree); trim_and_cap removes the triangles that hit, plus rings around them,
// and closes every cut loop with a fan around its centroid, so that the
// remaining pieces are closed elements again.
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
  ~ElementCollider();
  ElementCollider(ElementCollider&&) noexcept;
  ElementCollider& operator=(ElementCollider&&) noexcept;
  /// Per triangle of `m`: 1 if it intersects a triangle of the collider whose
  /// element is not `skip` (-1: none skipped), or, with clearance > 0, if one
  /// of its corners lies within `clearance` of such a triangle; else 0.
  /// (With a skipped element the distance test is not made: its own
  /// triangles would be nearest.)
  /// `dead` (indexed by element tag; tags past its end count as alive):
  /// elements whose triangles are ignored.
  std::vector<char> hits(const ElementMesh& m, int skip, double clearance, const std::vector<char>* dead = nullptr) const;
  /// Smallest distance from any of `points` to a triangle of the collider, or `limit` if none is closer.
  double nearest_distance(const std::vector<P3>& points, double limit) const;
  /// Adds the triangles of `m`, tagged `id` (so that later queries see it).
  void add(const ElementMesh& m, int id);
  bool empty() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The triangles of `m` without those marked in `drop`, and without `rings`
/// rings of triangles around them (rings >= 0; a ring: the triangles sharing
/// a vertex with a removed one), split into connected pieces; each piece
/// whose border is a set of simple loops gets every loop closed by a fan
/// around the loop's centroid (a new vertex) and is returned if it has at
/// least min_faces triangles before capping and is closed and consistently
/// oriented after it. `m` should be closed (else no piece is returned).
std::vector<ElementMesh> trim_and_cap(const ElementMesh& m, const std::vector<char>& drop, int rings, std::size_t min_faces);

/// An element is compact if the larger side of its xy bounding box is at
/// most `ratio` times the smaller one (a ring, a pebble; not a thread).
bool is_compact_element(const ElementMesh& m, double ratio = 2.5);

/// The smallest distance between two different elements of `elements`
/// (vertex to triangle); 0 if there are fewer than two or two intersect;
/// at most `limit`.
double smallest_element_gap(const std::vector<ElementMesh>& elements, double limit);

}  // namespace surftex
