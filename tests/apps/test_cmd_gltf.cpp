// SPDX-License-Identifier: AGPL-3.0-or-later
// GLB in and out through the CLI (issue 16 items 4 and 5): `render` shows a
// GLB with its embedded texture as the source looked, `info` and `convert`
// read GLB, OBJ -> GLB keeps the OBJ's materials and map_Kd textures, and bad
// input (no triangles, truncated or corrupt GLB, --texture without UVs) gets
// "error: ...", exit 2 and no output.
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "geometry/image_io.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

using surftex::test::q;

std::string read_bytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

double psnr(const Image& a, const Image& b) {
  EXPECT_EQ(a.data.size(), b.data.size());
  double se = 0;
  for (std::size_t i = 0; i < a.data.size() && i < b.data.size(); ++i) se += (a.data[i] - b.data[i]) * (a.data[i] - b.data[i]);
  const double mse = se / std::max<std::size_t>(a.data.size(), 1);
  return mse == 0 ? 99.0 : 10 * std::log10(1.0 / mse);
}

void expect_refused(const test::RunResult& r, const std::string& output, const std::string& says) {
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(r.err.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(output)) << output;
}

}  // namespace

TEST(CmdGltf, RenderOfAGlbMatchesTheRenderOfItsSource) {
  // chair.obj (UVs, its .mtl missing) textured with a brick photo, converted
  // to GLB: the GLB renders with its embedded texture as the OBJ did.
  const std::string d = test::temp_dir("cmd-gltf-render");
  const std::string chair = test::shared_data("meshes/chair.obj");
  const std::string brick = test::shared_data("textures/brick_small_96.png");
  auto r = test::run_surftex("convert " + q(chair) + " -o " + q(d + "/chair.glb") + " --texture " + q(brick) + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_surftex("render " + q(chair) + " --texture " + q(brick) + " -o " + q(d + "/obj.png") + " --size 256 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_surftex("render " + q(d + "/chair.glb") + " -o " + q(d + "/glb.png") + " --size 256 --report " +
                        q(d + "/r.json") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image a = read_image(d + "/obj.png"), b = read_image(d + "/glb.png");
  EXPECT_GT(psnr(a, b), 35.0);
  std::ifstream rf(d + "/r.json");
  const auto j = nlohmann::json::parse(rf);
  EXPECT_EQ(j["colors"], "material");
  // Without its texture the GLB renders plain: the texture is what made them match.
  r = test::run_surftex("render " + q(d + "/chair.glb") + " --colors none -o " + q(d + "/plain.png") + " --size 256 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(psnr(a, read_image(d + "/plain.png")), 25.0);
}

TEST(CmdGltf, InfoAndConvertReadGlb) {
  const std::string d = test::temp_dir("cmd-gltf-convert");
  const std::string rock = test::shared_data("swatches/rock_1.obj");
  const std::string tex = test::shared_data("textures/pebbles_256.png");
  auto r = test::run_surftex("convert " + q(rock) + " -o " + q(d + "/rock.glb") + " --texture " + q(tex) + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_surftex("info " + q(d + "/rock.glb"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("faces:           332"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("texture embedded"), std::string::npos) << r.out;
  // GLB -> OBJ: the embedded texture comes out as rock_back.png, the same pixels.
  r = test::run_surftex("convert " + q(d + "/rock.glb") + " -o " + q(d + "/rock_back.obj") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image original = read_image(tex), back = read_image(d + "/rock_back.png");
  ASSERT_EQ(back.width, original.width);
  EXPECT_GT(psnr(original, back), 60.0);
  EXPECT_NE(read_bytes(d + "/rock_back.mtl").find("map_Kd rock_back.png"), std::string::npos);
  // The OBJ renders as the GLB does.
  r = test::run_surftex("render " + q(d + "/rock.glb") + " -o " + q(d + "/a.png") + " --size 128 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = test::run_surftex("render " + q(d + "/rock_back.obj") + " -o " + q(d + "/b.png") + " --size 128 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GT(psnr(read_image(d + "/a.png"), read_image(d + "/b.png")), 35.0);
}

TEST(CmdGltf, ObjToGlbKeepsItsMaterialsAndMapKd) {
  const std::string d = test::temp_dir("cmd-gltf-mtl");
  fs::copy_file(test::shared_data("textures/denim_256.png"), d + "/denim.png");
  std::ofstream(d + "/quads.mtl") << "newmtl cloth\nKd 1 1 1\nmap_Kd denim.png\nnewmtl trim\nKd 0.8 0.1 0.1\n";
  std::ofstream(d + "/quads.obj") << "mtllib quads.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                                  << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                  << "usemtl cloth\nf 1/1 2/2 3/3 4/4\nusemtl trim\nf 2/1 5/2 6/3 3/4\n";
  auto r = test::run_surftex("convert " + q(d + "/quads.obj") + " -o " + q(d + "/quads.glb") + " --report " +
                             q(d + "/r.json") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  ASSERT_TRUE(loader.LoadBinaryFromFile(&model, &err, &warn, d + "/quads.glb")) << err;
  ASSERT_EQ(model.materials.size(), 2u);
  EXPECT_EQ(model.materials[0].name, "cloth");
  EXPECT_EQ(model.materials[1].name, "trim");
  EXPECT_NEAR(model.materials[1].pbrMetallicRoughness.baseColorFactor[0], 0.8, 1e-6);
  const int t = model.materials[0].pbrMetallicRoughness.baseColorTexture.index;
  ASSERT_GE(t, 0);
  const auto& img = model.images[static_cast<std::size_t>(model.textures[static_cast<std::size_t>(t)].source)];
  const Image denim = read_image(d + "/denim.png");
  ASSERT_EQ(img.width, denim.width);
  ASSERT_GE(img.component, 3);
  for (std::size_t i = 0; i < static_cast<std::size_t>(denim.width) * denim.height; i += 97)
    for (std::size_t c = 0; c < 3; ++c)
      EXPECT_NEAR(img.image[i * img.component + c] / 255.0, denim.data[i * denim.channels + c], 0.5 / 255 + 1e-6);
  EXPECT_EQ(model.meshes[0].primitives.size(), 2u);
  // The report lists the .mtl and the texture among the inputs.
  std::ifstream rf(d + "/r.json");
  const auto j = nlohmann::json::parse(rf);
  std::vector<std::string> ins;
  for (const auto& e : j["inputs"]) ins.push_back(e["path"]);
  EXPECT_NE(std::find(ins.begin(), ins.end(), d + "/quads.mtl"), ins.end());
  EXPECT_NE(std::find(ins.begin(), ins.end(), d + "/denim.png"), ins.end());
}

TEST(CmdGltf, TextureOnAMeshWithoutUvsIsRefused) {
  const std::string d = test::temp_dir("cmd-gltf-nouv");
  expect_refused(test::run_surftex("convert " + q(test::shared_data("meshes/fish_blub.obj")) + " -o " +
                                   q(d + "/x.glb") + " --texture " + q(test::shared_data("textures/leather_64.png"))),
                 d + "/x.glb", "texture coordinates");
}

TEST(CmdGltf, BadGlbIsRefusedWithoutOutput) {
  const std::string d = test::temp_dir("cmd-gltf-bad");
  auto r = test::run_surftex("convert " + q(test::shared_data("meshes/eight_genus2.off")) + " -o " + q(d + "/e.glb") + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string good = read_bytes(d + "/e.glb");
  // Truncated in the BIN chunk.
  std::ofstream(d + "/cut.glb", std::ios::binary) << good.substr(0, good.size() / 2);
  // Corrupt JSON (a bracket in the JSON chunk replaced).
  std::string bad = good;
  bad[20] = '#';
  std::ofstream(d + "/corrupt.glb", std::ios::binary) << bad;
  // No triangles: the same file with its primitive's mode set to POINTS.
  std::string points = good;
  const std::size_t at = points.find("\"mode\":4");
  ASSERT_NE(at, std::string::npos);
  points[at + 7] = '0';
  std::ofstream(d + "/points.glb", std::ios::binary) << points;
  for (const char* f : {"cut.glb", "corrupt.glb", "points.glb"}) test::skip_glb_validation(d + "/" + f);
  expect_refused(test::run_surftex("render " + q(d + "/cut.glb") + " -o " + q(d + "/cut.png")), d + "/cut.png",
                 "truncated GLB");
  expect_refused(test::run_surftex("info " + q(d + "/corrupt.glb") + " --report " + q(d + "/i.json")), d + "/i.json",
                 "corrupt.glb");
  expect_refused(test::run_surftex("convert " + q(d + "/points.glb") + " -o " + q(d + "/p.obj")), d + "/p.obj",
                 "no triangles");
}

// A texture path that does not exist, named on the command line or by an
// OBJ's material: refused with its path, exit 2, nothing written.
TEST(CmdGltf, ATexturePathThatDoesNotExistIsRefusedWithoutOutput) {
  const std::string d = test::temp_dir("cmd-gltf-notex");
  std::ofstream(d + "/quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                 << "f 1/1 2/2 3/3 4/4\n";
  expect_refused(test::run_surftex("render " + q(d + "/quad.obj") + " --texture " + q(d + "/nope.png") + " -o " +
                                   q(d + "/r.png") + " -q"),
                 d + "/r.png", "nope.png");
  expect_refused(test::run_surftex("convert " + q(d + "/quad.obj") + " --texture " + q(d + "/nope.png") + " -o " +
                                   q(d + "/c.glb") + " -q"),
                 d + "/c.glb", "nope.png");
  // The material's map_Kd names a missing file.
  std::ofstream(d + "/lost.mtl") << "newmtl m\nKd 1 1 1\nmap_Kd gone.png\n";
  std::ofstream(d + "/lost.obj") << "mtllib lost.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                                 << "usemtl m\nf 1/1 2/2 3/3\n";
  expect_refused(test::run_surftex("convert " + q(d + "/lost.obj") + " -o " + q(d + "/l.glb") + " -q"), d + "/l.glb",
                 "gone.png");
  expect_refused(test::run_surftex("render " + q(d + "/lost.obj") + " -o " + q(d + "/l.png") + " -q"), d + "/l.png",
                 "gone.png");
}

namespace {

// A unit quad in the xy plane with u running 0..3 across it, textured with an
// 8 x 1 image (left half black, right half white) whose sampler wraps u with
// `wrap_s` (glTF codes), written as a GLB by tinygltf itself.
void write_wrap_quad(const std::string& path, const std::string& png, int wrap_s) {
  tinygltf::Model m;
  m.asset.version = "2.0";
  const float pos[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const float uv[] = {0, 1, 3, 1, 3, 0, 0, 0};
  const std::uint16_t idx[] = {0, 1, 2, 0, 2, 3};
  const std::string img = read_bytes(png);
  tinygltf::Buffer buf;
  auto add = [&](const void* p, std::size_t n, int target) {
    while (buf.data.size() % 4) buf.data.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.data.size();
    v.byteLength = n;
    v.target = target;
    buf.data.insert(buf.data.end(), static_cast<const unsigned char*>(p), static_cast<const unsigned char*>(p) + n);
    m.bufferViews.push_back(v);
    return static_cast<int>(m.bufferViews.size() - 1);
  };
  auto accessor = [&](int view, int comp, int type, std::size_t count, std::vector<double> mn = {}, std::vector<double> mx = {}) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = comp;
    a.type = type;
    a.count = count;
    a.minValues = std::move(mn);
    a.maxValues = std::move(mx);
    m.accessors.push_back(a);
    return static_cast<int>(m.accessors.size() - 1);
  };
  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = accessor(add(pos, sizeof pos, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT,
                                         TINYGLTF_TYPE_VEC3, 4, {0, 0, 0}, {1, 1, 0});
  prim.attributes["TEXCOORD_0"] =
      accessor(add(uv, sizeof uv, TINYGLTF_TARGET_ARRAY_BUFFER), TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, 4);
  prim.indices = accessor(add(idx, sizeof idx, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR, 6);
  prim.material = 0;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Image im;
  im.bufferView = add(img.data(), img.size(), 0);
  m.bufferViews.back().target = 0;
  im.mimeType = "image/png";
  m.images.push_back(im);
  tinygltf::Sampler s;
  s.wrapS = wrap_s;
  s.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
  m.samplers.push_back(s);
  tinygltf::Texture t;
  t.source = 0;
  t.sampler = 0;
  m.textures.push_back(t);
  tinygltf::Material mat;
  mat.pbrMetallicRoughness.baseColorTexture.index = 0;
  m.materials.push_back(mat);
  tinygltf::Mesh mesh;
  mesh.primitives.push_back(prim);
  m.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  m.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  m.scenes.push_back(scene);
  m.defaultScene = 0;
  m.buffers.push_back(buf);
  tinygltf::TinyGLTF io;
  ASSERT_TRUE(io.WriteGltfSceneToFile(&m, path, false, true, false, true));
}

// Along the middle row of a front view: the surface's pixels (background red
// excluded) as 'b' / 'w', runs merged.
std::string middle_row_runs(const Image& img) {
  std::string runs;
  const int y = img.height / 2;
  for (int x = 0; x < img.width; ++x) {
    if (img.at(x, y, 0) > 0.9f && img.at(x, y, 1) < 0.1f) continue;  // background
    const char c = img.at(x, y, 1) > 0.5f ? 'w' : 'b';
    if (runs.empty() || runs.back() != c) runs += c;
  }
  return runs;
}

}  // namespace

TEST(CmdGltf, RenderWrapsATextureAsItsSamplerSays) {
  // u runs 0..3 over the quad: REPEAT shows black-white three times, MIRRORED_REPEAT
  // black-white, white-black, black-white (two runs merge), CLAMP_TO_EDGE one black
  // run then white to the end; --clamp forces the last.
  const std::string d = test::temp_dir("cmd-gltf-wrap");
  Image tex(8, 1, 3);
  for (int x = 4; x < 8; ++x)
    for (int c = 0; c < 3; ++c) tex.at(x, 0, c) = 1.f;
  write_image(d + "/bw.png", tex);
  const std::string view = " --view 0,0 --ortho --no-shade --supersample 1 --size 240 --background 1,0,0 -q";
  const std::vector<std::pair<int, std::string>> cases{{TINYGLTF_TEXTURE_WRAP_REPEAT, "bwbwbw"},
                                                       {TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT, "bwbw"},
                                                       {TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE, "bw"}};
  for (const auto& [wrap, runs] : cases) {
    const std::string glb = d + "/q" + std::to_string(wrap) + ".glb", png = d + "/q" + std::to_string(wrap) + ".png";
    write_wrap_quad(glb, d + "/bw.png", wrap);
    const auto r = test::run_surftex("render " + q(glb) + " -o " + q(png) + view);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(middle_row_runs(read_image(png)), runs) << "wrap " << wrap;
  }
  const auto r = test::run_surftex("render " + q(d + "/q10497.glb") + " --clamp -o " + q(d + "/forced.png") + view);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(middle_row_runs(read_image(d + "/forced.png")), "bw");
  fs::remove_all(d);
}
