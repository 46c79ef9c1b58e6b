// SPDX-License-Identifier: AGPL-3.0-or-later
// Regression tests for issue 21 (reliability under hostile input): the
// material-space constraints parser's depth, range and work limits.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "test_support.h"
#include "texture/material_space/material_constraints.h"

using namespace surftex;

namespace {
std::string constraint_error(const std::string& text, const Mesh& m) {
  try {
    parse_material_constraints(text, m, "c.json");
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  return "(no error)";
}
}  // namespace

// A polyline point at 1e200 overflowed a squared distance: SIGSEGV. A scale
// point at 1e308 gave "constraint vertex 4294967295 out of range".
TEST(HostileConstraints, PointsFarOutsideTheMeshAreRefusedNamingLineAndField) {
  Mesh m;
  make_icosphere(m, 2);
  const std::string far = constraint_error("{\n\"strokes\": [{\"polyline\": [[0,0,0],\n [1e200,0,0]]}]}", m);
  EXPECT_EQ(far.rfind("c.json: line 3: field strokes[0].polyline[1]: coordinate 1e+200 is far outside the mesh", 0), 0u)
      << far;
  const std::string scale = constraint_error("{\"scale\": [{\"point\": [1e308, 0, 0], \"value\": 1}]}", m);
  EXPECT_EQ(scale.rfind("c.json: line 1: field scale[0].point: coordinate", 0), 0u) << scale;
  const std::string neg = constraint_error("{\"material\": [{\"point\": [0, -1e308, 0], \"value\": 1}]}", m);
  EXPECT_NE(neg.find("field material[0].point: coordinate"), std::string::npos) << neg;
  // A point just outside the mesh's box is fine (it snaps to the nearest vertex).
  EXPECT_NO_THROW(parse_material_constraints("{\"material\": [{\"point\": [1.5, 0, 0], \"value\": 1}]}", m));
}

// A mesh at 1e154 (passes repair) made the distances overflow too.
TEST(HostileConstraints, AMeshNearTheDoubleRangeIsHandledInItsOwnFrame) {
  Mesh m;
  make_icosphere(m, 1, 1e154);
  const MaterialConstraints c = parse_material_constraints(
      "{\"strokes\": [{\"polyline\": [[-1e154,0,0],[1e154,0,0]]}], \"material\": [{\"point\": [0,0,1e154], \"value\": 1}]}",
      m);
  EXPECT_FALSE(c.directions.empty());
  ASSERT_EQ(c.material.size(), 1u);
  EXPECT_LT(c.material[0].vertex, m.num_vertices());
  for (const auto& d : c.directions)
    for (double x : d.direction) EXPECT_TRUE(std::isfinite(x));
}

// A value nested 100,000 deep in a field whose message printed it: SIGSEGV.
TEST(HostileConstraints, DeepNestingIsRefusedBeforeRecursion) {
  Mesh m;
  make_icosphere(m, 1);
  for (int depth : {40, 10000, 100000}) {
    const std::string text = "{\"strokes\": [{\"faces\": " + std::string(depth, '[') + std::string(depth, ']') +
                             ", \"direction\": [1,0,0]}]}";
    const std::string e = constraint_error(text, m);
    EXPECT_NE(e.find("c.json: line 1: field strokes[0].faces"), std::string::npos) << e.substr(0, 200);
    EXPECT_NE(e.find("nested deeper than 32 levels"), std::string::npos) << e.substr(0, 200);
    EXPECT_LT(e.size(), 300u);
  }
  // Depth that the format allows but a field does not want: named, not printed.
  const std::string e = constraint_error("{\"strokes\": [{\"faces\": [[[[[1]]]]], \"direction\": [1,0,0]}]}", m);
  EXPECT_NE(e.find("field strokes[0].faces[0]: must be an integer, got an array of 1 elements"), std::string::npos) << e;
}

// 23 refusals were raw JSON-library text ("number overflow parsing '1e400'").
TEST(HostileConstraints, MalformedJsonAndOverflowsAreOurOwnWords) {
  Mesh m;
  make_icosphere(m, 1);
  const std::vector<std::pair<std::string, std::string>> cases{
      {"{\n\"scale\": [{\"point\": [0,0,0], \"value\": 1e400}]}", "c.json: line 2: field scale[0].value: number 1e400 is out of range"},
      {"{\"strokes\": [{\"faces\": [1,, 2]}]}", "c.json: line 1: field strokes[0].faces[1]: malformed JSON: unexpected ','"},
      {"{\"strokes\": [", "c.json: line 1: field strokes[0]: malformed JSON: the file ends before the value is complete"},
      {"{\n\n\"a\" 1}", "c.json: line 3: field a: malformed JSON"},
      {"[1, 2]", "c.json: line 1: field (top level): must be an object, got an array of 2 elements"},
      {"{\"strokes\": [{\"faces\": [1e300], \"direction\": [1,0,0]}]}", "field strokes[0].faces[0]: must be an integer, got 1.0000000000000001e+300"},
      {"{\"strokes\": [{\"faces\": [18446744073709551615], \"direction\": [1,0,0]}]}", "face 18446744073709551615 out of range"},
      {"{\"strokes\": [{\"faces\": [-1], \"direction\": [1,0,0]}]}", "face -1 out of range"},
      {"{\"strokes\": [{\"faces\": [1], \"direction\": [1e308, 1e308, 0]}]}", "(no error)"},
      {"{\"scale\": [{\"point\": [0,0,0], \"value\": 1e300}]}", "field scale[0].value: must be a number in ["},
      {"{\"" + std::string(5000, 'k') + "\": 1}", "field kkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkkk...: unknown field"},
  };
  // A UTF-8 byte-order mark is skipped (the JSON reader's own rule), not eaten with a field.
  EXPECT_EQ(constraint_error("\xEF\xBB\xBF{\"material\": [{\"point\": [0,0,1], \"value\": 1}]}", m), "(no error)");
  for (const auto& [text, expect] : cases) {
    const std::string e = constraint_error(text, m);
    EXPECT_NE(e.find(expect), std::string::npos) << "input " << text.substr(0, 80) << "\ngot " << e;
    EXPECT_EQ(e.find("json.exception"), std::string::npos) << e;
    EXPECT_EQ(e.find("parse error"), std::string::npos) << e;
    EXPECT_LT(e.size(), 400u) << e;
  }
}

// `[[0,0,0],[1e7,0,0]]` on a unit mesh ran 48 s: the work is now bounded by
// the mesh (at most two samples per face over all strokes), and a point is
// refused when it is far outside the mesh.
TEST(HostileConstraints, PolylineWorkIsBoundedByTheMesh) {
  Mesh m;
  make_icosphere(m, 3);  // 1280 faces
  const MaterialConstraints c =
      parse_material_constraints("{\"strokes\": [{\"polyline\": [[-3,0,0],[3,0,0],[-3,0.01,0],[3,0.01,0]]}]}", m);
  EXPECT_LE(c.directions.size(), m.number_of_faces());
  EXPECT_GT(c.directions.size(), 5u);
  std::string many = "{\"strokes\": [{\"polyline\": [";
  for (int i = 0; i < 20000; ++i) many += std::string(i ? "," : "") + "[" + (i % 2 ? "3" : "-3") + ",0," + std::to_string(i * 1e-5) + "]";
  many += "]}]}";
  const MaterialConstraints d = parse_material_constraints(many, m);  // 20000 segments across the mesh: quick
  EXPECT_LE(d.directions.size(), m.number_of_faces());
  EXPECT_NE(constraint_error("{\"strokes\": [{\"polyline\": [[0,0,0],[1e7,0,0]]}]}", m).find("far outside the mesh"),
            std::string::npos);
}

TEST(HostileConstraints, OversizedFilesAreRefusedBeforeReading) {
  const std::string dir = test::temp_dir("constraints_big");
  {
    std::ofstream f(dir + "/big.json", std::ios::binary);
    f << "{\"strokes\": [";
    const std::string chunk(1 << 20, ' ');
    for (int i = 0; i < 17; ++i) f << chunk;
    f << "]}";
  }
  Mesh m;
  make_icosphere(m, 1);
  try {
    read_material_constraints(dir + "/big.json", m);
    FAIL() << "no error";
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("more than the 16777216"), std::string::npos) << e.what();
  }
}

