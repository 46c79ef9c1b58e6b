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
#include "texture/material_tile.h"

namespace surftex::cli {
namespace {

struct Args {
  std::vector<std::string> inputs, masks;
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
  std::vector<std::string> all_inputs = a.inputs;
  for (const auto& m : a.masks)
    if (m != "-") all_inputs.push_back(m);
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
  write_material_tile(a.out, r, info, a.common.force);

  nlohmann::json rep;
  rep["output"] = a.out;
  rep["sources"] = info.sources;
  rep["size"] = a.size;
  rep["layers"] = r.layers.size();
  rep["layers_per_pair"] = a.layers;
  rep["sign_changes"] = r.sign_changes;
  rep["mask_agreement"] = r.mask_agreement;
  rep["seconds"] = {{"keys", r.seconds_keys}, {"morph", r.seconds_morph}, {"synthesis", r.seconds_synthesis}};
  RunFiles files{a.inputs, files_in_folder(a.out)};
  for (const std::string& m : a.masks)
    if (m != "-") files.inputs.push_back(m);
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
       app.add_option("-o,--output", a->out, "Output folder (layer_NNN.png, mask_NNN.png, layers.tif, tile.json)")
           ->required();
       app.add_option("--mask", a->masks,
                      "Painted feature mask per texture, in the same order (luminance >= 0.5 = feature; "
                      "'-' = automatic for that texture). Default: all automatic");
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

}  // namespace
}  // namespace surftex::cli
