// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex tile`: a seamless periodic tile grown from an exemplar by graph-cut
// synthesis on the torus (texture/tileable_tile.h; Ray et al. 2009 section 1).
#include <cstdio>
#include <string>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "surftex/command.h"
#include "texture/tileable_tile.h"
#include "texture/wrap_seam_ratio.h"

namespace surftex::cli {
namespace {
namespace tile_command {  // named: the unity build joins these files

struct TileArgs {
  std::string input, output, preview;
  int size = 0;
  int patch = 0;
  int overlap = 0;
  int passes = TileOptions{}.refinement_passes;
  int straight_seam_steps = TileOptions{}.straight_seam_steps;
  bool synthesis_cut = false;
  CommonOptions common;
};

int run_tile(const TileArgs& a) {
  require_input_file(a.input, "exemplar");
  check_output(a.output, {a.input}, a.common.force);
  if (!a.preview.empty()) check_output(a.preview, {a.input, a.output}, a.common.force);
  auto limit = apply_thread_limit(a.common.threads);
  Image ex = read_image(a.input);
  TileOptions o;
  o.patch_size = a.patch;
  o.overlap = a.overlap;
  o.refinement_passes = a.passes;
  o.straight_seam_steps = a.straight_seam_steps;
  o.choose_cut = !a.synthesis_cut;
  o.seed = a.common.seed;
  o.progress = terminal_progress(a.common.quiet);
  check_budget(estimate_tile(a.size, ex.width, ex.height, a.passes), a.common);
  Timer timer;
  TileResult t = make_tileable_detailed(ex, a.size, o);
  const double seconds = timer.seconds();
  WriteImageOptions wo;
  wo.overwrite = a.common.force;
  write_image(a.output, t.tile, wo);
  if (!a.preview.empty()) {
    Image rep(2 * a.size, 2 * a.size, t.tile.channels);
    for (int y = 0; y < rep.height; ++y)
      for (int x = 0; x < rep.width; ++x)
        for (int c = 0; c < rep.channels; ++c) rep.at(x, y, c) = t.tile.at(x % a.size, y % a.size, c);
    write_image(a.preview, rep, wo);
  }
  nlohmann::json report;
  report["input"] = a.input;
  report["output"] = a.output;
  if (!a.preview.empty()) report["preview"] = a.preview;
  report["size"] = a.size;
  report["patch"] = a.patch;
  report["overlap"] = a.overlap;
  report["passes"] = a.passes;
  report["straight_seam_steps"] = a.straight_seam_steps;
  report["seconds"] = {{"synthesis", seconds}};
  report["wrap_seam_ratio"] = t.wrap_seam_ratio;
  report["wrap_seam_ratio_at_synthesis_cut"] = t.wrap_seam_ratio_at_synthesis_cut;
  report["choose_cut"] = o.choose_cut;
  report["cut_shift"] = {t.shift_x, t.shift_y};
  report["exemplar_wrap_seam_ratio"] =
      ex.width >= 2 && ex.height >= 2 ? wrap_seam_ratio(ex) : 0.0;
  report["seam_cost"] = t.seam_cost;
  report["worst_line_ratio"] = t.worst_line_ratio;
  report["synthesis_cut_percentile"] = {t.synthesis_column_percentile, t.synthesis_row_percentile};
  report["source_matched_wrap_ratio_at_synthesis_cut"] = t.source_matched_wrap_ratio_at_synthesis_cut;
  report["source_matched_worst_line_ratio"] = t.source_matched_worst_line_ratio;
  RunFiles files{{a.input}, {a.output}};
  if (!a.preview.empty()) files.outputs.push_back(a.preview);
  write_report(a.common, "tile", report, files);
  if (!a.common.quiet)
    std::fprintf(stderr,
                 "tile %dx%d written to %s in %.2f s, wrap-seam ratio %.3f (%.3f at the synthesis "
                 "cut, rolled by %d,%d), worst line of the torus %.3f\n",
                 a.size, a.size, a.output.c_str(), seconds, t.wrap_seam_ratio,
                 t.wrap_seam_ratio_at_synthesis_cut, t.shift_x, t.shift_y, t.worst_line_ratio);
  return 0;
}

SubcommandRegistrar reg{
    {"tile", "Grow a seamless periodic tile from an exemplar (graph-cut synthesis on the torus)",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<TileArgs>();
       app.add_option("exemplar", a->input, "Exemplar image (any format OpenImageIO reads)")
           ->required();
       app.add_option("-o,--output", a->output, "Output tile image (format from the extension)")
           ->required();
       app.add_option("--size", a->size, "Tile side in pixels (8..8192)")
           ->required()
           ->check(CLI::Range(8, 8192));
       app.add_option("--patch", a->patch,
                      "Patch side in pixels; 0 = automatic: min(7 size/8, 3/4 of the shorter "
                      "exemplar side), at least 4 (0 or 4..4096, default 0)")
           ->check(CLI::Range(0, 4096));
       app.add_option("--overlap", a->overlap,
                      "Overlap of neighbouring patches in pixels, smaller than the patch; "
                      "0 = automatic: patch/3 (0..4095, default 0)")
           ->check(CLI::Range(0, 4095));
       app.add_option("--passes", a->passes,
                      "Seam-repair passes after the tile is filled (0..100, default " +
                          std::to_string(TileOptions{}.refinement_passes) + ", as the library)")
           ->check(CLI::Range(0, 100));
       app.add_option("--straight-seam-steps", a->straight_seam_steps,
                      "Targeted repairs of straight seams inside the tile: lines whose jump is "
                      "above 1.3x the exemplar's own jump at the same sources get a small patch "
                      "across them, the tile's seam cost may at most double; 0 = off (0..1000, "
                      "default " + std::to_string(TileOptions{}.straight_seam_steps) + ")")
           ->check(CLI::Range(0, 1000));
       app.add_flag("--synthesis-cut", a->synthesis_cut,
                    "Keep the tile's border where the synthesis left it instead of rolling the "
                    "tile so that its border lies on the smoothest row and column (the tiling is "
                    "the same either way; default off: the border is moved)");
       app.add_option("--preview", a->preview,
                      "Also write the tile repeated 2x2 to this image (to check the seams)");
       add_common_options(app, a->common);
       return [a] { return run_tile(*a); };
     }}};

}  // namespace tile_command
}  // namespace
}  // namespace surftex::cli
