// SPDX-License-Identifier: AGPL-3.0-or-later
// write_material_tile (declared in material_tile.h): the folder format of a 3D tile.
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/output_file.h"
#include "texture/material_space/material_tile.h"

namespace surftex {

namespace fs = std::filesystem;

void write_material_tile(const std::string& dir, const MaterialTileResult& tile, const MaterialTileInfo& info,
                         bool overwrite) {
  if (tile.layers.empty()) throw InvalidInputError("write_material_tile: the tile has no layer");
  // The folder is written whole into a temporary (or, in a staged run, the
  // run's staging folder) and put in place at once, replacing an old tile
  // as a unit (geometry/output_file.h).
  std::error_code ec;
  fs::path abs = fs::absolute(fs::path(dir), ec).lexically_normal();
  if (abs.filename().empty()) abs = abs.parent_path();
  const fs::path parent = abs.parent_path();
  if (!parent.empty()) ensure_directory(parent.string());
  AtomicOutputFolder out(dir, overwrite);
  const fs::path stage(out.temp_path());
  nlohmann::json j;
  j["format"] = "surftex material tile";
  j["size"] = tile.layers[0].width;
  j["channels"] = tile.layers[0].channels;
  j["layers"] = tile.layers.size();
  j["layers_per_pair"] = info.layers_per_pair;
  j["sources"] = info.sources;
  j["source_masks"] = info.masks;
  j["seed"] = info.seed;
  j["multilayer_file"] = "layers.tif";
  // Map layers (material_tile.h): kind, layers, sources; height as 16-bit PNG.
  struct MapKind {
    const char* name;
    const std::vector<Image>* layers;
    const std::vector<std::string>* sources;
    bool sixteen_bit;
  };
  const MapKind kinds[] = {{"normal", &tile.normal_layers, &info.normal_sources, false},
                           {"height", &tile.height_layers, &info.height_sources, true},
                           {"roughness", &tile.roughness_layers, &info.roughness_sources, false}};
  nlohmann::json maps = nlohmann::json::array();
  for (const MapKind& k : kinds) {
    if (k.layers->empty()) continue;
    if (k.layers->size() != tile.layers.size())
      throw InvalidInputError(std::string("write_material_tile: ") + std::to_string(k.layers->size()) + " " + k.name +
                              " layers for " + std::to_string(tile.layers.size()) + " layers");
    maps.push_back(k.name);
    if (!k.sources->empty()) j["source_maps"][k.name] = *k.sources;
  }
  if (!maps.empty()) j["maps"] = maps;
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < tile.layers.size(); ++i) {
    char name[64], mname[64];
    std::snprintf(name, sizeof name, "layer_%03zu.png", i);
    std::snprintf(mname, sizeof mname, "mask_%03zu.png", i);
    write_image((stage / name).string(), tile.layers[i]);
    write_image((stage / mname).string(), tile.masks[i]);
    nlohmann::json l;
    l["index"] = i;
    l["m"] = tile.material[i];
    l["file"] = name;
    l["mask"] = mname;
    for (const MapKind& k : kinds) {
      if (k.layers->empty()) continue;
      char kname[64];
      std::snprintf(kname, sizeof kname, "%s_%03zu.png", k.name, i);
      WriteImageOptions io;
      io.sixteen_bit = k.sixteen_bit;
      write_image((stage / kname).string(), (*k.layers)[i], io);
      l[k.name] = kname;
    }
    l["sign_changes"] = tile.sign_changes[i];
    l["mask_agreement"] = tile.mask_agreement[i];
    list.push_back(l);
  }
  j["layer_list"] = list;
  write_image_layers((stage / "layers.tif").string(), tile.layers);
  write_file_atomic((stage / "tile.json").string(), j.dump(2) + "\n");
  out.commit();
}

}  // namespace surftex
