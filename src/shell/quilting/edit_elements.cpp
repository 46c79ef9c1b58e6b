// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/edit_elements.h"

#include <CGAL/boost/graph/Euler_operations.h>

#include <cstdio>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "shell/element_colors.h"
#include "shell/swatch.h"

namespace surftex {
namespace {

// One "ID=r,g,b" onto the vertices of element ID's faces.
void recolor_element(Mesh& m, const std::string& rc, int n) {
  const auto elem = find(m, kFaceElement).first;
  auto col = get_or_add(m, kVertexColor, Color3f{0.8f, 0.8f, 0.8f});
  int id = -1;
  float r = 0, g = 0, b = 0;
  int used = 0;
  if (std::sscanf(rc.c_str(), "%d=%f,%f,%f%n", &id, &r, &g, &b, &used) != 4 || used != static_cast<int>(rc.size()) ||
      id < 0 || id >= n)
    throw InvalidInputError("elements: --recolor wants ID=r,g,b with 0 <= ID < " + std::to_string(n) +
                            " and colours in [0,1] (got '" + rc + "')");
  for (float c : {r, g, b})
    if (!(c >= 0 && c <= 1)) throw InvalidInputError("elements: colour out of [0,1] in '" + rc + "'");
  for (FaceIndex f : m.faces())
    if (elem[f] == id)
      for (VertexIndex v : m.vertices_around_face(m.halfedge(f))) col[v] = {r, g, b};
}

// Removes the faces of the elements in `ids`; returns how many.
std::size_t remove_elements(Mesh& m, const std::vector<int>& ids, int n) {
  for (int id : ids)
    if (id < 0 || id >= n)
      throw InvalidInputError("elements: --remove id " + std::to_string(id) + " out of range 0.." + std::to_string(n - 1));
  if (ids.empty()) return 0;
  const auto elem = find(m, kFaceElement).first;
  std::vector<char> gone(static_cast<std::size_t>(n), 0);
  for (int id : ids) gone[id] = 1;
  std::size_t removed = 0;
  std::vector<FaceIndex> faces(m.faces().begin(), m.faces().end());
  for (FaceIndex f : faces)
    if (gone[elem[f]]) {
      CGAL::Euler::remove_face(m.halfedge(f), m);
      ++removed;
    }
  m.collect_garbage();
  return removed;
}

}  // namespace

EditElementsResult edit_elements(Mesh& m, const EditElementsOptions& opt) {
  EditElementsResult r;
  r.elements = label_elements(m);
  if (!find(m, kVertexColor).second) color_by_element(m, opt.seed);
  for (const std::string& rc : opt.recolor) recolor_element(m, rc, r.elements);
  r.faces_removed = remove_elements(m, opt.remove, r.elements);
  return r;
}

}  // namespace surftex
