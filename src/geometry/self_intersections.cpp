// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/self_intersections.h"

#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <iterator>
#include <utility>

#include "geometry/errors.h"
#include "geometry/mesh.h"

namespace surftex {

namespace PMP = CGAL::Polygon_mesh_processing;

namespace {
void check_triangles(const Mesh& mesh) {
  if (!CGAL::is_triangle_mesh(mesh))
    throw InvalidInputError("self_intersecting_faces: mesh has non-triangle faces (" +
                            std::to_string(mesh.number_of_faces()) + " faces)");
}

template <class FaceRange>
std::vector<FacePair> sorted_pairs(const FaceRange& faces, const Mesh& mesh,
                                   const SelfIntersectionOptions& opt) {
  std::vector<std::pair<FaceIndex, FaceIndex>> raw;
#if defined(CGAL_LINKED_WITH_TBB)
  if (opt.parallel)
    PMP::self_intersections<CGAL::Parallel_tag>(faces, mesh, std::back_inserter(raw));
  else
#endif
    PMP::self_intersections<CGAL::Sequential_tag>(faces, mesh, std::back_inserter(raw));
  std::vector<FacePair> out;
  out.reserve(raw.size());
  for (const auto& [a, b] : raw) {
    auto ia = static_cast<std::uint32_t>(a.idx()), ib = static_cast<std::uint32_t>(b.idx());
    out.push_back({std::min(ia, ib), std::max(ia, ib)});
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}
}  // namespace

std::vector<FacePair> self_intersecting_faces(const Mesh& mesh, const SelfIntersectionOptions& opt) {
  check_triangles(mesh);
  return sorted_pairs(faces(mesh), mesh, opt);
}

std::vector<FacePair> self_intersecting_faces(const Mesh& mesh, const std::vector<std::uint32_t>& faces,
                                              const SelfIntersectionOptions& opt) {
  check_triangles(mesh);
  std::vector<FaceIndex> range;
  range.reserve(faces.size());
  for (std::uint32_t f : faces) {
    if (f >= mesh.number_of_faces() + mesh.number_of_removed_faces() || mesh.is_removed(FaceIndex(f)))
      throw InvalidInputError("self_intersecting_faces: face " + std::to_string(f) + " is not in the mesh");
    range.push_back(FaceIndex(f));
  }
  return sorted_pairs(range, mesh, opt);
}

std::size_t count_self_intersections(const Mesh& mesh, const SelfIntersectionOptions& opt) {
  return self_intersecting_faces(mesh, opt).size();
}

}  // namespace surftex
