// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Checks of finished assets shared by the CLI tests (issue 16 items 1-3):
// byte-identical files in an output folder, the JSON chunk of a GLB, the
// bit depth of a PNG, and whether a normal map follows a height map's slopes.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/uv_raster.h"
#include "test_support.h"

namespace surftex::test {

/// Names of files in `dir` whose bytes equal another file's there ("a = b").
inline std::vector<std::string> duplicate_files(const std::string& dir) {
  std::map<std::string, std::string> seen;
  std::vector<std::string> dup;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& p : files) {
    auto [it, fresh] = seen.emplace(file_bytes(p.string()), p.filename().string());
    if (!fresh) dup.push_back(it->second + " = " + p.filename().string());
  }
  return dup;
}

/// The JSON chunk of a binary glTF (empty object if the file is not a GLB).
inline nlohmann::json glb_json(const std::string& path) {
  const std::string b = file_bytes(path);
  if (b.size() < 20 || b.compare(0, 4, "glTF") != 0) return nlohmann::json::object();
  std::uint32_t len = 0;
  std::memcpy(&len, b.data() + 12, 4);
  if (20 + static_cast<std::size_t>(len) > b.size()) return nlohmann::json::object();
  return nlohmann::json::parse(b.substr(20, len));
}

/// A GLB as surftex writes it (one buffer, tightly packed views): its JSON and
/// BIN chunk, and readers of its accessors and embedded images.
struct Glb {
  nlohmann::json json = nlohmann::json::object();
  std::string bin;
  std::string view_bytes(int view) const {
    const auto& v = json["bufferViews"][view];
    return bin.substr(v.value("byteOffset", 0), v["byteLength"].get<std::size_t>());
  }
  /// Components of a FLOAT (5126) or UNSIGNED_INT (5125) accessor, as T.
  template <class T>
  std::vector<T> accessor(int a) const {
    const auto& acc = json["accessors"][a];
    const std::string b = view_bytes(acc["bufferView"].get<int>());
    const std::string type = acc["type"];
    const std::size_t per = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
    std::vector<T> out(acc["count"].get<std::size_t>() * per);
    if (b.size() >= out.size() * 4) std::memcpy(out.data(), b.data() + acc.value("byteOffset", 0), out.size() * 4);
    return out;
  }
  /// The encoded bytes of image `i` (PNG).
  std::string image_bytes(int i) const { return view_bytes(json["images"][i]["bufferView"].get<int>()); }
};

inline Glb read_glb(const std::string& path) {
  Glb g;
  g.json = glb_json(path);
  const std::string b = file_bytes(path);
  std::uint32_t len = 0;
  if (b.size() < 20) return g;
  std::memcpy(&len, b.data() + 12, 4);
  const std::size_t bin_at = 20 + static_cast<std::size_t>(len);
  if (bin_at + 8 > b.size()) return g;
  std::uint32_t bin_len = 0;
  std::memcpy(&bin_len, b.data() + bin_at, 4);
  g.bin = b.substr(bin_at + 8, bin_len);
  return g;
}

/// Bit depth of a PNG (IHDR byte 24), 0 if not a PNG.
inline int png_bit_depth(const std::string& path) {
  const std::string b = file_bytes(path);
  if (b.size() < 25 || b.compare(1, 3, "PNG") != 0) return 0;
  return static_cast<unsigned char>(b[24]);
}

/// Atlas texels (W x H) whose centre lies inside a face of the mesh file's
/// uv (its charts), 1 per texel; its 3x3 interior only (no chart edge).
inline std::vector<char> chart_interior(const std::string& mesh_path, int W, int H) {
  Mesh m;
  read_mesh(mesh_path, m);
  auto uv = find(m, kCornerUV).first;
  std::vector<UvTriangle> tris;
  for (FaceIndex f : m.faces()) {
    std::vector<UV> c;
    for (HalfedgeIndex h : m.halfedges_around_face(m.halfedge(f))) c.push_back(uv[h]);
    for (std::size_t k = 1; k + 1 < c.size(); ++k)
      tris.push_back({{{c[0][0], c[0][1]}, {c[k][0], c[k][1]}, {c[k + 1][0], c[k + 1][1]}}});
  }
  const UvRaster r = rasterize_uv_triangles(tris, W, H, 0.0);
  std::vector<char> in(static_cast<std::size_t>(W) * H, 0);
  for (int y = 1; y + 1 < H; ++y)
    for (int x = 1; x + 1 < W; ++x) {
      bool all = true;
      for (int dy = -1; dy <= 1 && all; ++dy)
        for (int dx = -1; dx <= 1 && all; ++dx) all = r.triangle[static_cast<std::size_t>(y + dy) * W + x + dx] >= 0;
      in[static_cast<std::size_t>(y) * W + x] = all;
    }
  return in;
}

/// Fraction of chart-interior texels (`mask`; empty = all) with a clear
/// height slope along u (the steeper half of the masked slopes, and at least
/// 0.002 over two texels: a smooth vertex-colour bake has small slopes) whose
/// normal map x component tilts against it (n.x < 0.5 for a rising slope):
/// near 1 for a normal map derived from that height, 0.5 for an unrelated one.
/// 0 when no texel has a slope.
inline double normal_follows_height(const Image& normal, const Image& height, const std::vector<char>& mask = {}) {
  auto used = [&](int x, int y) { return mask.empty() || mask[static_cast<std::size_t>(y) * height.width + x]; };
  auto slope = [&](int x, int y) { return height.at(x + 1, y, 0) - height.at(x - 1, y, 0); };
  std::vector<float> mag;
  for (int y = 0; y < height.height; ++y)
    for (int x = 1; x + 1 < height.width; ++x)
      if (used(x, y)) mag.push_back(std::abs(slope(x, y)));
  if (mag.empty()) return 0.0;
  std::nth_element(mag.begin(), mag.begin() + mag.size() / 2, mag.end());
  const float threshold = std::max(0.002f, mag[mag.size() / 2]);
  std::size_t n = 0, agree = 0;
  for (int y = 0; y < height.height; ++y)
    for (int x = 1; x + 1 < height.width; ++x) {
      if (!used(x, y)) continue;
      const float d = slope(x, y);
      if (std::abs(d) < threshold) continue;
      ++n;
      agree += (d > 0) == (normal.at(x, y, 0) < 0.5f);
    }
  return n ? static_cast<double>(agree) / n : 0.0;
}

}  // namespace surftex::test
