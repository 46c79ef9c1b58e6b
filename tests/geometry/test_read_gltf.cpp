// SPDX-License-Identifier: AGPL-3.0-or-later
// glTF 2.0 input (read_gltf.cpp through read_mesh / read_mesh_file): what
// surftex writes reads back as it was (positions, UVs, colours, textures);
// hand-built files exercise what other tools write (strips, fans,
// normalised colours, node transforms, sparse accessors, external files);
// broken files are refused with IOError / InvalidInputError, never a crash.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "geometry/errors.h"
#include "geometry/face_material.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

std::string read_bytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_bytes(const std::string& p, const std::string& b) { std::ofstream(p, std::ios::binary) << b; }

Image checker(int n) {
  Image img(n, n, 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const bool on = ((x / 4) + (y / 4)) % 2 == 0;
      img.at(x, y, 0) = on ? 0.9f : 0.1f;
      img.at(x, y, 1) = static_cast<float>(x) / (n - 1);
      img.at(x, y, 2) = static_cast<float>(y) / (n - 1);
    }
  return img;
}

std::uint32_t le32(const std::string& d, std::size_t o) {
  std::uint32_t v;
  std::memcpy(&v, d.data() + o, 4);
  return v;
}
void put32(std::string& s, std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

// A GLB split into its JSON and its BIN chunk, and put back together.
struct GlbParts {
  nlohmann::json json;
  std::string bin;
};
GlbParts split_glb(const std::string& g) {
  const std::uint32_t jl = le32(g, 12);
  GlbParts p{nlohmann::json::parse(g.substr(20, jl)), {}};
  if (20 + jl + 8 <= g.size()) p.bin = g.substr(20 + jl + 8, le32(g, 20 + jl));
  return p;
}
std::string join_glb(const GlbParts& p) {
  std::string j = p.json.dump();
  while (j.size() % 4) j += ' ';
  std::string bin = p.bin;
  while (bin.size() % 4) bin += '\0';
  std::string out = "glTF";
  put32(out, 2);
  put32(out, static_cast<std::uint32_t>(12 + 8 + j.size() + (bin.empty() ? 0 : 8 + bin.size())));
  put32(out, static_cast<std::uint32_t>(j.size()));
  put32(out, 0x4E4F534A);
  out += j;
  if (!bin.empty()) {
    put32(out, static_cast<std::uint32_t>(bin.size()));
    put32(out, 0x004E4942);
    out += bin;
  }
  return out;
}

// A model with one buffer that tests fill in code.
struct ModelBuilder {
  tinygltf::Model m;
  ModelBuilder() {
    m.asset.version = "2.0";
    m.buffers.emplace_back();
  }
  int view(const void* data, std::size_t bytes, std::size_t stride = 0) {
    auto& b = m.buffers[0].data;
    while (b.size() % 4) b.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = b.size();
    v.byteLength = bytes;
    v.byteStride = stride;
    b.insert(b.end(), static_cast<const unsigned char*>(data), static_cast<const unsigned char*>(data) + bytes);
    m.bufferViews.push_back(v);
    return static_cast<int>(m.bufferViews.size() - 1);
  }
  int accessor(int view, int comp, int type, std::size_t count, bool normalized = false) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = comp;
    a.type = type;
    a.count = count;
    a.normalized = normalized;
    m.accessors.push_back(a);
    return static_cast<int>(m.accessors.size() - 1);
  }
  int positions(const std::vector<float>& p) {
    int a = accessor(view(p.data(), p.size() * 4), TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, p.size() / 3);
    std::vector<double> mn(3, 1e30), mx(3, -1e30);
    for (std::size_t i = 0; i < p.size(); ++i) {
      mn[i % 3] = std::min<double>(mn[i % 3], p[i]);
      mx[i % 3] = std::max<double>(mx[i % 3], p[i]);
    }
    m.accessors[a].minValues = mn;
    m.accessors[a].maxValues = mx;
    return a;
  }
  // One node per mesh, all roots of scene 0.
  void mesh(const tinygltf::Primitive& p, std::vector<double> translation = {}) {
    tinygltf::Mesh me;
    me.primitives.push_back(p);
    m.meshes.push_back(me);
    tinygltf::Node n;
    n.mesh = static_cast<int>(m.meshes.size() - 1);
    n.translation = std::move(translation);
    m.nodes.push_back(n);
    if (m.scenes.empty()) m.scenes.emplace_back();
    m.scenes[0].nodes.push_back(static_cast<int>(m.nodes.size() - 1));
    m.defaultScene = 0;
  }
  std::string glb() {
    while (m.buffers[0].data.size() % 4) m.buffers[0].data.push_back(0);
    tinygltf::TinyGLTF w;
    std::ostringstream os;
    EXPECT_TRUE(w.WriteGltfSceneToStream(&m, os, false, true));
    return os.str();
  }
};

// A unit square in z = 0 as two triangles, indexed.
tinygltf::Primitive square(ModelBuilder& b) {
  tinygltf::Primitive p;
  p.attributes["POSITION"] = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
  const std::vector<std::uint16_t> idx{0, 1, 2, 0, 2, 3};
  p.indices = b.accessor(b.view(idx.data(), idx.size() * 2), TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                         TINYGLTF_TYPE_SCALAR, idx.size());
  p.mode = TINYGLTF_MODE_TRIANGLES;
  return p;
}

double fan_signed_volume(const Mesh& m) {
  double v = 0;
  for (FaceIndex f : m.faces()) {
    std::vector<Point3> p;
    for (VertexIndex u : m.vertices_around_face(m.halfedge(f))) p.push_back(m.point(u));
    for (std::size_t k = 1; k + 1 < p.size(); ++k)
      v += CGAL::scalar_product(p[0] - CGAL::ORIGIN, CGAL::cross_product(p[k] - CGAL::ORIGIN, p[k + 1] - CGAL::ORIGIN)) / 6;
  }
  return v;
}

}  // namespace

TEST(ReadGltf, TexturedTorusRoundTripsPositionsUvsAndTexture) {
  const std::string d = test::temp_dir("gltf-torus");
  Mesh torus;
  make_torus(torus, 2.0, 0.7, 24, 12);
  assign_torus_uvs(torus, 2.0, 2.0, 1.0);
  const Image tex = checker(32);
  WriteMeshOptions wo;
  wo.texture = &tex;
  write_mesh(d + "/t.glb", torus, wo);
  Mesh back;
  MeshFileContents in = read_mesh_file(d + "/t.glb", back);
  // Welded again at the UV seams: the same vertices and faces.
  EXPECT_EQ(back.number_of_vertices(), torus.number_of_vertices());
  EXPECT_EQ(back.number_of_faces(), torus.number_of_faces());
  ASSERT_EQ(in.materials.size(), 1u);
  EXPECT_FALSE(in.materials[0].texture_bytes.empty());
  load_material_textures(in.materials);
  const Image& t = in.materials[0].texture;
  ASSERT_EQ(t.width, 32);
  ASSERT_EQ(t.height, 32);
  for (std::size_t i = 0; i < tex.data.size(); i += 7) EXPECT_NEAR(t.data[i], tex.data[i], 0.5 / 255 + 1e-6);
  // Every corner's UV is the one written: the corner with the same position
  // and the same next position (GLB positions are floats: within 1e-5).
  auto uv0 = find(torus, kCornerUV).first;
  auto uv1 = find(back, kCornerUV);
  ASSERT_TRUE(uv1.second);
  auto near = [](const Point3& a, const Point3& b) { return CGAL::squared_distance(a, b) < 1e-10; };
  std::size_t checked = 0;
  for (HalfedgeIndex h : back.halfedges()) {
    if (back.is_border(h)) continue;
    const Point3 p = back.point(back.target(h)), n = back.point(back.target(back.next(h)));
    bool found = false;
    for (HalfedgeIndex g : torus.halfedges())
      if (!torus.is_border(g) && near(torus.point(torus.target(g)), p) &&
          near(torus.point(torus.target(torus.next(g))), n)) {
        EXPECT_NEAR(uv1.first[h][0], uv0[g][0], 1e-6);
        EXPECT_NEAR(uv1.first[h][1], uv0[g][1], 1e-6);
        found = true;
        break;
      }
    EXPECT_TRUE(found) << p;
    ++checked;
  }
  EXPECT_EQ(checked, 3 * torus.number_of_faces());
}

TEST(ReadGltf, VertexColoursRoundTrip) {
  const std::string d = test::temp_dir("gltf-colours");
  Mesh s;
  make_icosphere(s, 2);
  auto col = get_or_add(s, kVertexColor);
  for (VertexIndex v : s.vertices()) {
    const Point3& p = s.point(v);
    col[v] = {float(0.5 + 0.5 * p.x()), float(0.5 + 0.5 * p.y()), float(0.5 + 0.5 * p.z())};
  }
  write_mesh(d + "/s.glb", s);
  Mesh back;
  read_mesh(d + "/s.glb", back);
  auto c = find(back, kVertexColor);
  ASSERT_TRUE(c.second);
  for (VertexIndex v : back.vertices()) {
    const Point3& p = back.point(v);
    EXPECT_NEAR(c.first[v][0], 0.5 + 0.5 * p.x(), 1e-6);
    EXPECT_NEAR(c.first[v][2], 0.5 + 0.5 * p.z(), 1e-6);
  }
  EXPECT_GT(fan_signed_volume(back), 0);  // outward, as written
}

TEST(ReadGltf, StripFanNormalisedColoursAndNodeTransforms) {
  ModelBuilder b;
  // A strip of 4 vertices (2 triangles) with unsigned-byte RGBA colours, moved by +10 in x.
  tinygltf::Primitive strip;
  strip.attributes["POSITION"] = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
  const std::vector<std::uint8_t> rgba{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  strip.attributes["COLOR_0"] =
      b.accessor(b.view(rgba.data(), rgba.size()), TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TYPE_VEC4, 4, true);
  strip.mode = TINYGLTF_MODE_TRIANGLE_STRIP;
  b.mesh(strip, {10, 0, 0});
  // A fan of 5 vertices (3 triangles), non-indexed, under a rotated, scaled parent.
  tinygltf::Primitive fan;
  fan.attributes["POSITION"] = b.positions({0, 0, 5, 1, 0, 5, 1, 1, 5, 0, 1, 5, -1, 1, 5});
  fan.mode = TINYGLTF_MODE_TRIANGLE_FAN;
  b.mesh(fan);
  b.m.nodes.back().scale = {2, 2, 2};
  b.m.nodes.back().rotation = {0, 0, std::sin(M_PI / 4), std::cos(M_PI / 4)};  // 90 degrees about z
  const std::string d = test::temp_dir("gltf-strip");
  write_bytes(d + "/m.glb", b.glb());
  Mesh m;
  SoupRepairCounts c;
  read_mesh(d + "/m.glb", m, {}, &c);
  EXPECT_EQ(m.number_of_faces(), 5u);
  EXPECT_EQ(m.number_of_vertices(), 9u);
  auto col = find(m, kVertexColor);
  ASSERT_TRUE(col.second);
  bool saw_red = false, saw_rotated = false;
  for (VertexIndex v : m.vertices()) {
    const Point3& p = m.point(v);
    if (p == Point3(10, 0, 0)) {
      saw_red = true;
      EXPECT_FLOAT_EQ(col.first[v][0], 1.f);
      EXPECT_FLOAT_EQ(col.first[v][1], 0.f);
    }
    // (1, 0, 5) scaled by 2 and turned 90 degrees about z: (0, 2, 10).
    if (std::abs(p.x()) < 1e-9 && std::abs(p.y() - 2) < 1e-9 && std::abs(p.z() - 10) < 1e-9) saw_rotated = true;
  }
  EXPECT_TRUE(saw_red);
  EXPECT_TRUE(saw_rotated);
}

TEST(ReadGltf, NegativeScaleKeepsTheSurfaceOutward) {
  // glTF 2.0 3.7.4: a negative determinant reverses the winding order.
  const std::string d = test::temp_dir("gltf-mirror");
  Mesh s;
  make_icosphere(s, 1);
  write_mesh(d + "/s.glb", s);
  GlbParts g = split_glb(read_bytes(d + "/s.glb"));
  g.json["nodes"][0]["scale"] = {-1, 1, 1};
  write_bytes(d + "/mirror.glb", join_glb(g));
  Mesh m;
  read_mesh(d + "/mirror.glb", m);
  EXPECT_GT(fan_signed_volume(m), 0);
}

TEST(ReadGltf, SparseAccessorReplacesListedElements) {
  ModelBuilder b;
  tinygltf::Primitive p = square(b);
  // The square's vertex 2 moved to (1, 1, 3) by a sparse substitution.
  const std::vector<std::uint8_t> sidx{2, 0, 0, 0};
  const std::vector<float> sval{1, 1, 3};
  tinygltf::Accessor& a = b.m.accessors[p.attributes["POSITION"]];
  a.sparse.isSparse = true;
  a.sparse.count = 1;
  const int iv = b.view(sidx.data(), 1), vv = b.view(sval.data(), 12);
  tinygltf::Accessor& a2 = b.m.accessors[p.attributes["POSITION"]];
  a2.sparse.indices.bufferView = iv;
  a2.sparse.indices.byteOffset = 0;
  a2.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  a2.sparse.values.bufferView = vv;
  a2.sparse.values.byteOffset = 0;
  a2.maxValues = {1, 1, 3};
  b.mesh(p);
  const std::string d = test::temp_dir("gltf-sparse");
  write_bytes(d + "/s.glb", b.glb());
  Mesh m;
  read_mesh(d + "/s.glb", m);
  bool moved = false;
  for (VertexIndex v : m.vertices()) moved = moved || m.point(v) == Point3(1, 1, 3);
  EXPECT_TRUE(moved);
}

TEST(ReadGltf, GltfWithExternalBufferAndTexture) {
  // A .gltf beside its .bin and a PNG whose name has a blank (URI %20).
  const std::string d = test::temp_dir("gltf-external");
  Mesh torus;
  make_torus(torus, 1.0, 0.3, 12, 8);
  assign_torus_uvs(torus, 1.0, 1.0, 1.0);
  const Image tex = checker(16);
  WriteMeshOptions wo;
  wo.texture = &tex;
  write_mesh(d + "/t.glb", torus, wo);
  GlbParts g = split_glb(read_bytes(d + "/t.glb"));
  write_image(d + "/my tex.png", tex);
  g.json["images"][0] = {{"uri", "my%20tex.png"}};
  g.json["buffers"][0]["uri"] = "t.bin";
  write_bytes(d + "/t.bin", g.bin);
  std::ofstream(d + "/t.gltf") << g.json.dump(1);
  Mesh m;
  MeshFileContents in = read_mesh_file(d + "/t.gltf", m);
  EXPECT_EQ(m.number_of_faces(), torus.number_of_faces());
  ASSERT_EQ(in.materials.size(), 1u);
  EXPECT_EQ(fs::path(in.materials[0].texture_file).filename(), "my tex.png");
  load_material_textures(in.materials);
  EXPECT_EQ(in.materials[0].texture.width, 16);
  EXPECT_NE(std::find(in.files_read.begin(), in.files_read.end(), d + "/t.bin"), in.files_read.end());
  // The texture missing: refused, naming it.
  fs::remove(d + "/my tex.png");
  try {
    read_mesh_file(d + "/t.gltf", m);
    ADD_FAILURE() << "a missing texture was accepted";
  } catch (const IOError& e) {
    EXPECT_NE(std::string(e.what()).find("my%20tex.png"), std::string::npos) << e.what();
  }
}

TEST(ReadGltf, NoTrianglesIsRefused) {
  ModelBuilder b;
  tinygltf::Primitive p;
  p.attributes["POSITION"] = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
  p.mode = TINYGLTF_MODE_POINTS;
  b.mesh(p);
  const std::string d = test::temp_dir("gltf-points");
  write_bytes(d + "/p.glb", b.glb());
  Mesh m;
  try {
    read_mesh(d + "/p.glb", m);
    ADD_FAILURE() << "a GLB without triangles was accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("no triangles"), std::string::npos) << e.what();
  }
}

TEST(ReadGltf, BadReferencesAreRefused) {
  const std::string d = test::temp_dir("gltf-bad");
  auto refused = [&](ModelBuilder& b, const std::string& name, const std::string& says) {
    write_bytes(d + "/" + name, b.glb());
    test::skip_glb_validation(d + "/" + name);
    Mesh m;
    try {
      read_mesh(d + "/" + name, m);
      ADD_FAILURE() << name << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << name << ": " << e.what();
    }
  };
  {  // an index past the vertices
    ModelBuilder b;
    tinygltf::Primitive p = square(b);
    b.m.buffers[0].data[b.m.bufferViews[b.m.accessors[p.indices].bufferView].byteOffset] = 9;
    b.mesh(p);
    refused(b, "index.glb", "out of range");
  }
  {  // an accessor longer than its view
    ModelBuilder b;
    tinygltf::Primitive p = square(b);
    b.m.accessors[p.attributes["POSITION"]].count = 400;
    b.mesh(p);
    refused(b, "count.glb", "run past buffer view");
  }
  {  // a stride shorter than an element
    ModelBuilder b;
    tinygltf::Primitive p = square(b);
    b.m.bufferViews[b.m.accessors[p.attributes["POSITION"]].bufferView].byteStride = 4;
    b.mesh(p);
    refused(b, "stride.glb", "less than an element");
  }
  {  // a required extension surftex does not read
    ModelBuilder b;
    b.mesh(square(b));
    b.m.extensionsUsed = b.m.extensionsRequired = {"KHR_draco_mesh_compression"};
    refused(b, "draco.glb", "KHR_draco_mesh_compression");
  }
  {  // a node that is its own child
    ModelBuilder b;
    b.mesh(square(b));
    b.m.nodes[0].children = {0};
    refused(b, "cycle.glb", "twice");
  }
  {  // a NaN position
    ModelBuilder b;
    tinygltf::Primitive p = square(b);
    const float nan = std::nanf("");
    std::memcpy(&b.m.buffers[0].data[4], &nan, 4);
    b.mesh(p);
    refused(b, "nan.glb", "NaN");
  }
}

TEST(ReadGltf, TruncatedAndCorruptGlbNeverCrash) {
  const std::string d = test::temp_dir("gltf-corrupt");
  Mesh s;
  make_icosphere(s, 1);
  const Image tex = checker(8);
  assign_torus_uvs(s, 1.0, 1.0, 1.0);
  WriteMeshOptions wo;
  wo.texture = &tex;
  write_mesh(d + "/s.glb", s, wo);
  const std::string good = read_bytes(d + "/s.glb");
  fs::remove(d + "/s.glb");
  std::size_t refused = 0, tried = 0;
  // Every cut in the header and chunk headers, then every 37th byte.
  for (std::size_t len = 0; len < good.size(); len += (len < 64 ? 1 : 37)) {
    write_bytes(d + "/cut.glb", good.substr(0, len));
    Mesh m;
    ++tried;
    try {
      read_mesh(d + "/cut.glb", m);
    } catch (const Error& e) {
      ++refused;
      if (len >= 12) { EXPECT_NE(std::string(e.what()).find("cut.glb"), std::string::npos) << e.what(); }
    }
  }
  EXPECT_EQ(refused, tried);  // a cut GLB never reads as a mesh
  // Bytes overwritten all over the file: refused or read, never a crash.
  std::uint32_t h = 12345;
  for (int k = 0; k < 300; ++k) {
    std::string bad = good;
    for (int j = 0; j < 4; ++j) {
      h = h * 1664525u + 1013904223u;
      bad[h % bad.size()] = static_cast<char>(h >> 24);
    }
    write_bytes(d + "/bad.glb", bad);
    Mesh m;
    try {
      read_mesh(d + "/bad.glb", m);
    } catch (const Error&) {
    }
  }
  fs::remove(d + "/bad.glb");
  fs::remove(d + "/cut.glb");
}

TEST(ReadObjMaterials, MtlColoursTexturesAndFaceMaterials) {
  const std::string d = test::temp_dir("obj-mtl");
  write_image(d + "/wood grain.png", checker(8));
  std::ofstream(d + "/m.mtl") << "# two materials\nnewmtl wood\nKd 0.5 0.4 0.3\nmap_Kd -s 2 2 1 -bm 0.5 wood grain.png\n"
                              << "newmtl paint\nKd 0.1 0.2 0.9\n";
  std::ofstream(d + "/m.obj") << "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                              << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                              << "usemtl wood\nf 1/1 2/2 3/3 4/4\nusemtl paint\nf 2 5 6 3\nusemtl missing\nf 1 3 4\n";
  Mesh m;
  MeshFileContents in = read_mesh_file(d + "/m.obj", m);
  ASSERT_EQ(in.materials.size(), 3u);
  EXPECT_EQ(in.materials[0].name, "wood");
  EXPECT_EQ(fs::path(in.materials[0].texture_file).filename(), "wood grain.png");
  EXPECT_FLOAT_EQ(in.materials[0].base_color[0], 1.f);  // textured: Kd not multiplied in (as Blender)
  EXPECT_FLOAT_EQ(in.materials[1].base_color[2], 0.9f);
  EXPECT_FALSE(in.materials[2].has_texture());
  ASSERT_EQ(in.warnings.size(), 1u);
  EXPECT_NE(in.warnings[0].find("missing"), std::string::npos);
  EXPECT_EQ(in.files_read.size(), 2u);  // the OBJ and its .mtl
  // The quads were split; each triangle keeps its quad's material.
  auto fm = find(m, kFaceMaterial);
  ASSERT_TRUE(fm.second);
  std::map<int, int> count;
  for (FaceIndex f : m.faces()) ++count[fm.first[f]];
  EXPECT_EQ(count[0] + count[1] + count[2], static_cast<int>(m.number_of_faces()));
  EXPECT_GE(count[1], 2);
  load_material_textures(in.materials);
  EXPECT_EQ(in.materials[0].texture.width, 8);
}

TEST(ReadObjMaterials, MissingMtlIsAWarning) {
  // Real OBJs reference .mtl files that were not shipped (shared data README).
  Mesh m;
  MeshFileContents in = read_mesh_file(test::shared_data("meshes/coffee_cup.obj"), m);
  EXPECT_GT(m.number_of_faces(), 1000u);
  ASSERT_FALSE(in.warnings.empty());
  EXPECT_NE(in.warnings[0].find("does not exist"), std::string::npos) << in.warnings[0];
  EXPECT_FALSE(in.materials.empty());
}
