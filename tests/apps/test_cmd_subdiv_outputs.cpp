// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex subdiv`'s finished asset (issue 16 items 2-3): the GLB carries the
// baked atlas (base colour, normal map from the height) beside the vertex
// colours; the atlas has mip gutters and no black background; no file twice.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "apps/asset_checks.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/uv_raster.h"
#include "geometry/write_mesh.h"
#include "test_support.h"

using namespace surftex;
namespace fs = std::filesystem;

TEST(CmdSubdivOutputs, GlbCarriesTheAtlasAndItsNormalMap) {
  const std::string dir = test::temp_dir("subdiv_outputs");
  const std::string out = dir + "/out";
  auto r = test::run_surftex("subdiv '" + test::shared_data("meshes/fish_blub.obj") + "' '" +
                             test::shared_data("textures/leather_64.png") + "' -o '" + out +
                             "' --levels 1 --atlas-size 256 -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json g = test::glb_json(out + "/surface.glb");
  ASSERT_TRUE(g.contains("materials"));
  EXPECT_TRUE(g["materials"][0]["pbrMetallicRoughness"].contains("baseColorTexture"));
  EXPECT_TRUE(g["materials"][0].contains("normalTexture"));
  const auto& attr = g["meshes"][0]["primitives"][0]["attributes"];
  EXPECT_TRUE(attr.contains("TEXCOORD_0"));
  EXPECT_TRUE(attr.contains("_COLOR"));     // the vertex colours, kept
  EXPECT_FALSE(attr.contains("COLOR_0"));   // which would multiply the texture holding them
  const Image atlas = read_image(out + "/surface_atlas.png");
  std::size_t black = 0;
  for (int y = 0; y < atlas.height; ++y)
    for (int x = 0; x < atlas.width; ++x) black += atlas.at(x, y, 0) + atlas.at(x, y, 1) + atlas.at(x, y, 2) == 0.f;
  EXPECT_EQ(black, 0u);
  EXPECT_EQ(test::png_bit_depth(out + "/surface_atlas_height.png"), 16);
  const Image height = read_image(out + "/surface_atlas_height.png");
  EXPECT_GT(test::normal_follows_height(read_image(out + "/surface_atlas_normal.png"), height,
                                        test::chart_interior(out + "/surface_atlas.obj", height.width, height.height)),
            0.9);
  EXPECT_TRUE(test::duplicate_files(out).empty()) << test::duplicate_files(out).front();
  const auto j = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(j["export"]["atlas"]["gutter"], 4);  // 256 -> 64 px: 2 halvings
  EXPECT_EQ(j["export"]["atlas"]["gutter_violations"], 0);
}

// Every stage after the synthesis runs side by side (the fidelity beside the
// bake, the render beside the writing, the atlas raster, dilation and OBJ text
// in parallel): one and two threads write the same bytes, report aside.
TEST(CmdSubdivOutputs, OneAndTwoThreadsWriteTheSameFiles) {
  const std::string dir = test::temp_dir("subdiv_threads");
  std::string outs[2];
  for (int t = 0; t < 2; ++t) {
    outs[t] = dir + "/out" + std::to_string(t + 1);
    auto r = test::run_surftex("subdiv '" + test::shared_data("meshes/fish_blub.obj") + "' '" +
                               test::shared_data("textures/leather_64.png") + "' -o '" + outs[t] +
                               "' --levels 2 --atlas-size 512 -q --threads " + std::to_string(t + 1));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  std::size_t compared = 0;
  for (const auto& e : fs::directory_iterator(outs[0])) {
    const std::string name = e.path().filename().string();
    if (name == "report.json") continue;
    const std::string sa = test::file_bytes(e.path().string()), sb = test::file_bytes(outs[1] + "/" + name);
    EXPECT_FALSE(sa.empty()) << name;
    EXPECT_TRUE(sa == sb) << name << " differs between 1 and 2 threads";
    ++compared;
  }
  EXPECT_GE(compared, 7u);  // ply, glb, obj, mtl, three maps, render
  const auto j1 = test::read_json(outs[0] + "/report.json"), j2 = test::read_json(outs[1] + "/report.json");
  EXPECT_EQ(j1["fidelity"]["ratio"], j2["fidelity"]["ratio"]);
  EXPECT_EQ(j1["export"]["atlas"]["seam"]["ratio"], j2["export"]["atlas"]["seam"]["ratio"]);
}

namespace {

// A small periodic stochastic exemplar.
Image noise_exemplar(int n) {
  Image img(n, n, 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      unsigned h = static_cast<unsigned>(x * 73856093u) ^ static_cast<unsigned>(y * 19349663u);
      h = (h ^ (h >> 13)) * 0x5bd1e995u;
      const float v = static_cast<float>((h >> 8) & 255u) / 255.f;
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = 0.3f + 0.4f * v * (c + 1) / 3.f;
    }
  return img;
}

// The same with a red channel over most of [0, 1] (a height of 1 - red then varies clearly).
Image red_noise_exemplar(int n) {
  Image img = noise_exemplar(n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) img.at(x, y, 0) = 0.1f + 0.8f * (img.at(x, y, 2) - 0.3f) / 0.4f;
  return img;
}

Image constant_normal_map(int n, double x, double y, double z) {
  Image img(n, n, 3);
  for (int i = 0; i < n * n; ++i)
    for (int c = 0; c < 3; ++c) img.data[3 * i + c] = static_cast<float>(0.5 + 0.5 * (c == 0 ? x : c == 1 ? y : z));
  return img;
}

using D3 = std::array<double, 3>;
double dot(const D3& a, const D3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
D3 unit(const D3& a) {
  const double l = std::sqrt(dot(a, a));
  return l > 0 ? D3{a[0] / l, a[1] / l, a[2] / l} : D3{0, 0, 0};
}

// What a glTF viewer shades with: every texel of the GLB's normal texture
// inside a triangle, decoded (2 rgb - 1) through the blend of the file's own
// NORMAL and TANGENT there (N normalised, T made orthogonal, B = cross(N, T) w),
// in object space; `valid` marks the texels inside a triangle.
struct ViewerNormals {
  std::vector<D3> n;
  std::vector<char> valid;
};

ViewerNormals viewer_normals(const std::string& glb, const std::string& scratch_png) {
  const test::Glb g = test::read_glb(glb);
  const auto& prim = g.json["meshes"][0]["primitives"][0];
  const auto& at = prim["attributes"];
  const auto N = g.accessor<float>(at["NORMAL"].get<int>()), T = g.accessor<float>(at["TANGENT"].get<int>());
  const auto uv = g.accessor<float>(at["TEXCOORD_0"].get<int>());
  const auto idx = g.accessor<std::uint32_t>(prim["indices"].get<int>());
  const int tex = g.json["materials"][0]["normalTexture"]["index"];
  { std::ofstream(scratch_png, std::ios::binary) << g.image_bytes(g.json["textures"][tex]["source"].get<int>()); }
  const Image img = read_image(scratch_png);
  std::vector<UvTriangle> tris;
  for (std::size_t k = 0; k + 2 < idx.size(); k += 3) {
    UvTriangle t;
    for (int c = 0; c < 3; ++c) t[c] = {uv[2 * idx[k + c]], 1.0 - uv[2 * idx[k + c] + 1]};  // v up
    tris.push_back(t);
  }
  const UvRaster r = rasterize_uv_triangles(tris, img.width, img.height, 0.0);
  ViewerNormals out;
  out.n.assign(r.triangle.size(), {0, 0, 0});
  out.valid.assign(r.triangle.size(), 0);
  for (std::size_t i = 0; i < r.triangle.size(); ++i) {
    const int t = r.triangle[i];
    if (t < 0) continue;
    D3 n{0, 0, 0}, tg{0, 0, 0};
    double w = 0;
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = idx[3 * t + c];
      for (int k = 0; k < 3; ++k) n[k] += r.bary[i][c] * N[3 * v + k], tg[k] += r.bary[i][c] * T[4 * v + k];
      w += r.bary[i][c] * T[4 * v + 3];
    }
    n = unit(n);
    const double d = dot(tg, n);
    tg = unit({tg[0] - d * n[0], tg[1] - d * n[1], tg[2] - d * n[2]});
    const double s = w < 0 ? -1 : 1;
    const D3 b{s * (n[1] * tg[2] - n[2] * tg[1]), s * (n[2] * tg[0] - n[0] * tg[2]), s * (n[0] * tg[1] - n[1] * tg[0])};
    D3 e;
    for (int k = 0; k < 3; ++k) e[k] = 2.0 * img.data[3 * i + k] - 1.0;
    out.n[i] = unit({e[0] * tg[0] + e[1] * b[0] + e[2] * n[0], e[0] * tg[1] + e[1] * b[1] + e[2] * n[1],
                     e[0] * tg[2] + e[1] * b[2] + e[2] * n[2]});
    out.valid[i] = 1;
  }
  return out;
}

}  // namespace

// Issue 16 item 2 for subdiv: the exemplar maps are read where every vertex's
// colour was read, so a height map that is 1 - red of the colour exemplar
// comes out as 1 - red of the baked colour atlas; roughness goes to the GLB
// and the MTL.
TEST(CmdSubdivOutputs, ExemplarMapsFollowTheColourSynthesis) {
  const std::string dir = test::temp_dir("subdiv_maps");
  Mesh m;
  make_icosphere(m, 2);
  write_mesh(dir + "/sphere.obj", m);
  const Image ex = red_noise_exemplar(32);
  write_image(dir + "/ex.png", ex);
  Image h(32, 32, 1), rough(32, 32, 1, 0.7f);
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) h.at(x, y) = 1.f - ex.at(x, y, 0);
  write_image(dir + "/h.png", h, {.eight_bit = true, .sixteen_bit = true});
  write_image(dir + "/r.png", rough);
  const std::string out = dir + "/out";
  auto r = test::run_surftex("subdiv '" + dir + "/sphere.obj' '" + dir + "/ex.png' --texel-size 1x --atlas-size 128 -q "
                             "--exemplar-height '" + dir + "/h.png' --exemplar-roughness '" + dir + "/r.png' -o '" +
                             out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image colour = read_image(out + "/surface_atlas.png"), height = read_image(out + "/surface_atlas_height.png");
  ASSERT_EQ(colour.width, height.width);
  const std::vector<char> chart = test::chart_interior(out + "/surface_atlas.obj", colour.width, colour.height);
  std::size_t same = 0, texels = 0;
  double sum = 0, sum2 = 0;
  for (int y = 0; y < colour.height; ++y)
    for (int x = 0; x < colour.width; ++x) {
      if (!chart[static_cast<std::size_t>(y) * colour.width + x]) continue;
      ++texels;
      const double hv = height.at(x, y, 0);
      same += std::abs(hv - (1.0 - colour.at(x, y, 0))) < 1.5 / 255;
      sum += hv, sum2 += hv * hv;
    }
  EXPECT_GT(texels, 1000u);
  EXPECT_GT(same, texels * 995 / 1000) << "height is not the same synthesis as the colour";
  EXPECT_GT(std::sqrt(sum2 / texels - (sum / texels) * (sum / texels)), 0.05) << "a flat height proves nothing";
  const Image mr = read_image(out + "/surface_atlas_roughness.png");
  EXPECT_NEAR(mr.at(mr.width / 2, mr.height / 2, 1), 0.7, 1.0 / 255);
  const nlohmann::json g = test::glb_json(out + "/surface.glb");
  EXPECT_TRUE(g["materials"][0]["pbrMetallicRoughness"].contains("metallicRoughnessTexture"));
  EXPECT_NE(test::file_bytes(out + "/surface_atlas.mtl").find("map_Pr"), std::string::npos);
  EXPECT_TRUE(test::duplicate_files(out).empty()) << test::duplicate_files(out).front();
  const auto j = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(j["export"]["atlas"]["normal_source"], "height");
  EXPECT_EQ(j["export"]["atlas"]["height_source"], "exemplar_height");
  EXPECT_EQ(j["export"]["atlas"]["roughness"], true);
}

// A constant exemplar normal tilted 45 degrees towards the exemplar's +x and
// +y (image up) on a flat square in z = 0: subdiv lays the exemplar with +x
// along the field (world +x from its default key) and image up along
// normal x field = +y, so a viewer shading the GLB sees (0.5, 0.5, 0.707).
TEST(CmdSubdivOutputs, ExemplarNormalPointsWhereTheExemplarLiesOnAPlane) {
  const std::string dir = test::temp_dir("subdiv_normal_plane");
  Mesh m;
  make_grid(m, 6, 6);
  write_mesh(dir + "/plane.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  write_image(dir + "/n.png", constant_normal_map(32, 0.5, 0.5, std::sqrt(0.5)));
  const std::string out = dir + "/out";
  auto r = test::run_surftex("subdiv '" + dir + "/plane.obj' '" + dir + "/ex.png' --levels 2 --atlas-size 128 -q "
                             "--exemplar-normal '" + dir + "/n.png' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const ViewerNormals vn = viewer_normals(out + "/surface.glb", dir + "/glb_normal.png");
  const D3 want = unit({0.5, 0.5, std::sqrt(0.5)});
  std::size_t texels = 0, right = 0;
  for (std::size_t i = 0; i < vn.n.size(); ++i) {
    if (!vn.valid[i]) continue;
    ++texels;
    right += dot(vn.n[i], want) > std::cos(3 * M_PI / 180);
  }
  EXPECT_GT(texels, 1000u);
  EXPECT_GT(right, texels * 99 / 100);
  const auto j = nlohmann::json::parse(std::ifstream(out + "/report.json"));
  EXPECT_EQ(j["export"]["atlas"]["normal_source"], "exemplar_normal");
  EXPECT_EQ(j["export"]["atlas"]["height_source"], "luminance");
}

// A flat exemplar normal (0, 0, 1) on a curved mesh: object normals along the
// surface, turned into the GLB's tangent frames, give a flat map (0.5, 0.5, 1).
TEST(CmdSubdivOutputs, FlatExemplarNormalGivesAFlatTangentMapOnACurvedMesh) {
  const std::string dir = test::temp_dir("subdiv_normal_flat");
  Mesh m;
  make_torus(m, 1.0, 0.4, 24, 12);
  write_mesh(dir + "/torus.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  write_image(dir + "/n.png", constant_normal_map(32, 0, 0, 1));
  const std::string out = dir + "/out";
  auto r = test::run_surftex("subdiv '" + dir + "/torus.obj' '" + dir + "/ex.png' --levels 1 --atlas-size 128 -q "
                             "--exemplar-normal '" + dir + "/n.png' -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image n = read_image(out + "/surface_atlas_normal.png");
  std::size_t flat = 0;
  for (int y = 0; y < n.height; ++y)
    for (int x = 0; x < n.width; ++x)
      flat += std::abs(n.at(x, y, 0) - 0.5) < 0.03 && std::abs(n.at(x, y, 1) - 0.5) < 0.03 && n.at(x, y, 2) > 0.99;
  EXPECT_GT(flat, static_cast<std::size_t>(n.width) * n.height * 99 / 100);
}

// Maps of another size than the colour exemplar, missing, or a grey normal
// map: refused before anything is written.
TEST(CmdSubdivOutputs, RefusesExemplarMapsOfAnotherSizeOrMissing) {
  const std::string dir = test::temp_dir("subdiv_maps_bad");
  Mesh m;
  make_icosphere(m, 1);
  write_mesh(dir + "/s.obj", m);
  write_image(dir + "/ex.png", noise_exemplar(32));
  write_image(dir + "/small.png", noise_exemplar(16));
  write_image(dir + "/grey.png", Image(32, 32, 1, 0.5f));
  const std::string base = "subdiv '" + dir + "/s.obj' '" + dir + "/ex.png' --levels 0 -q -o '" + dir + "/o' ";
  for (const char* opt : {"--exemplar-normal", "--exemplar-height", "--exemplar-roughness"}) {
    auto r = test::run_surftex(base + opt + " '" + dir + "/small.png'");
    EXPECT_EQ(r.exit_code, 2) << opt;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(opt), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("16 x 16"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("32 x 32"), std::string::npos) << r.err;
    r = test::run_surftex(base + opt + " '" + dir + "/nope.png'");
    EXPECT_EQ(r.exit_code, 2) << opt;
    EXPECT_NE(r.err.find("error: "), std::string::npos) << r.err;
  }
  auto r = test::run_surftex(base + "--exemplar-normal '" + dir + "/grey.png'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--exemplar-normal"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/o"));
}
