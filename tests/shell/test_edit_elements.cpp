// SPDX-License-Identifier: AGPL-3.0-or-later
// Editing geometric-texture elements by id (shell/quilting/edit_elements.h):
// ids in order of first face, recolouring, removal, refusals.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <array>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "shell/quilting/edit_elements.h"
#include "shell/quilting/quilt_json.h"

namespace surftex {
namespace {

// Three disjoint triangles (elements 0, 1, 2 in face order); element 1 has two
// faces sharing an edge.
Mesh three_elements() {
  Mesh m;
  auto tri = [&](double x) {
    return std::array<VertexIndex, 3>{m.add_vertex(Point3(x, 0, 0)), m.add_vertex(Point3(x + 1, 0, 0)),
                                      m.add_vertex(Point3(x, 1, 0))};
  };
  const auto a = tri(0);
  m.add_face(a[0], a[1], a[2]);
  const auto b = tri(3);
  m.add_face(b[0], b[1], b[2]);
  m.add_face(b[1], m.add_vertex(Point3(4, 1, 0)), b[2]);
  const auto c = tri(6);
  m.add_face(c[0], c[1], c[2]);
  return m;
}

std::string error_of(Mesh& m, const EditElementsOptions& o) {
  try {
    edit_elements(m, o);
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  return "";
}

TEST(EditElements, RecoloursTheElementsVerticesAndRemovesFacesById) {
  Mesh m = three_elements();
  EditElementsOptions o;
  o.recolor = {"1=1,0,0.5", "2=0,1,0"};
  o.remove = {0};
  const EditElementsResult r = edit_elements(m, o);
  EXPECT_EQ(r.elements, 3);
  EXPECT_EQ(r.faces_removed, 1u);
  EXPECT_EQ(m.number_of_faces(), 3u);
  const auto col = find(m, kVertexColor).first;
  const auto el = find(m, kFaceElement).first;
  int red = 0, green = 0;
  for (FaceIndex f : m.faces())
    for (VertexIndex v : m.vertices_around_face(m.halfedge(f))) {
      if (el[f] == 1) {
        EXPECT_EQ(col[v], (Color3f{1.f, 0.f, 0.5f}));
        ++red;
      }
      if (el[f] == 2) {
        EXPECT_EQ(col[v], (Color3f{0.f, 1.f, 0.f}));
        ++green;
      }
      EXPECT_NE(el[f], 0);
    }
  EXPECT_EQ(red, 6);
  EXPECT_EQ(green, 3);
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["elements"], 3);
  EXPECT_EQ(j["faces_removed"], 1);
}

TEST(EditElements, KeepsGivenColoursAndColoursAMeshWithoutThem) {
  Mesh plain = three_elements();
  edit_elements(plain, {});
  EXPECT_TRUE(find(plain, kVertexColor).second);  // coloured by element
  Mesh given = three_elements();
  get_or_add(given, kVertexColor, Color3f{0.25f, 0.5f, 0.75f});
  EditElementsOptions o;
  o.remove = {1};
  EXPECT_EQ(edit_elements(given, o).faces_removed, 2u);
  for (VertexIndex v : given.vertices()) EXPECT_EQ(find(given, kVertexColor).first[v], (Color3f{0.25f, 0.5f, 0.75f}));
}

TEST(EditElements, RefusesBadIdsAndColoursNamingTheOption) {
  Mesh m = three_elements();
  EditElementsOptions o;
  o.recolor = {"3=1,0,0"};
  EXPECT_EQ(error_of(m, o), "elements: --recolor wants ID=r,g,b with 0 <= ID < 3 and colours in [0,1] (got '3=1,0,0')");
  o.recolor = {"1=1,0"};
  EXPECT_NE(error_of(m, o).find("(got '1=1,0')"), std::string::npos);
  o.recolor = {"1=1,0,0x"};
  EXPECT_NE(error_of(m, o).find("(got '1=1,0,0x')"), std::string::npos);
  o.recolor = {"1=1,0,2"};
  EXPECT_EQ(error_of(m, o), "elements: colour out of [0,1] in '1=1,0,2'");
  o.recolor.clear();
  o.remove = {1, 3};
  EXPECT_EQ(error_of(m, o), "elements: --remove id 3 out of range 0..2");
  o.remove = {-1};
  EXPECT_EQ(error_of(m, o), "elements: --remove id -1 out of range 0..2");
  EXPECT_EQ(m.number_of_faces(), 4u);  // nothing removed by a refused edit
}

}  // namespace
}  // namespace surftex
