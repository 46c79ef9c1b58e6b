// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/material_tile_io.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/json_input.h"

namespace surftex {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
namespace ji = json_input;

// tile.json bounds: a layer is an image (image_limits() per layer); the tile
// together may hold 4 times the per-image decoded limit; at most 4096 layers.
constexpr long long kMaxLayers = 4096;

struct TileJson {
  std::string source;  // tile.json's path, for messages
  const json& root;
};

const json& field(const TileJson& t, const json& obj, const char* name, const std::string& where) {
  auto it = obj.find(name);
  if (it == obj.end()) ji::fail(t.source, ji::line_of(obj), where.empty() ? name : where + "." + name, "missing");
  return *it;
}

long long int_field(const TileJson& t, const json& obj, const char* name, long long lo, long long hi) {
  const json& v = field(t, obj, name, "");
  const bool ok = v.is_number_integer() &&
                  (v.is_number_unsigned() ? v.get<unsigned long long>() <= static_cast<unsigned long long>(hi)
                                          : (v.get<long long>() >= lo && v.get<long long>() <= hi));
  if (!ok || v.get<long long>() < lo)
    ji::fail(t.source, ji::line_of(obj, name), name,
             "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + ji::describe(v));
  return v.get<long long>();
}

// A layer's file name (field `key`: "file" or a map kind): a plain name
// inside the tile folder.
std::string layer_file(const TileJson& t, const json& l, const std::string& where, const char* key = "file") {
  const json& file = field(t, l, key, where);
  const int line = ji::line_of(l, key);
  const std::string f = where + "." + key;
  if (!file.is_string() || file.get_ref<const std::string&>().empty())
    ji::fail(t.source, line, f, "must be a non-empty string, got " + ji::describe(file));
  const std::string& name = file.get_ref<const std::string&>();
  if (name.size() > 255 || name == "." || name == ".." || name.find('/') != std::string::npos ||
      name.find('\\') != std::string::npos || name.find('\0') != std::string::npos)
    ji::fail(t.source, line, f, "must be a file name inside the tile folder, got " + ji::describe(file));
  return name;
}

// The map kinds a tile may carry beside its colour layers, their channels.
struct MapKind {
  const char* name;
  int channels;
  std::vector<Image> MaterialTile::*layers;
};
constexpr MapKind kMapKinds[] = {{"normal", 3, &MaterialTile::normal_layers},
                                 {"height", 1, &MaterialTile::height_layers},
                                 {"roughness", 1, &MaterialTile::roughness_layers}};

// "maps": an array of distinct kind names (absent = none); the kinds' indices.
std::vector<int> map_kinds(const TileJson& t, const json& j) {
  std::vector<int> kinds;
  auto it = j.find("maps");
  if (it == j.end()) return kinds;
  const int line = ji::line_of(j, "maps");
  if (!it->is_array() || it->size() > std::size(kMapKinds))
    ji::fail(t.source, line, "maps", "must be an array of at most 3 of \"normal\", \"height\", \"roughness\", got " +
                                         ji::describe(*it));
  for (std::size_t i = 0; i < it->size(); ++i) {
    const json& v = (*it)[i];
    int k = -1;
    for (int c = 0; c < static_cast<int>(std::size(kMapKinds)); ++c)
      if (v.is_string() && v.get_ref<const std::string&>() == kMapKinds[c].name) k = c;
    const std::string f = "maps[" + std::to_string(i) + "]";
    if (k < 0) ji::fail(t.source, ji::element_line(j, "maps", i), f, "must be \"normal\", \"height\" or \"roughness\", got " + ji::describe(v));
    if (std::find(kinds.begin(), kinds.end(), k) != kinds.end())
      ji::fail(t.source, ji::element_line(j, "maps", i), f, "repeats " + ji::describe(v));
    kinds.push_back(k);
  }
  return kinds;
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
  for (const MapKind& k : kMapKinds) {
    const std::vector<Image>& maps = tile.*(k.layers);
    if (maps.empty()) continue;
    if (maps.size() != tile.layers.size())
      throw InvalidInputError("material tile: " + std::to_string(maps.size()) + " " + k.name + " layers for " +
                              std::to_string(tile.layers.size()) + " layers");
    for (std::size_t i = 0; i < maps.size(); ++i) {
      const Image& l = maps[i];
      const bool channels_ok = k.channels == 3 ? l.channels >= 3 : l.channels == 1;
      if (l.width != l0.width || l.height != l0.height || !channels_ok ||
          l.data.size() != static_cast<std::size_t>(l.width) * l.height * l.channels)
        throw InvalidInputError("material tile: " + std::string(k.name) + " layer " + std::to_string(i) + " is " +
                                std::to_string(l.width) + "x" + std::to_string(l.height) + "x" +
                                std::to_string(l.channels) + ", layer 0 is " + std::to_string(l0.width) + "x" +
                                std::to_string(l0.height) + " (" + k.name + " needs " +
                                (k.channels == 3 ? ">= 3 channels)" : "1 channel)"));
    }
  }
}

MaterialTile read_material_tile(const std::string& dir) {
  const fs::path json_path = fs::path(dir) / "tile.json";
  std::error_code ec;
  if (!fs::is_regular_file(json_path, ec))
    throw IOError("material tile '" + dir + "': cannot open '" + json_path.string() + "'");
  const std::string src = json_path.string();
  const json j = ji::parse(ji::read_file(src, "material tile description"), src);
  const TileJson t{src, j};
  if (!j.is_object()) ji::fail(src, 1, "(top level)", "must be an object, got " + ji::describe(j));
  const json& fmt = field(t, j, "format", "");
  if (!fmt.is_string() || fmt.get_ref<const std::string&>() != "surftex material tile")
    ji::fail(src, ji::line_of(j, "format"), "format", "must be \"surftex material tile\", got " + ji::describe(fmt));
  const ImageLimits& lim = image_limits();
  MaterialTile tile;
  tile.size = static_cast<int>(int_field(t, j, "size", 1, lim.max_side()));
  const int channels = static_cast<int>(int_field(t, j, "channels", 1, ImageLimits::kMaxChannels));
  const long long count = int_field(t, j, "layers", 1, kMaxLayers);
  tile.layers_per_pair = static_cast<int>(int_field(t, j, "layers_per_pair", 0, kMaxLayers));
  const std::vector<int> kinds = map_kinds(t, j);
  int map_channels = 0;
  for (int k : kinds) map_channels += kMapKinds[k].channels;
  const long long layer_bytes = static_cast<long long>(tile.size) * tile.size * channels * 4;
  const long long maps_bytes = static_cast<long long>(tile.size) * tile.size * map_channels * 4;
  if (layer_bytes > lim.max_bytes() || (layer_bytes + maps_bytes) * count > 4 * lim.max_bytes())
    ji::fail(src, ji::line_of(j, "size"), "size",
             std::to_string(count) + " layers of " + std::to_string(tile.size) + "x" + std::to_string(tile.size) + "x" +
                 std::to_string(channels) + (map_channels ? " (+" + std::to_string(map_channels) + " map channels)" : "") +
                 " hold " + std::to_string(((layer_bytes + maps_bytes) * count) >> 20) +
                 " MiB decoded; the limit is " + std::to_string(lim.max_bytes() >> 20) + " MiB a layer and " +
                 std::to_string((4 * lim.max_bytes()) >> 20) + " MiB a tile (--max-image-pixels raises it)");
  const json& list = field(t, j, "layer_list", "");
  if (!list.is_array()) ji::fail(src, ji::line_of(j, "layer_list"), "layer_list", "must be an array, got " + ji::describe(list));
  if (static_cast<long long>(list.size()) != count)
    ji::fail(src, ji::line_of(j, "layer_list"), "layer_list",
             "has " + std::to_string(list.size()) + " entries but 'layers' is " + std::to_string(count));
  // Every entry and every layer file's header is checked before any pixel is decoded.
  std::vector<std::string> files;
  std::vector<std::string> map_files[std::size(kMapKinds)];
  // A layer's map of one kind: named, present, of the tile's size and the kind's channels.
  auto map_file = [&](const TileJson& tj, const json& l, const std::string& lw, const char* kind, int ch) {
    const std::string name = layer_file(tj, l, lw, kind);
    const fs::path p = fs::path(dir) / name;
    const int line = ji::line_of(l, kind);
    if (!fs::is_regular_file(p, ec))
      ji::fail(src, line, lw + "." + kind, "map file '" + p.string() + "' missing");
    const ImageHeader h = read_image_header(p.string());
    if (h.width != tile.size || h.height != tile.size || h.channels != ch)
      ji::fail(src, line, lw + "." + kind,
               "map file '" + p.string() + "' is " + std::to_string(h.width) + "x" + std::to_string(h.height) + "x" +
                   std::to_string(h.channels) + ", the tile needs " + std::to_string(tile.size) + "x" +
                   std::to_string(tile.size) + "x" + std::to_string(ch) + " (size " + std::to_string(tile.size) +
                   ", " + kind + " maps have " + std::to_string(ch) + (ch == 1 ? " channel)" : " channels)"));
    return p.string();
  };
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string lw = "layer_list[" + std::to_string(i) + "]";
    const json& l = list[i];
    if (!l.is_object()) ji::fail(src, ji::element_line(j, "layer_list", i), lw, "must be an object, got " + ji::describe(l));
    const std::string name = layer_file(t, l, lw);
    const json& m = field(t, l, "m", lw);
    if (!m.is_number() || !std::isfinite(m.get<double>()) || std::fabs(m.get<double>()) > 1e6)
      ji::fail(src, ji::line_of(l, "m"), lw + ".m", "must be a finite number in [-1e6, 1e6], got " + ji::describe(m));
    const fs::path p = fs::path(dir) / name;
    if (!fs::is_regular_file(p, ec))
      throw IOError("material tile '" + dir + "': layer file '" + p.string() + "' missing (" + src + ": line " +
                    std::to_string(ji::line_of(l, "file")) + ": field " + lw + ".file)");
    const ImageHeader h = read_image_header(p.string());
    if (h.width != tile.size || h.height != tile.size || h.channels != channels)
      throw InvalidInputError("material tile '" + dir + "': layer file '" + p.string() + "' is " +
                              std::to_string(h.width) + "x" + std::to_string(h.height) + "x" +
                              std::to_string(h.channels) + ", tile.json declares " + std::to_string(tile.size) +
                              "x" + std::to_string(tile.size) + "x" + std::to_string(channels));
    files.push_back(p.string());
    tile.material.push_back(m.get<double>());
    for (int k : kinds) map_files[k].push_back(map_file(t, l, lw, kMapKinds[k].name, kMapKinds[k].channels));
  }
  auto decode = [&](const std::string& f, int ch, std::vector<Image>& into) {
    Image img = read_image(f);
    if (img.width != tile.size || img.height != tile.size || img.channels != ch)
      throw InvalidInputError("material tile '" + dir + "': layer file '" + f + "' decoded as " +
                              std::to_string(img.width) + "x" + std::to_string(img.height) + "x" +
                              std::to_string(img.channels) + ", unlike its header");
    into.push_back(std::move(img));
  };
  for (const std::string& f : files) decode(f, channels, tile.layers);
  for (int k : kinds)
    for (const std::string& f : map_files[k]) decode(f, kMapKinds[k].channels, tile.*(kMapKinds[k].layers));
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
  return sample_material_layers(tile.layers, s, t, m);
}

Vec3f sample_material_layers(const std::vector<Image>& layers, double s, double t, double m) {
  Vec3f acc{0.f, 0.f, 0.f};
  if (!std::isfinite(s) || !std::isfinite(t)) return acc;
  const int L = static_cast<int>(layers.size());
  if (L == 1) {
    bilinear_add(layers[0], s, t, 1.f, acc);
    return acc;
  }
  const double mm = std::isfinite(m) ? std::clamp(m, 0.0, 1.0) : 0.0;
  const double z = mm * (L - 1);
  const int k0 = std::min(static_cast<int>(z), L - 2);
  const float a = static_cast<float>(z - k0);
  if (a < 1.f) bilinear_add(layers[k0], s, t, 1.f - a, acc);
  if (a > 0.f) bilinear_add(layers[k0 + 1], s, t, a, acc);
  return acc;
}

}  // namespace surftex
