// SPDX-License-Identifier: AGPL-3.0-or-later
// The constraints file of a material-space mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "texture/material_space/material_constraints.h"
#include "geometry/mesh.h"
#include "geometry/mesh_util.h"
#include "geometry/primitive_meshes.h"

namespace surftex {
namespace {

std::string error_of(const std::string& text, const Mesh& m) {
  try {
    parse_material_constraints(text, m, "c.json");
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(MaterialConstraints, ParsesEveryKind) {
  Mesh m;
  make_grid(m, 10, 10, 1.0, 1.0);  // z = 0, [0,1]^2, 200 faces
  const std::string text = R"({
    "effect_radius": 0.3,
    "strokes": [
      {"faces": [3, 4], "direction": [0, 1, 0]},
      {"polyline": [[0.05, 0.52, 0], [0.95, 0.52, 0]]}
    ],
    "scale": [{"point": [0.0, 0.0, 0.1], "value": 0.05}],
    "material": [{"point": [1.0, 1.0, 0], "value": 1}, {"point": [0.98, 0.99, 0], "value": 0.5}]
  })";
  const MaterialConstraints c = parse_material_constraints(text, m, "c.json");
  EXPECT_DOUBLE_EQ(c.effect_radius, 0.3);
  EXPECT_EQ(c.strokes, 2u);
  ASSERT_GE(c.directions.size(), 2u + 6u);  // two faces + about one face per mean edge length
  EXPECT_EQ(c.directions[0].face, 3u);
  EXPECT_EQ(c.directions[1].face, 4u);
  for (std::size_t i = 2; i < c.directions.size(); ++i) {
    EXPECT_DOUBLE_EQ(c.directions[i].direction[0], 1.0);  // the unit tangent
    EXPECT_DOUBLE_EQ(c.directions[i].direction[1], 0.0);
    // The polyline's faces lie in the row around y = 0.52.
    const auto vs = face_vertices(m, FaceIndex(c.directions[i].face));
    double y = 0;
    for (VertexIndex v : vs) y += m.point(v).y() / 3;
    EXPECT_NEAR(y, 0.52, 0.1);
  }
  ASSERT_EQ(c.scale.size(), 1u);
  EXPECT_EQ(m.point(VertexIndex(c.scale[0].vertex)), Point3(0, 0, 0));
  EXPECT_DOUBLE_EQ(c.scale[0].value, 0.05);
  ASSERT_EQ(c.material.size(), 1u);  // both points snap to the corner vertex: the later wins
  EXPECT_EQ(m.point(VertexIndex(c.material[0].vertex)), Point3(1, 1, 0));
  EXPECT_DOUBLE_EQ(c.material[0].value, 0.5);
  EXPECT_TRUE(std::is_sorted(c.seed_vertices.begin(), c.seed_vertices.end()));
  EXPECT_GE(c.seed_vertices.size(), 6u);
  // Empty file content: nothing constrained, whole mesh.
  const MaterialConstraints e = parse_material_constraints("{}", m);
  EXPECT_TRUE(e.directions.empty() && e.seed_vertices.empty());
  EXPECT_TRUE(std::isinf(e.effect_radius));
}

TEST(MaterialConstraints, ErrorsNameLineAndField) {
  Mesh m;
  make_grid(m, 4, 4);
  EXPECT_NE(error_of("{\n \"strokes\": [\n  {\"faces\": [1, 9000],\n   \"direction\": [1,0,0]}]}", m)
                .find("c.json: line 3: field strokes[0].faces[1]: face 9000 out of range (32 faces)"),
            std::string::npos)
      << error_of("{\n \"strokes\": [\n  {\"faces\": [1, 9000],\n   \"direction\": [1,0,0]}]}", m);
  EXPECT_NE(error_of("{\n\n \"scale\": [{\"point\": [0,0,0],\n  \"value\": -1}]}", m)
                .find("c.json: line 4: field scale[0].value: must be a number in ["),
            std::string::npos)
      << error_of("{\n\n \"scale\": [{\"point\": [0,0,0],\n  \"value\": -1}]}", m);
  EXPECT_NE(error_of("{\"material\": [{\"point\": [0,0], \"value\": 1}]}", m).find("c.json: line 1: field material[0].point: must be an array of 3"),
            std::string::npos);
  EXPECT_NE(error_of("{\n \"strokez\": []}", m).find("c.json: line 2: field strokez: unknown field"), std::string::npos)
      << error_of("{\n \"strokez\": []}", m);
  EXPECT_NE(error_of("{\"strokes\": [{\"polyline\": [[0,0,0]]}]}", m).find("field strokes[0].polyline: needs at least 2 points"),
            std::string::npos);
  EXPECT_NE(error_of("{\"strokes\": [{\"faces\": [1]}]}", m).find("field strokes[0].direction: missing"), std::string::npos);
  EXPECT_NE(error_of("{\"effect_radius\": 0}", m).find("field effect_radius: must be a finite number > 0"), std::string::npos);
  EXPECT_NE(error_of("{\n\"scale\": [\n{\"point\" [0,0,0]}]}", m).find("c.json: line 3: field scale[0]"), std::string::npos)
      << error_of("{\n\"scale\": [\n{\"point\" [0,0,0]}]}", m);
  EXPECT_NE(error_of("{\n\"scale\": [\n{\"point\" [0,0,0]}]}", m).find("malformed JSON"), std::string::npos);
  EXPECT_THROW(read_material_constraints("/nonexistent/c.json", m), IOError);
}

}  // namespace
}  // namespace surftex
