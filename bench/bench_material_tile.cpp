// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: material-space 3D tiles (Ray et al. 2009, section 1; they report
// 5 minutes per morph for 8 layers at 256x256 with 3 pyramid levels). Two
// cases, one JSON line each (total and per-stage seconds, process CPU
// seconds, the largest wrap-seam ratio over the layers, sign changes):
//  - cli_defaults: `surftex material-tile A B --layers 8 --size 256` as
//    issue 19 ran it: 128 x 128 crops (top-left) of pebbles_256 and
//    box_tree_leaves_256, MaterialTileOptions{} (layers 8 -> 9 layers, size
//    256, automatic pyramid levels: 4 for 256), sets nothing else;
//  - paper: the paper's table setting: the full 256 px textures, layers 7
//    (8 layers), 3 pyramid levels.
// Measurement history: docs/decisions/50N-*.md.
//
// Usage: bench_material_tile [cli_defaults|paper|all] [threads]
// BENCH_OUT=DIR writes the cli_defaults tile there. Tuning:
// SURFTEX_BENCH_MT_SET="pca_dims=5,ann_eps=4,candidates=2,fine_ann_passes=1,
// fine_ann_only_mismatched=1,coarse_passes=20,fine_passes=3" overrides those
// synthesis options (cases
// then say "tuned").
#include <tbb/global_control.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/image_ops.h"
#include "texture/material_space/material_tile.h"
#include "texture/wrap_seam_ratio.h"

using namespace surftex;

namespace {

void run_case(const std::string& name, int crop_side, int layers, int levels) {
  const std::string dir = std::string(SURFTEX_SHARED_DATA_DIR) + "/textures/";
  const std::string a = "pebbles_256.png", b = "box_tree_leaves_256.png";
  Image ia = read_image(dir + a), ib = read_image(dir + b);
  if (crop_side > 0) {
    ia = crop(ia, 0, 0, crop_side, crop_side);
    ib = crop(ib, 0, 0, crop_side, crop_side);
  }
  std::vector<MaterialKey> keys = {{ia, {}, a}, {ib, {}, b}};
  MaterialTileOptions opt;
  if (layers > 0) opt.layers = layers;
  opt.synthesis.levels = levels;
  std::string tuned;
  if (const char* set = std::getenv("SURFTEX_BENCH_MT_SET")) {
    std::stringstream ss(set);
    for (std::string kv; std::getline(ss, kv, ',');) {
      const auto eq = kv.find('=');
      if (eq == std::string::npos) continue;
      const std::string k = kv.substr(0, eq);
      const double v = std::atof(kv.c_str() + eq + 1);
      ConstrainedSynthesisOptions& so = opt.synthesis;
      if (k == "pca_dims") so.pca_dims = int(v);
      else if (k == "ann_eps") so.ann_eps = v;
      else if (k == "candidates") so.candidates = int(v);
      else if (k == "fine_ann_passes") so.fine_ann_passes = int(v);
      else if (k == "fine_ann_only_mismatched") so.fine_ann_only_mismatched = v != 0;
      else if (k == "coarse_passes") so.coarse_passes = int(v);
      else if (k == "fine_passes") so.fine_passes = int(v);
      else continue;
      tuned += (tuned.empty() ? "" : ",") + kv;
    }
  }
  Timer t;
  const std::clock_t c0 = std::clock();
  MaterialTileResult r = make_material_tile(keys, opt);
  const double total = t.seconds();
  const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  double worst = 0;
  for (const Image& l : r.layers) worst = std::max(worst, wrap_seam_ratio(l));
  if (const char* out = std::getenv("BENCH_OUT"); out && name == "cli_defaults") {
    MaterialTileInfo info{{a, b}, {"", ""}, opt.seed, opt.layers};
    write_material_tile(out, r, info, true);
  }
  nlohmann::json j;
  j["bench"] = "material_tile_" + name;
  j["sets"] = name == "paper" ? "layers 7, levels 3 (the paper's table)" : "nothing (CLI defaults)";
  if (!tuned.empty()) j["tuned"] = tuned;
  j["inputs"] = {a, b};
  j["exemplar_side"] = ia.width;
  j["layers"] = r.layers.size();
  j["size"] = opt.size;
  j["levels"] = levels;
  j["seconds_total"] = total;
  j["cpu_seconds"] = cpu;
  j["threads"] = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  j["seconds"] = {{"key_tiles", r.seconds_keys}, {"morph", r.seconds_morph}, {"synthesis", r.seconds_synthesis}};
  j["max_wrap_seam_ratio"] = worst;
  j["sign_changes"] = r.sign_changes;
  j["mask_agreement_min"] = *std::min_element(r.mask_agreement.begin(), r.mask_agreement.end());
  std::printf("%s\n", j.dump().c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string which = argc > 1 ? argv[1] : "all";
  std::unique_ptr<tbb::global_control> limit;
  if (argc > 2 && std::atoi(argv[2]) > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::atoi(argv[2]));
  try {
    if (which == "all" || which == "cli_defaults") run_case("cli_defaults", 128, 0, 0);
    if (which == "all" || which == "paper") run_case("paper", 0, 7, 3);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
