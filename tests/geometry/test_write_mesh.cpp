// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

/// A 2x1 grid of quads split into 4 triangles, with per-corner UVs that have
/// a seam: the middle column of vertices gets u = 0.5 in the left quad's
/// triangles and u = 0.0 in the right ones. 6 vertices, 4 faces.
Mesh seamed_strip() {
  Mesh m;
  VertexIndex v[6];
  for (int i = 0; i < 6; ++i) v[i] = m.add_vertex(Point3(i % 3, i / 3, 0.1 * i));
  auto uv = get_or_add(m, kCornerUV);
  auto col = get_or_add(m, kVertexColor);
  for (int i = 0; i < 6; ++i) col[v[i]] = {i / 5.f, 1.f - i / 5.f, (i % 2) * 1.f};
  auto add = [&](int a, int b, int c, bool right) {
    FaceIndex f = m.add_face(v[a], v[b], v[c]);
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) {
      const Point3& p = m.point(m.target(h));
      double u = p.x() * 0.5;
      if (right && p.x() == 1.0) u = 0.0;
      uv[h] = {u, p.y() * 0.75};
    }
  };
  add(0, 1, 4, false);
  add(0, 4, 3, false);
  add(1, 2, 5, true);
  add(1, 5, 4, true);
  return m;
}

Image checker() {
  Image img(8, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = ((x + y) % 2) ? 1.f : (c == 0 ? 0.8f : 0.f);
  return img;
}

void expect_same_positions(const Mesh& a, const Mesh& b, double tol) {
  ASSERT_EQ(a.number_of_vertices(), b.number_of_vertices());
  ASSERT_EQ(a.number_of_faces(), b.number_of_faces());
  std::vector<std::array<double, 3>> pa, pb;
  for (auto v : a.vertices()) pa.push_back({a.point(v).x(), a.point(v).y(), a.point(v).z()});
  for (auto v : b.vertices()) pb.push_back({b.point(v).x(), b.point(v).y(), b.point(v).z()});
  std::sort(pa.begin(), pa.end());
  std::sort(pb.begin(), pb.end());
  for (std::size_t i = 0; i < pa.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(pa[i][c], pb[i][c], tol * (1 + std::abs(pa[i][c])));
}

}  // namespace

TEST(WriteMesh, RoundTripObjPlyOffOnRealMesh) {
  Mesh m;
  read_mesh(test::shared_data("meshes/elephant.off"), m);
  auto d = test::temp_dir("wm");
  for (std::string ext : {".obj", ".ply", ".off"}) {
    SCOPED_TRACE(ext);
    write_mesh(d + "/e" + ext, m);
    Mesh b;
    SoupRepairCounts c;
    read_mesh(d + "/e" + ext, b, {}, &c);
    EXPECT_EQ(c.input_points, m.number_of_vertices());
    EXPECT_EQ(c.input_polygons, m.number_of_faces());
    // PLY stores float; OBJ and OFF write shortest round-trip doubles.
    expect_same_positions(m, b, ext == ".ply" ? 1e-7 : 0.0);
  }
}

TEST(WriteMesh, PolygonsSurviveOff) {
  Mesh m;
  read_mesh(test::shared_data("meshes/double_torus_polygons.off"), m, {.triangulate = false});
  ASSERT_EQ(m.number_of_faces(), 220u);
  auto d = test::temp_dir("wm");
  write_mesh(d + "/p.off", m);
  write_mesh(d + "/p.ply", m);
  EXPECT_EQ(read_polygon_soup(d + "/p.off").polygons.size(), 220u);
  EXPECT_EQ(read_polygon_soup(d + "/p.ply").polygons.size(), 220u);
}

TEST(WriteMesh, PlyColoursAndScalarRoundTrip) {
  Mesh m = seamed_strip();
  auto s = m.add_property_map<VertexIndex, double>("v:material", 0.0).first;
  for (auto v : m.vertices()) s[v] = 0.25 * v.idx();
  auto d = test::temp_dir("wm");
  WriteMeshOptions opt;
  opt.vertex_scalar_property = "v:material";
  write_mesh(d + "/c.ply", m, opt);
  const std::string bytes = test::file_bytes(d + "/c.ply");
  EXPECT_NE(bytes.find("property float v:material"), std::string::npos);
  auto soup = read_polygon_soup(d + "/c.ply");
  ASSERT_EQ(soup.colors.size(), 6u);
  auto col = find(m, kVertexColor).first;
  for (auto v : m.vertices())
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(soup.colors[v.idx()][c], col[v][c], 0.5 / 255.0 + 1e-6);
  // Colours also reach the mesh through soup_to_mesh.
  Mesh b;
  read_mesh(d + "/c.ply", b);
  auto bc = find(b, kVertexColor);
  ASSERT_TRUE(bc.second);
  // A missing scalar property is refused and nothing is written.
  opt.vertex_scalar_property = "v:absent";
  EXPECT_THROW(write_mesh(d + "/x.ply", m, opt), InvalidInputError);
  EXPECT_FALSE(fs::exists(d + "/x.ply"));
}

TEST(WriteMesh, ObjUvsRoundTripWithDeduplicatedVt) {
  Mesh m = seamed_strip();
  auto d = test::temp_dir("wm");
  write_mesh(d + "/s.obj", m);
  const std::string text = test::file_bytes(d + "/s.obj");
  std::size_t vt = 0, pos = 0;
  while ((pos = text.find("\nvt ", pos)) != std::string::npos) ++vt, ++pos;
  // Distinct (u,v): (0,0) (0.5,0) (1,0) (0,0.75) (0.5,0.75) (1,0.75); the seam
  // vertices reuse values of other vertices, so 6 vt lines for 12 corners.
  EXPECT_EQ(vt, 6u);
  std::set<std::array<double, 2>> distinct;
  auto uv = find(m, kCornerUV).first;
  for (auto h : m.halfedges())
    if (!m.is_border(h)) distinct.insert({uv[h][0], uv[h][1]});
  EXPECT_EQ(vt, distinct.size());

  auto soup = read_polygon_soup(d + "/s.obj");
  ASSERT_EQ(soup.polygons.size(), 4u);
  ASSERT_EQ(soup.polygon_uvs.size(), 4u);
  Mesh b;
  SoupRepairCounts c;
  soup_to_mesh(soup, b, {}, &c);
  EXPECT_EQ(c.uv_corners, 12u);
  EXPECT_EQ(c.uv_corners_dropped, 0u);
  auto buv = find(b, kCornerUV);
  ASSERT_TRUE(buv.second);
  // Each corner's (position -> uv) in the read-back mesh matches the original.
  std::map<std::pair<std::array<double, 3>, std::array<double, 3>>, UV> orig;  // (face centroid, corner pos)
  auto key = [](const Mesh& mm, HalfedgeIndex h) {
    std::array<double, 3> cen{0, 0, 0};
    for (auto g : mm.halfedges_around_face(h)) {
      cen[0] += mm.point(mm.target(g)).x();
      cen[1] += mm.point(mm.target(g)).y();
      cen[2] += mm.point(mm.target(g)).z();
    }
    const Point3& p = mm.point(mm.target(h));
    return std::make_pair(cen, std::array<double, 3>{p.x(), p.y(), p.z()});
  };
  for (auto f : m.faces())
    for (auto h : m.halfedges_around_face(m.halfedge(f))) orig[key(m, h)] = uv[h];
  int matched = 0;
  for (auto f : b.faces())
    for (auto h : b.halfedges_around_face(b.halfedge(f))) {
      auto it = orig.find(key(b, h));
      ASSERT_NE(it, orig.end());
      EXPECT_EQ(buv.first[h], it->second);
      ++matched;
    }
  EXPECT_EQ(matched, 12);
}

TEST(WriteMesh, ObjWithTextureWritesMtlAndPngBesideIt) {
  Mesh m = seamed_strip();
  auto d = test::temp_dir("wm");
  Image tex = checker();
  WriteMeshOptions opt;
  opt.texture = &tex;
  write_mesh(d + "/tex.obj", m, opt);
  ASSERT_TRUE(fs::exists(d + "/tex.mtl"));
  ASSERT_TRUE(fs::exists(d + "/tex.png"));
  EXPECT_NE(test::file_bytes(d + "/tex.obj").find("mtllib tex.mtl"), std::string::npos);
  EXPECT_NE(test::file_bytes(d + "/tex.mtl").find("map_Kd tex.png"), std::string::npos);
  Image back = read_image(d + "/tex.png");
  EXPECT_EQ(back.width, 8);
  EXPECT_EQ(back.height, 4);
  EXPECT_NEAR(back.at(0, 0, 0), 0.8f, 1.f / 255);
  // Only our files in the folder: no temporaries left.
  int n = 0;
  for (auto& e : fs::directory_iterator(d)) (void)e, ++n;
  EXPECT_EQ(n, 3);
  // Refusing to overwrite leaves all three unchanged and adds nothing.
  opt.overwrite = false;
  EXPECT_THROW(write_mesh(d + "/tex.obj", m, opt), IOError);
}

TEST(WriteMesh, GlbParsesBackWithTinygltf) {
  Mesh m = seamed_strip();
  auto d = test::temp_dir("wm");
  Image tex = checker();
  WriteMeshOptions opt;
  opt.texture = &tex;
  write_mesh(d + "/s.glb", m, opt);

  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, d + "/s.glb")) << err;
  EXPECT_TRUE(err.empty()) << err;
  ASSERT_EQ(model.meshes.size(), 1u);
  ASSERT_EQ(model.meshes[0].primitives.size(), 1u);
  const auto& prim = model.meshes[0].primitives[0];
  for (const char* a : {"POSITION", "NORMAL", "TEXCOORD_0", "COLOR_0"})
    ASSERT_TRUE(prim.attributes.count(a)) << a;
  // 6 mesh vertices, the 2 on the seam split: 8 glTF vertices.
  const auto& pos = model.accessors[prim.attributes.at("POSITION")];
  EXPECT_EQ(pos.count, 8u);
  EXPECT_EQ(pos.type, TINYGLTF_TYPE_VEC3);
  ASSERT_EQ(pos.minValues.size(), 3u);
  EXPECT_FLOAT_EQ(pos.minValues[0], 0.f);
  EXPECT_FLOAT_EQ(pos.maxValues[0], 2.f);
  EXPECT_FLOAT_EQ(pos.maxValues[2], 0.5f);
  EXPECT_EQ(model.accessors[prim.indices].count, 12u);
  EXPECT_EQ(model.accessors[prim.attributes.at("TEXCOORD_0")].count, 8u);
  // The texture came back embedded and decoded.
  ASSERT_EQ(model.images.size(), 1u);
  EXPECT_EQ(model.images[0].width, 8);
  EXPECT_EQ(model.images[0].height, 4);
  ASSERT_EQ(model.materials.size(), 1u);
  EXPECT_EQ(model.materials[0].pbrMetallicRoughness.baseColorTexture.index, 0);

  // UVs are flipped: for every glTF vertex, (u, 1 - v) is a UV of a corner at
  // that position in the mesh.
  auto read_floats = [&](int acc, int comps) {
    const auto& a = model.accessors[acc];
    const auto& bv = model.bufferViews[a.bufferView];
    std::vector<float> out(a.count * comps);
    std::memcpy(out.data(), model.buffers[bv.buffer].data.data() + bv.byteOffset + a.byteOffset, out.size() * 4);
    return out;
  };
  auto P = read_floats(prim.attributes.at("POSITION"), 3);
  auto T = read_floats(prim.attributes.at("TEXCOORD_0"), 2);
  auto uv = find(m, kCornerUV).first;
  for (std::size_t i = 0; i < 8; ++i) {
    bool found = false;
    for (auto h : m.halfedges()) {
      if (m.is_border(h)) continue;
      const Point3& p = m.point(m.target(h));
      if (std::abs(p.x() - P[3 * i]) < 1e-6 && std::abs(p.y() - P[3 * i + 1]) < 1e-6 &&
          std::abs(uv[h][0] - T[2 * i]) < 1e-6 && std::abs((1.0 - uv[h][1]) - T[2 * i + 1]) < 1e-6)
        found = true;
    }
    EXPECT_TRUE(found) << "glTF vertex " << i;
  }
}

TEST(WriteMesh, GlbOfRealMeshWithoutUvsHasOneVertexPerMeshVertex) {
  Mesh m;
  read_mesh(test::shared_data("meshes/eight_genus2.off"), m);
  auto d = test::temp_dir("wm");
  write_mesh(d + "/e.glb", m);
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, d + "/e.glb")) << err;
  const auto& prim = model.meshes[0].primitives[0];
  EXPECT_EQ(model.accessors[prim.attributes.at("POSITION")].count, m.number_of_vertices());
  EXPECT_EQ(model.accessors[prim.indices].count, 3 * m.number_of_faces());
  EXPECT_FALSE(prim.attributes.count("TEXCOORD_0"));
  EXPECT_TRUE(model.images.empty());
}

TEST(WriteMesh, FailedWriteLeavesNoFile) {
  Mesh m = seamed_strip();
  auto d = test::temp_dir("wm");
  // Unknown extension, missing folder, existing output without overwrite, empty mesh.
  EXPECT_THROW(write_mesh(d + "/a.xyz", m), InvalidInputError);
  EXPECT_THROW(write_mesh(d + "/no/such/dir/a.obj", m), IOError);
  write_file_atomic(d + "/keep.ply", "original");
  WriteMeshOptions keep;
  keep.overwrite = false;
  EXPECT_THROW(write_mesh(d + "/keep.ply", m, keep), IOError);
  EXPECT_EQ(test::file_bytes(d + "/keep.ply"), "original");
  Mesh empty;
  EXPECT_THROW(write_mesh(d + "/empty.glb", empty), InvalidInputError);
  // The PNG's name is taken by a folder: the OBJ and MTL must not appear.
  fs::create_directory(d + "/u.png");
  Image tex = checker();
  WriteMeshOptions topt;
  topt.texture = &tex;
  EXPECT_THROW(write_mesh(d + "/u.obj", m, topt), IOError);
  EXPECT_FALSE(fs::exists(d + "/u.obj"));
  EXPECT_FALSE(fs::exists(d + "/u.mtl"));
  fs::remove(d + "/u.png");
  // A texture that cannot be encoded (0 channels) fails the OBJ write: no OBJ,
  // MTL or PNG may remain.
  WriteMeshOptions opt;
  Image nan_img(2, 2, 7);  // 7 channels: PNG cannot hold it
  opt.texture = &nan_img;
  try {
    write_mesh(d + "/t.obj", m, opt);
  } catch (const Error&) {
  }
  std::vector<std::string> names;
  for (auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  if (fs::exists(d + "/t.obj")) {
    // The encoder accepted the image: then all three must be there.
    EXPECT_TRUE(fs::exists(d + "/t.mtl"));
    EXPECT_TRUE(fs::exists(d + "/t.png"));
  } else {
    EXPECT_EQ(names, std::vector<std::string>{"keep.ply"});
  }
}
