// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex material-tile A.png B.png [C.png ...] -o DIR`: a material-space 3D
// tile (Ray et al. 2009, section 1) morphing the key textures into each other.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "surftex/command.h"
#include "texture/material_space/material_tile.h"
#include "texture/material_space/material_tile_json.h"

namespace surftex::cli {
namespace {
namespace material_tile_command {  // named: the unity build joins these files

struct Args {
  std::vector<std::string> inputs, masks;
  std::vector<std::string> normals, heights, roughnesses;  // one per input, or none
  std::string out;
  int layers = 8, size = 256, levels = 0, steps = 0;
  std::string auto_rule = "luminance";
  bool tileable = false;
  CommonOptions common;
};

int run(const Args& a) {
  auto keep = apply_thread_limit(a.common.threads);
  if (!a.masks.empty() && a.masks.size() != a.inputs.size())
    throw InvalidInputError("--mask given " + std::to_string(a.masks.size()) + " times for " +
                            std::to_string(a.inputs.size()) + " textures (give one per texture, '-' = automatic)");
  // Exemplar maps: each option once per texture, in texture order.
  const std::pair<const std::vector<std::string>*, const char*> map_options[] = {
      {&a.normals, "--exemplar-normal"}, {&a.heights, "--exemplar-height"}, {&a.roughnesses, "--exemplar-roughness"}};
  for (const auto& [files, what] : map_options)
    if (!files->empty() && files->size() != a.inputs.size())
      throw InvalidInputError(std::string(what) + " given " + std::to_string(files->size()) + " times for " +
                              std::to_string(a.inputs.size()) + " textures (give one per texture, in the same order)");
  std::vector<std::string> all_inputs = a.inputs;
  for (const auto& m : a.masks)
    if (m != "-") all_inputs.push_back(m);
  for (const auto& [files, what] : map_options)
    for (const auto& f : *files) {
      require_input_file(f, what);
      all_inputs.push_back(f);
    }
  for (const auto& in : all_inputs) require_input_file(in, "input");
  namespace fs = std::filesystem;
  for (const auto& in : all_inputs) {
    std::error_code ec;
    if (fs::exists(a.out, ec) && fs::equivalent(fs::path(a.out), fs::path(in).parent_path(), ec))
      throw InvalidInputError("output folder '" + a.out + "' holds the input '" + in + "'; choose another folder");
  }
  if (!a.common.force && fs::exists(a.out))
    throw IOError("output '" + a.out + "' already exists (pass --force to replace it)");

  std::vector<MaterialKey> keys;
  for (std::size_t i = 0; i < a.inputs.size(); ++i) {
    MaterialKey k;
    k.texture = read_image(a.inputs[i]);
    k.name = fs::path(a.inputs[i]).filename().string();
    if (!a.masks.empty() && a.masks[i] != "-") k.mask = read_feature_mask(a.masks[i]);
    // A map must match its texture texel for texel (checked from its header before decoding).
    for (const auto& [files, what] : map_options) {
      if (files->empty()) continue;
      const std::string& f = (*files)[i];
      const ImageHeader h = read_image_header(f);
      if (h.width != k.texture.width || h.height != k.texture.height)
        throw InvalidInputError(std::string(what) + " '" + f + "' is " + std::to_string(h.width) + " x " +
                                std::to_string(h.height) + ", its texture '" + a.inputs[i] + "' is " +
                                std::to_string(k.texture.width) + " x " + std::to_string(k.texture.height) +
                                " (maps must match their texture texel for texel)");
      if (files == &a.normals && h.channels < 3)
        throw InvalidInputError(std::string(what) + " '" + f + "' has " + std::to_string(h.channels) +
                                " channels; a tangent-space normal map needs RGB");
      Image m = read_image(f);
      (files == &a.normals ? k.normal : files == &a.heights ? k.height : k.roughness) = std::move(m);
    }
    keys.push_back(std::move(k));
  }
  MaterialTileOptions opt;
  opt.size = a.size;
  opt.layers = a.layers;
  opt.keys_are_tileable = a.tileable;
  opt.seed = a.common.seed;
  opt.synthesis.levels = a.levels;
  opt.morph.steps = a.steps;
  opt.auto_mask.rule =
      a.auto_rule == "gradient" ? FeatureMaskOptions::Rule::Gradient : FeatureMaskOptions::Rule::Luminance;
  opt.progress = terminal_progress(a.common.quiet);
  check_budget(estimate_material_tile(a.size, a.layers, static_cast<int>(keys.size()), keys[0].texture.width,
                                      keys[0].texture.height),
               a.common);
  MaterialTileResult r = make_material_tile(keys, opt);

  MaterialTileInfo info;
  for (const auto& k : keys) info.sources.push_back(k.name);
  for (std::size_t i = 0; i < a.inputs.size(); ++i) info.masks.push_back(a.masks.empty() ? "" : a.masks[i] == "-" ? "" : a.masks[i]);
  info.seed = a.common.seed;
  info.layers_per_pair = a.layers;
  info.normal_sources = a.normals;
  info.height_sources = a.heights;
  info.roughness_sources = a.roughnesses;
  write_material_tile(a.out, r, info, a.common.force);

  nlohmann::json rep = to_json(r);
  rep["output"] = a.out;
  rep["sources"] = info.sources;
  rep["size"] = a.size;
  rep["layers_per_pair"] = a.layers;
  RunFiles files{a.inputs, files_in_folder(a.out)};
  for (const std::string& m : a.masks)
    if (m != "-") files.inputs.push_back(m);
  nlohmann::json maps = nlohmann::json::array();
  for (const auto& [list, what] : map_options) {
    files.inputs.insert(files.inputs.end(), list->begin(), list->end());
    if (!list->empty()) maps.push_back(std::string(what).substr(std::string("--exemplar-").size()));
  }
  rep["maps"] = maps;
  write_report(a.common, "material-tile", rep, files);
  if (!a.common.quiet)
    std::fprintf(stderr, "material-tile: %zu layers of %dx%d written to %s (%.2f s)\n", r.layers.size(), a.size,
                 a.size, a.out.c_str(), r.seconds_total);
  return 0;
}

SubcommandRegistrar reg{
    {"material-tile",
     "Build a material-space 3D tile (tileable layers morphing texture A into B [into C ...]; "
     "one texture: layers sharing its mask that hide the periodicity)",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<Args>();
       app.add_option("textures", a->inputs, "Key textures, in material order (one or more image files)")
           ->required()
           ->check(CLI::ExistingFile);
       app.add_option("-o,--output", a->out,
                      "Output folder (layer_NNN.png, mask_NNN.png, layers.tif, tile.json; normal_NNN.png, "
                      "height_NNN.png, roughness_NNN.png with exemplar maps)")
           ->required();
       app.add_option("--mask", a->masks,
                      "Painted feature mask per texture, in the same order (luminance >= 0.5 = feature; "
                      "'-' = automatic for that texture). Default: all automatic");
       app.add_option("--exemplar-normal", a->normals,
                      "Tangent-space normal map of each texture (RGB = (n+1)/2, +X right, +Y up; the texture's "
                      "size), given once per texture in the same order: carried through the same resampling, "
                      "cuts, synthesis and blend as the colour into normal_NNN.png (default none)");
       app.add_option("--exemplar-height", a->heights,
                      "Height map of each texture (grey, [0,1]; the texture's size), once per texture in the same "
                      "order: into height_NNN.png (16-bit) the same way (default none)");
       app.add_option("--exemplar-roughness", a->roughnesses,
                      "Roughness map of each texture (grey, [0,1]; the texture's size), once per texture in the "
                      "same order: into roughness_NNN.png the same way (default none)");
       app.add_option("--layers", a->layers, "M: layer intervals per pair of keys (1..256, default 8)")
           ->check(CLI::Range(1, 256));
       app.add_option("--size", a->size,
                      "Layer side in texels (16..2048, default 256; each pyramid level halves it, rounding up)")
           ->check(CLI::Range(16, 2048));
       app.add_option("--levels", a->levels,
                      "Pyramid levels of the synthesis (0 = automatic down to about 32x32, default 0; 0..8)")
           ->check(CLI::Range(0, 8));
       app.add_option("--steps", a->steps,
                      "Advection steps N of the mask morph (0 = automatic, default 0; else >= --layers)")
           ->check(CLI::Range(0, 100000));
       app.add_option("--auto-mask", a->auto_rule,
                      "Rule for automatic masks: luminance (Otsu, minority class) or gradient (Otsu on "
                      "gradient magnitude); default luminance")
           ->check(CLI::IsMember({"luminance", "gradient"}));
       app.add_flag("--tileable", a->tileable,
                    "The textures already tile: use their centred square as key tile instead of "
                    "synthesising a tileable one (default off)");
       add_common_options(app, a->common);
       return [a] { return run(*a); };
     }}};

}  // namespace material_tile_command
}  // namespace
}  // namespace surftex::cli
