// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Splitting polygons that visit a vertex more than once ("pinched") into
// simple cycles, in time linear in the number of corners (issue 21 item 5).
// CGAL 5.5's split_pinched_polygons_in_polygon_soup is quadratic in the
// corners (figure: docs/decisions/603); this runs before it (soup_to_mesh).
//
// Walks the corners keeping a stack of the current path; when a vertex
// already on the stack comes again, the cycle from its earlier position to
// the top becomes a polygon of its own and the path continues from that
// vertex. Cycles with fewer than 3 corners bound no area and are dropped
// (counted). Polygons without a repeated vertex are left as they are, in
// place; the new polygons are appended at the end of `polygons`.

#include <cstddef>
#include <vector>

namespace surftex {

struct PinchedSplitCounts {
  std::size_t polygons_split = 0;     ///< polygons that had a repeated vertex
  std::size_t polygons_added = 0;     ///< new polygons appended
  std::size_t cycles_dropped = 0;     ///< cycles of 1 or 2 corners dropped
};

/// `points` is the number of points the indices refer to (all < points).
PinchedSplitCounts split_pinched_polygons(std::vector<std::vector<std::size_t>>& polygons, std::size_t points);

}  // namespace surftex
