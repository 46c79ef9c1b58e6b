// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Checks of finished assets shared by the CLI tests (issue 16 items 1-3):
// byte-identical files in an output folder, the JSON chunk of a GLB, the
// bit depth of a PNG, and whether a normal map follows a height map's slopes.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/image.h"

namespace surftex::test {

inline std::string file_bytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

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

/// Bit depth of a PNG (IHDR byte 24), 0 if not a PNG.
inline int png_bit_depth(const std::string& path) {
  const std::string b = file_bytes(path);
  if (b.size() < 25 || b.compare(1, 3, "PNG") != 0) return 0;
  return static_cast<unsigned char>(b[24]);
}

/// Fraction of texels with a clear height slope along u (|dh| > 0.05 over
/// two texels) whose normal map x component tilts against it (n.x < 0.5 for
/// a rising slope): near 1 on the charts of a normal map derived from that
/// height, 0.5 for an unrelated one; the gutters (normals dilated from the
/// charts, heights from the colour's dilation) bring a derived map to ~0.8.
inline double normal_follows_height(const Image& normal, const Image& height) {
  std::size_t n = 0, agree = 0;
  for (int y = 0; y < height.height; ++y)
    for (int x = 1; x + 1 < height.width; ++x) {
      const float d = height.at(x + 1, y, 0) - height.at(x - 1, y, 0);
      if (std::abs(d) < 0.05f) continue;
      ++n;
      agree += (d > 0) == (normal.at(x, y, 0) < 0.5f);
    }
  return n ? static_cast<double>(agree) / n : 0.0;
}

}  // namespace surftex::test
