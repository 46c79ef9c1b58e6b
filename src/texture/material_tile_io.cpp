// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_tile_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "geometry/errors.h"
#include "geometry/image_io.h"

namespace surftex {

namespace {

namespace fs = std::filesystem;

const nlohmann::json& field(const nlohmann::json& j, const char* name, const std::string& where) {
  auto it = j.find(name);
  if (it == j.end()) throw InvalidInputError(where + ": field '" + name + "' missing");
  return *it;
}

long long int_field(const nlohmann::json& j, const char* name, const std::string& where, long long lo) {
  const nlohmann::json& v = field(j, name, where);
  if (!v.is_number_integer() || v.get<long long>() < lo)
    throw InvalidInputError(where + ": field '" + name + "' must be an integer >= " + std::to_string(lo) +
                            ", got " + v.dump());
  return v.get<long long>();
}

}  // namespace

void validate_material_tile(const MaterialTile& tile) {
  if (tile.layers.empty()) throw InvalidInputError("material tile: no layer");
  const Image& l0 = tile.layers[0];
  if (l0.empty() || l0.width != l0.height)
    throw InvalidInputError("material tile: layer 0 is " + std::to_string(l0.width) + "x" +
                            std::to_string(l0.height) + " (must be square and non-empty)");
  for (std::size_t i = 0; i < tile.layers.size(); ++i) {
    const Image& l = tile.layers[i];
    if (l.width != l0.width || l.height != l0.height || l.channels != l0.channels)
      throw InvalidInputError("material tile: layer " + std::to_string(i) + " is " + std::to_string(l.width) + "x" +
                              std::to_string(l.height) + "x" + std::to_string(l.channels) + ", layer 0 is " +
                              std::to_string(l0.width) + "x" + std::to_string(l0.height) + "x" +
                              std::to_string(l0.channels));
    if (l.data.size() != static_cast<std::size_t>(l.width) * l.height * l.channels)
      throw InvalidInputError("material tile: layer " + std::to_string(i) + " has a wrong data size");
  }
}

MaterialTile read_material_tile(const std::string& dir) {
  const fs::path json_path = fs::path(dir) / "tile.json";
  std::ifstream in(json_path, std::ios::binary);
  if (!in) throw IOError("material tile '" + dir + "': cannot open '" + json_path.string() + "'");
  std::stringstream buf;
  buf << in.rdbuf();
  const std::string where = json_path.string();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(buf.str());
  } catch (const nlohmann::json::parse_error& e) {
    throw InvalidInputError(where + ": malformed JSON at byte " + std::to_string(e.byte) + ": " + e.what());
  }
  if (!j.is_object()) throw InvalidInputError(where + ": top level must be an object");
  const nlohmann::json& fmt = field(j, "format", where);
  if (!fmt.is_string() || fmt.get<std::string>() != "surftex material tile")
    throw InvalidInputError(where + ": field 'format' must be \"surftex material tile\", got " + fmt.dump());
  MaterialTile tile;
  tile.size = static_cast<int>(int_field(j, "size", where, 1));
  const int channels = static_cast<int>(int_field(j, "channels", where, 1));
  const long long count = int_field(j, "layers", where, 1);
  tile.layers_per_pair = static_cast<int>(int_field(j, "layers_per_pair", where, 0));
  const nlohmann::json& list = field(j, "layer_list", where);
  if (!list.is_array()) throw InvalidInputError(where + ": field 'layer_list' must be an array");
  if (static_cast<long long>(list.size()) != count)
    throw InvalidInputError(where + ": 'layers' is " + std::to_string(count) + " but 'layer_list' has " +
                            std::to_string(list.size()) + " entries");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string lw = where + ": layer_list[" + std::to_string(i) + "]";
    const nlohmann::json& l = list[i];
    if (!l.is_object()) throw InvalidInputError(lw + " must be an object");
    const nlohmann::json& file = field(l, "file", lw);
    if (!file.is_string() || file.get<std::string>().empty())
      throw InvalidInputError(lw + ": field 'file' must be a non-empty string");
    const nlohmann::json& m = field(l, "m", lw);
    if (!m.is_number()) throw InvalidInputError(lw + ": field 'm' must be a number, got " + m.dump());
    const fs::path p = fs::path(dir) / file.get<std::string>();
    std::error_code ec;
    if (!fs::is_regular_file(p, ec))
      throw IOError("material tile '" + dir + "': layer file '" + p.string() + "' missing");
    Image img = read_image(p.string());
    if (img.width != tile.size || img.height != tile.size || img.channels != channels)
      throw InvalidInputError("material tile '" + dir + "': layer file '" + p.string() + "' is " +
                              std::to_string(img.width) + "x" + std::to_string(img.height) + "x" +
                              std::to_string(img.channels) + ", tile.json declares " + std::to_string(tile.size) +
                              "x" + std::to_string(tile.size) + "x" + std::to_string(channels));
    tile.layers.push_back(std::move(img));
    tile.material.push_back(m.get<double>());
  }
  validate_material_tile(tile);
  return tile;
}

namespace {

inline void bilinear_add(const Image& img, double s, double t, float w, Vec3f& acc) {
  const double x = (s - std::floor(s)) * img.width - 0.5;
  const double y = (t - std::floor(t)) * img.height - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const float ax = static_cast<float>(x - fx), ay = static_cast<float>(y - fy);
  int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  int x1 = x0 + 1, y1 = y0 + 1;
  auto wrap = [](int v, int n) { return v < 0 ? v + n : (v >= n ? v - n : v); };
  x0 = wrap(x0, img.width);
  x1 = wrap(x1, img.width);
  y0 = wrap(y0, img.height);
  y1 = wrap(y1, img.height);
  const float wts[4] = {(1 - ax) * (1 - ay) * w, ax * (1 - ay) * w, (1 - ax) * ay * w, ax * ay * w};
  const float* px[4] = {img.pixel(x0, y0), img.pixel(x1, y0), img.pixel(x0, y1), img.pixel(x1, y1)};
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c) acc[c] += wts[k] * px[k][img.channels >= 3 ? c : 0];
}

}  // namespace

Vec3f sample_material_tile(const MaterialTile& tile, double s, double t, double m) {
  Vec3f acc{0.f, 0.f, 0.f};
  if (!std::isfinite(s) || !std::isfinite(t)) return acc;
  const int L = static_cast<int>(tile.layers.size());
  if (L == 1) {
    bilinear_add(tile.layers[0], s, t, 1.f, acc);
    return acc;
  }
  const double mm = std::isfinite(m) ? std::clamp(m, 0.0, 1.0) : 0.0;
  const double z = mm * (L - 1);
  const int k0 = std::min(static_cast<int>(z), L - 2);
  const float a = static_cast<float>(z - k0);
  if (a < 1.f) bilinear_add(tile.layers[k0], s, t, 1.f - a, acc);
  if (a > 0.f) bilinear_add(tile.layers[k0 + 1], s, t, a, acc);
  return acc;
}

}  // namespace surftex
