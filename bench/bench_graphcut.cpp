// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: graph-cut synthesis (texture/graphcut_synthesis.h) against G'MIC's
// `syntexturize_matchpatch` on every texture of shared/data/textures, 256x256
// output; plus a 128x128 periodic tile per texture and its wrap-seam ratio.
//
// Similarity: texture/bidirectional_similarity.h (Simakov et al. 2008) with a
// fixed setting for every texture and both methods: 7x7 patches, output
// patches at stride 2, exemplar patches at every position (non-periodic),
// exact nearest neighbours (max_candidates = 0). bds = coherence +
// completeness, mean squared difference per value (lower is better).
// Alpha is kept: both outputs are compared with the exemplar's channels.
//
// Usage: bench_graphcut [TEXTURE_DIR] [WORK_DIR] [NAME,NAME,...|-] [GMIC_RUNS] [TILE_SIZE] [MODE]
//                       [STRAIGHT_SEAM_STEPS] [STRAIGHT_SEAM_COST_TOLERANCE]
// The optional list keeps only the textures whose file stem is listed ("-" =
// all). MODE: all (default), synthesis (no tile) or tile (no 256 synthesis,
// no G'MIC). The last two override TileOptions::straight_seam_steps (0 = the
// tiles without the straight-seam repair) and straight_seam_cost_tolerance. G'MIC (from PATH; if it is missing or GMIC_RUNS is 0 the G'MIC
// fields are absent) is
// unseeded, so it runs GMIC_RUNS times (default 3) per texture and ours is
// compared with the median of its similarity scores and the median of its
// wall and CPU times (each run includes G'MIC's process start and PNG IO,
// ours excludes IO). TILE_SIZE (default 128) is the side of the periodic
// tile. One JSON line per texture, then a summary.
//
// Sets: nothing beyond the library defaults, which are the CLI defaults of
// `surftex synth --method graphcut` (output 256x256, the --size default) and
// of `surftex tile` (TileOptions{}); the tile size is the TILE_SIZE argument.
// Measurement history: docs/decisions/502-graphcut-bench-history.md.

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/bidirectional_similarity.h"
#include "texture/graphcut_synthesis.h"
#include "texture/tileable_tile.h"
#include "texture/wrap_seam_ratio.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

// The one similarity setting of this benchmark (see the header comment).
BidirectionalResult bidirectional(const Image& out, const Image& ex) {
  BidirectionalOptions o;
  o.patch = 7;
  o.stride = 2;
  o.max_candidates = 0;  // exact
  return bidirectional_similarity(out, ex, o);
}

// G'MIC may write a different channel count (e.g. drops or adds alpha): match the exemplar.
Image match_channels(const Image& img, int channels) {
  if (img.channels == channels) return img;
  Image r(img.width, img.height, channels, 1.f);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < channels; ++c) {
        const int sc = img.channels == 1 ? 0 : std::min(c, img.channels - 1);
        r.at(x, y, c) = (c == 3 && img.channels < 4) ? 1.f : img.at(x, y, sc);
      }
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double children_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_CHILDREN, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}
double self_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// Reference for a tile's worst-line ratio: the median, over 5 windows of the
// exemplar of the tile's size (4 corners and centre; the whole exemplar if
// smaller), of the worst interior line of the window (line_jump_profile,
// non-periodic): how uneven the lines of a seamless piece of the texture are.
// Returns {worst line, worst column line, worst row line}, each such a median.
std::vector<double> exemplar_worst_line_ratio(const Image& ex, int size) {
  const int w = std::min(size, ex.width), h = std::min(size, ex.height);
  std::vector<double> v, vc, vr;
  const int xs[5] = {0, ex.width - w, 0, ex.width - w, (ex.width - w) / 2};
  const int ys[5] = {0, 0, ex.height - h, ex.height - h, (ex.height - h) / 2};
  for (int k = 0; k < 5; ++k) {
    Image c(w, h, ex.channels);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int ch = 0; ch < ex.channels; ++ch) c.at(x, y, ch) = ex.at(xs[k] + x, ys[k] + y, ch);
    const LineJumpProfile p = line_jump_profile(c, false);
    v.push_back(p.worst_ratio);
    vc.push_back(p.worst_column_ratio);
    vr.push_back(p.worst_row_ratio);
  }
  return {median(v), median(vc), median(vr)};
}

// The command line (see the header comment).
struct BenchArgs {
  std::string dir, work;
  std::vector<std::string> files;  // the textures, sorted
  int gmic_runs = 3, tile_size = 128;
  std::string mode = "all";
  TileOptions tile_options;
};

// The textures of `dir` (PNG), only those listed in `names` unless it is "-".
std::vector<std::string> texture_files(const std::string& dir, const char* names) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".png") {
      if (names && std::string(names) != "-" &&
          ("," + std::string(names) + ",").find("," + e.path().stem().string() + ",") == std::string::npos)
        continue;
      files.push_back(e.path().string());
    }
  std::sort(files.begin(), files.end());
  return files;
}

BenchArgs parse_args(int argc, char** argv) {
  BenchArgs a;
  a.dir = argc > 1 ? argv[1] : std::string(SURFTEX_SHARED_DATA_DIR) + "/textures";
  a.work = argc > 2 ? argv[2] : "/tmp/surftex_bench_graphcut";
  fs::create_directories(a.work);
  a.files = texture_files(a.dir, argc > 3 ? argv[3] : nullptr);
  // G'MIC's syntexturize_matchpatch is unseeded: its output (and score) moves
  // between runs, so it runs `gmic_runs` times and we compare with the median.
  a.gmic_runs = argc > 4 ? std::max(0, std::atoi(argv[4])) : 3;
  a.tile_size = argc > 5 ? std::max(8, std::atoi(argv[5])) : 128;
  a.mode = argc > 6 ? argv[6] : "all";
  if (argc > 7) a.tile_options.straight_seam_steps = std::max(0, std::atoi(argv[7]));
  if (argc > 8) a.tile_options.straight_seam_cost_tolerance = std::max(0.0, std::atof(argv[8]));
  return a;
}

// The counts and sums of the summary line.
struct Totals {
  int compared = 0, no_worse = 0, faster = 0, tiles_ok = 0, tiles_ok_synthesis_cut = 0, tiles_worst_ok = 0,
      tiles_sm_worst_ok = 0;
  double expected_fail = 0, seam_total = 0;
  double t_ours = 0, t_gmic = 0, cpu_ours = 0, cpu_gmic = 0;
};

// G'MIC's 256x256 syntexturize_matchpatch, `runs` times: the medians of its
// similarity, wall and CPU times against ours (bds, seconds) into j and t.
void gmic_figures(const BenchArgs& a, const std::string& f, const std::string& name, const Image& ex,
                  double ours_bds, double ours_s, double ours_cpu, nlohmann::json& j, Totals& t) {
  std::vector<double> walls, cpus, scores;
  int failed_rc = 0;
  Timer tm;
  for (int run = 0; run < a.gmic_runs; ++run) {
    const std::string gm_png = a.work + "/" + name + "_gmic" + std::to_string(run) + ".png";
    fs::remove(gm_png);
    const std::string cmd = "gmic -v -1 input '" + f + "' syntexturize_matchpatch 256,256 output '" + gm_png +
                            "' >/dev/null 2>&1";
    double g0 = children_cpu_seconds();
    tm.reset();
    int rc = std::system(cmd.c_str());
    const double gm_s = tm.seconds(), gm_cpu = children_cpu_seconds() - g0;
    if (rc != 0 || !fs::exists(gm_png)) {
      failed_rc = rc != 0 ? rc : -1;
      continue;
    }
    Image g = match_channels(read_image(gm_png), ex.channels);
    walls.push_back(gm_s);
    cpus.push_back(gm_cpu);
    scores.push_back(bidirectional(g, ex).total);
  }
  if (!scores.empty()) {
    const double gm_bds = median(scores), gm_s = median(walls), gm_cpu = median(cpus);
    j["gmic_runs"] = scores.size();
    j["gmic_seconds_all"] = walls;
    j["gmic_cpu_seconds_all"] = cpus;
    j["gmic_bds_all"] = scores;
    j["gmic_seconds"] = gm_s;
    j["gmic_cpu_seconds"] = gm_cpu;
    j["gmic_bds"] = gm_bds;
    j["surftex_no_worse"] = ours_bds <= gm_bds;
    j["surftex_faster_wall"] = ours_s <= gm_s;
    j["surftex_faster_cpu"] = ours_cpu <= gm_cpu;
    ++t.compared;
    if (ours_bds <= gm_bds) ++t.no_worse;
    if (ours_cpu <= gm_cpu) ++t.faster;
    t.t_ours += ours_s;
    t.t_gmic += gm_s;
    t.cpu_ours += ours_cpu;
    t.cpu_gmic += gm_cpu;
  }
  if (failed_rc != 0) j["gmic_error"] = failed_rc;
}

// Our 256x256 graph-cut synthesis (seed 1): time, similarity, seam cost and
// patch counts; then G'MIC's when it is there and asked for.
void synthesis_figures(const BenchArgs& a, bool have_gmic, const std::string& f, const std::string& name,
                       const Image& ex, nlohmann::json& j, Totals& t) {
  GraphcutOptions o;
  o.seed = 1;
  double c0 = self_cpu_seconds();
  Timer tm;
  GraphcutResult r = graphcut_synthesize_detailed(ex, 256, 256, o);
  const double ours_s = tm.seconds(), ours_cpu = self_cpu_seconds() - c0;
  const std::string ours_png = a.work + "/" + name + "_graphcut.png";
  write_image(ours_png, r.image);
  BidirectionalResult bo = bidirectional(r.image, ex);
  j["surftex_seconds"] = ours_s;
  j["surftex_cpu_seconds"] = ours_cpu;
  j["surftex_bds"] = bo.total;
  j["surftex_coherence"] = bo.coherence;
  j["surftex_completeness"] = bo.completeness;
  j["surftex_seam_cost"] = {r.seam_cost_after_fill, r.seam_cost_final};
  j["surftex_patches"] = {r.fill_patches, r.refinement_tried, r.refinement_accepted};
  if (have_gmic && a.gmic_runs > 0) gmic_figures(a, f, name, ex, bo.total, ours_s, ours_cpu, j, t);
}

// Roll-independent figures of a tile: the worst line of the torus, and the
// distribution of the wrap-seam ratio over all size x size rolls (the
// synthesis cut is one draw from it if no line is special). Returns the
// fraction of rolls above 1.3.
double roll_figures(const TileResult& tr, int tile_size, nlohmann::json& j) {
  const LineJumpProfile prof = line_jump_profile(tr.tile, true);
  std::vector<double> rolls;
  rolls.reserve(static_cast<std::size_t>(tile_size) * tile_size);
  for (int ry = 0; ry < tile_size; ++ry)
    for (int rx = 0; rx < tile_size; ++rx) rolls.push_back(rolled_wrap_seam_ratio(prof, rx, ry));
  const double above =
      static_cast<double>(std::count_if(rolls.begin(), rolls.end(), [](double v) { return v > 1.3; })) /
      static_cast<double>(rolls.size());
  j["tile_worst_line_ratio"] = tr.worst_line_ratio;
  j["tile_worst_line"] = {prof.worst_is_column ? "column" : "row", prof.worst_index};  // in the rolled tile
  j["tile_worst_column_row_ratio"] = {prof.worst_column_ratio, prof.worst_row_ratio};
  j["tile_source_matched_wrap_ratio_at_synthesis_cut"] = tr.source_matched_wrap_ratio_at_synthesis_cut;
  j["tile_source_matched_worst_line_ratio"] = tr.source_matched_worst_line_ratio;
  j["tile_synthesis_cut_percentile"] = {tr.synthesis_column_percentile, tr.synthesis_row_percentile};
  j["tile_roll_wrap_ratio_median"] = median(rolls);
  j["tile_roll_wrap_ratio_fraction_above_1_3"] = above;
  return above;
}

// The periodic tile of TILE_SIZE: its seam figures against the exemplar's,
// and the tile repeated 2x2 written to the work folder.
void tile_figures(const BenchArgs& a, const std::string& name, const Image& ex, nlohmann::json& j,
                  Totals& t) {
  const int tile_size = a.tile_size;
  double c0 = self_cpu_seconds();
  Timer tm;
  TileResult tr = make_tileable_detailed(ex, tile_size, a.tile_options);
  j["tile_size"] = tile_size;
  j["tile_seconds"] = tm.seconds();
  j["tile_cpu_seconds"] = self_cpu_seconds() - c0;
  j["tile_wrap_seam_ratio"] = tr.wrap_seam_ratio;
  j["tile_wrap_seam_ratio_at_synthesis_cut"] = tr.wrap_seam_ratio_at_synthesis_cut;
  j["tile_cut_shift"] = {tr.shift_x, tr.shift_y};
  j["tile_seam_cost"] = tr.seam_cost;
  const double above = roll_figures(tr, tile_size, j);
  const std::vector<double> exw = exemplar_worst_line_ratio(ex, tile_size);
  j["exemplar_worst_line_ratio"] = exw[0];
  j["exemplar_worst_column_row_ratio"] = {exw[1], exw[2]};
  t.expected_fail += above;
  t.seam_total += tr.seam_cost;
  if (tr.worst_line_ratio <= 1.3) ++t.tiles_worst_ok;
  if (tr.source_matched_worst_line_ratio <= 1.3) ++t.tiles_sm_worst_ok;
  const WrapSeamStats ws = wrap_seam_stats(tr.tile);
  j["tile_wrap_mean_jump"] = ws.wrap_mean;
  j["tile_inside_mean_jump"] = ws.inside_mean;
  j["exemplar_wrap_seam_ratio"] = wrap_seam_ratio(ex);
  if (tr.wrap_seam_ratio <= 1.3) ++t.tiles_ok;
  if (tr.wrap_seam_ratio_at_synthesis_cut <= 1.3) ++t.tiles_ok_synthesis_cut;
  Image rep(2 * tile_size, 2 * tile_size, tr.tile.channels);
  for (int y = 0; y < rep.height; ++y)
    for (int x = 0; x < rep.width; ++x)
      for (int c = 0; c < rep.channels; ++c) rep.at(x, y, c) = tr.tile.at(x % tile_size, y % tile_size, c);
  write_image(a.work + "/" + name + "_tile2x2.png", rep);
}

nlohmann::json summary(const BenchArgs& a, bool have_gmic, const Totals& t) {
  nlohmann::json s;
  s["summary"] = true;
  s["textures"] = a.files.size();
  s["gmic_available"] = have_gmic;
  s["compared"] = t.compared;
  s["gmic_runs_per_texture"] = a.gmic_runs;
  s["no_worse_bds_than_gmic_median"] = t.no_worse;
  s["fraction_no_worse_bds"] = t.compared ? static_cast<double>(t.no_worse) / t.compared : 0.0;
  s["surftex_cpu_no_slower"] = t.faster;
  s["wall_time_ratio_surftex_over_gmic"] = t.t_gmic > 0 ? t.t_ours / t.t_gmic : 0.0;
  s["cpu_time_ratio_surftex_over_gmic"] = t.cpu_gmic > 0 ? t.cpu_ours / t.cpu_gmic : 0.0;
  s["surftex_total_seconds"] = t.t_ours;
  s["gmic_total_seconds"] = t.t_gmic;
  s["tile_size"] = a.tile_size;
  s["tiles_wrap_seam_ratio_le_1_3"] = t.tiles_ok;
  s["tiles_wrap_seam_ratio_at_synthesis_cut_le_1_3"] = t.tiles_ok_synthesis_cut;
  s["tiles_worst_line_ratio_le_1_3"] = t.tiles_worst_ok;
  s["tiles_source_matched_worst_line_ratio_le_1_3"] = t.tiles_sm_worst_ok;
  s["tiles_expected_wrap_ratio_above_1_3_at_a_random_cut"] = t.expected_fail;
  s["tiles_seam_cost_sum"] = t.seam_total;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  const BenchArgs a = parse_args(argc, argv);
  const bool have_gmic = std::system("command -v gmic >/dev/null 2>&1") == 0;
  if (a.mode != "all" && a.mode != "synthesis" && a.mode != "tile") {
    std::fprintf(stderr, "bench_graphcut: MODE must be all, synthesis or tile, got '%s'\n", a.mode.c_str());
    return 2;
  }
  const bool run_synthesis = a.mode != "tile", run_tile = a.mode != "synthesis";
  Totals t;
  for (const auto& f : a.files) {
    const std::string name = fs::path(f).stem().string();
    Image ex = read_image(f);
    nlohmann::json j;
    j["texture"] = name;
    j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height) + "x" + std::to_string(ex.channels);
    if (run_synthesis) synthesis_figures(a, have_gmic, f, name, ex, j, t);
    if (run_tile) tile_figures(a, name, ex, j, t);
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
  }
  std::printf("%s\n", summary(a, have_gmic, t).dump().c_str());
  return 0;
}
