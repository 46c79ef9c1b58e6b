// SPDX-License-Identifier: AGPL-3.0-or-later
// write_material_tile (declared in material_tile.h): the folder format of a 3D tile.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/output_file.h"
#include "texture/material_tile.h"

namespace surftex {

namespace fs = std::filesystem;

void write_material_tile(const std::string& dir, const MaterialTileResult& tile, const MaterialTileInfo& info,
                         bool overwrite) {
  if (tile.layers.empty()) throw InvalidInputError("write_material_tile: the tile has no layer");
  std::error_code ec;
  fs::path dest = fs::absolute(fs::path(dir), ec);
  if (dest.filename().empty()) dest = dest.parent_path();
  if (fs::exists(dest, ec) && !overwrite)
    throw IOError("output folder '" + dir + "' already exists (pass --force to replace it)");
  if (fs::exists(dest, ec) && !fs::is_directory(dest, ec))
    throw IOError("output '" + dir + "' exists and is not a folder");
  if (!dest.parent_path().empty()) ensure_directory(dest.parent_path().string());
  const std::string tag = "." + dest.filename().string() + ".partial-" + std::to_string(::getpid());
  fs::path stage = dest.parent_path() / tag;
  fs::remove_all(stage, ec);
  ensure_directory(stage.string());
  try {
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
      l["sign_changes"] = tile.sign_changes[i];
      l["mask_agreement"] = tile.mask_agreement[i];
      list.push_back(l);
    }
    j["layer_list"] = list;
    write_image_layers((stage / "layers.tif").string(), tile.layers);
    write_file_atomic((stage / "tile.json").string(), j.dump(2) + "\n");
    fs::path old;
    if (fs::exists(dest, ec)) {
      old = dest.parent_path() / ("." + dest.filename().string() + ".old-" + std::to_string(::getpid()));
      fs::remove_all(old, ec);
      fs::rename(dest, old);
    }
    fs::rename(stage, dest);
    if (!old.empty()) fs::remove_all(old, ec);
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(stage, ec);
    throw IOError("cannot write material tile '" + dir + "': " + e.what());
  } catch (...) {
    fs::remove_all(stage, ec);
    throw;
  }
}

}  // namespace surftex
