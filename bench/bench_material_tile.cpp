// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: a material-space tile of 8 layers (M = 7) of 256x256 with 3
// pyramid levels from two real textures (Ray et al. 2009 report 5 minutes per
// morph for 8 layers at 256x256). Prints one JSON line: total and per-stage
// seconds, the largest wrap-seam ratio over the layers, sign changes.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/material_tile.h"
#include "texture/wrap_seam_ratio.h"

using namespace surftex;

int main(int argc, char** argv) {
  std::string dir = std::string(SURFTEX_SHARED_DATA_DIR) + "/textures/";
  std::string a = argc > 1 ? argv[1] : "pebbles_256.png", b = argc > 2 ? argv[2] : "box_tree_leaves_256.png";
  std::vector<MaterialKey> keys = {{read_image(dir + a), {}, a}, {read_image(dir + b), {}, b}};
  MaterialTileOptions opt;
  opt.size = 256;
  opt.layers = 7;
  opt.synthesis.levels = 3;
  opt.seed = 1;
  Timer t;
  MaterialTileResult r = make_material_tile(keys, opt);
  double total = t.seconds();
  double worst = 0;
  for (const Image& l : r.layers) worst = std::max(worst, wrap_seam_ratio(l));
  if (const char* out = std::getenv("BENCH_OUT")) {
    MaterialTileInfo info{{a, b}, {"", ""}, opt.seed, opt.layers};
    write_material_tile(out, r, info, true);
  }
  nlohmann::json j;
  j["bench"] = "material_tile";
  j["inputs"] = {a, b};
  j["layers"] = r.layers.size();
  j["size"] = opt.size;
  j["levels"] = 3;
  j["seconds_total"] = total;
  j["seconds"] = {{"key_tiles", r.seconds_keys}, {"morph", r.seconds_morph}, {"synthesis", r.seconds_synthesis}};
  j["max_wrap_seam_ratio"] = worst;
  j["sign_changes"] = r.sign_changes;
  j["mask_agreement_min"] = *std::min_element(r.mask_agreement.begin(), r.mask_agreement.end());
  std::printf("%s\n", j.dump().c_str());
  return 0;
}
