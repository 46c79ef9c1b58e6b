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
// Usage: bench_graphcut [TEXTURE_DIR] [WORK_DIR] [NAME,NAME,...]  (the optional
// list keeps only the textures whose file stem is listed)  (gmic from PATH; if it is
// missing the G'MIC fields are null). One JSON line per texture, then a summary.
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

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : std::string(SURFTEX_SHARED_DATA_DIR) + "/textures";
  const std::string work = argc > 2 ? argv[2] : "/tmp/surftex_bench_graphcut";
  fs::create_directories(work);
  const bool have_gmic = std::system("command -v gmic >/dev/null 2>&1") == 0;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".png") {
      if (argc > 3 && ("," + std::string(argv[3]) + ",").find("," + e.path().stem().string() + ",") ==
                          std::string::npos)
        continue;
      files.push_back(e.path().string());
    }
  std::sort(files.begin(), files.end());

  int compared = 0, no_worse = 0, tiles_ok = 0;
  double t_ours = 0, t_gmic = 0, cpu_ours = 0, cpu_gmic = 0;
  for (const auto& f : files) {
    const std::string name = fs::path(f).stem().string();
    Image ex = read_image(f);
    nlohmann::json j;
    j["texture"] = name;
    j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height) + "x" + std::to_string(ex.channels);

    GraphcutOptions o;
    o.seed = 1;
    double c0 = self_cpu_seconds();
    Timer tm;
    GraphcutResult r = graphcut_synthesize_detailed(ex, 256, 256, o);
    const double ours_s = tm.seconds(), ours_cpu = self_cpu_seconds() - c0;
    const std::string ours_png = work + "/" + name + "_graphcut.png";
    write_image(ours_png, r.image);
    BidirectionalResult bo = bidirectional(r.image, ex);
    j["surftex_seconds"] = ours_s;
    j["surftex_cpu_seconds"] = ours_cpu;
    j["surftex_bds"] = bo.total;
    j["surftex_coherence"] = bo.coherence;
    j["surftex_completeness"] = bo.completeness;
    j["surftex_seam_cost"] = {r.seam_cost_after_fill, r.seam_cost_final};

    if (have_gmic) {
      const std::string gm_png = work + "/" + name + "_gmic.png";
      const std::string cmd = "gmic -v -1 input '" + f + "' syntexturize_matchpatch 256,256 output '" +
                              gm_png + "' >/dev/null 2>&1";
      double g0 = children_cpu_seconds();
      tm.reset();
      int rc = std::system(cmd.c_str());
      const double gm_s = tm.seconds(), gm_cpu = children_cpu_seconds() - g0;
      if (rc == 0 && fs::exists(gm_png)) {
        Image g = match_channels(read_image(gm_png), ex.channels);
        BidirectionalResult bg = bidirectional(g, ex);
        j["gmic_seconds"] = gm_s;
        j["gmic_cpu_seconds"] = gm_cpu;
        j["gmic_bds"] = bg.total;
        j["gmic_coherence"] = bg.coherence;
        j["gmic_completeness"] = bg.completeness;
        j["surftex_no_worse"] = bo.total <= bg.total;
        ++compared;
        if (bo.total <= bg.total) ++no_worse;
        t_ours += ours_s;
        t_gmic += gm_s;
        cpu_ours += ours_cpu;
        cpu_gmic += gm_cpu;
      } else {
        j["gmic_error"] = rc;
      }
    }

    TileOptions to;
    tm.reset();
    TileResult t = make_tileable_detailed(ex, 128, to);
    j["tile128_seconds"] = tm.seconds();
    j["tile128_wrap_seam_ratio"] = t.wrap_seam_ratio;
    const WrapSeamStats ws = wrap_seam_stats(t.tile);
    j["tile128_wrap_mean_jump"] = ws.wrap_mean;
    j["tile128_inside_mean_jump"] = ws.inside_mean;
    j["exemplar_wrap_seam_ratio"] = wrap_seam_ratio(ex);
    if (t.wrap_seam_ratio <= 1.3) ++tiles_ok;
    Image rep(256, 256, t.tile.channels);
    for (int y = 0; y < 256; ++y)
      for (int x = 0; x < 256; ++x)
        for (int c = 0; c < rep.channels; ++c) rep.at(x, y, c) = t.tile.at(x % 128, y % 128, c);
    write_image(work + "/" + name + "_tile2x2.png", rep);
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
  }
  nlohmann::json s;
  s["summary"] = true;
  s["textures"] = files.size();
  s["gmic_available"] = have_gmic;
  s["compared"] = compared;
  s["fraction_no_worse_bds"] = compared ? static_cast<double>(no_worse) / compared : 0.0;
  s["wall_time_ratio_surftex_over_gmic"] = t_gmic > 0 ? t_ours / t_gmic : 0.0;
  s["cpu_time_ratio_surftex_over_gmic"] = cpu_gmic > 0 ? cpu_ours / cpu_gmic : 0.0;
  s["surftex_total_seconds"] = t_ours;
  s["gmic_total_seconds"] = t_gmic;
  s["tiles_wrap_seam_ratio_le_1_3"] = tiles_ok;
  std::printf("%s\n", s.dump().c_str());
  return 0;
}
