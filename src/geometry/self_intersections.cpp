// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/self_intersections.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>

#include <algorithm>
#include <iterator>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"

namespace surftex {

std::size_t count_self_intersections(const Mesh& mesh, std::vector<std::pair<int, int>>* pairs) {
  for (FaceIndex f : mesh.faces())
    if (mesh.degree(f) != 3)
      throw InvalidInputError("self intersections: face " + std::to_string(f.idx()) + " is not a triangle");
  std::vector<std::pair<FaceIndex, FaceIndex>> found;
  CGAL::Polygon_mesh_processing::self_intersections(mesh, std::back_inserter(found));
  if (pairs) {
    pairs->clear();
    for (const auto& [a, b] : found) {
      const int x = static_cast<int>(a.idx()), y = static_cast<int>(b.idx());
      pairs->emplace_back(std::min(x, y), std::max(x, y));
    }
    std::sort(pairs->begin(), pairs->end());
  }
  return found.size();
}

}  // namespace surftex
