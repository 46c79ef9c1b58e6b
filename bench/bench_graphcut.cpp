// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: graph-cut synthesis (texture/graphcut_synthesis.h) against G'MIC's
// `syntexturize_matchpatch` on every texture of shared/data/textures, 256x256
// output; plus a 128x128 periodic tile per texture and its wrap-seam ratio.
//
// Similarity: texture/bidirectional_similarity.h was not on main when this was
// written, so a simple bidirectional patch distance is computed here: 7x7
// patches, queries on a subsampled grid (stride 16 in the queried image),
// exact nearest neighbour over EVERY position of the other image (no
// approximation), mean squared difference per pixel and channel. coherence =
// output queries against the exemplar, completeness = exemplar queries against
// the output; bds = coherence + completeness (lower is better).
//
// Usage: bench_graphcut [TEXTURE_DIR] [WORK_DIR]  (gmic from PATH; if it is
// missing the G'MIC fields are null). One JSON line per texture, then a summary.
#include <sys/resource.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/graphcut_synthesis.h"
#include "texture/tileable_tile.h"
#include "texture/wrap_seam_ratio.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

constexpr int kPatch = 7, kHalf = 3, kStride = 16;

// Mean over query positions of min over all positions of `ref` of the
// per-pixel, per-channel squared patch difference.
double directed_patch_distance(const Image& query, const Image& ref, int channels) {
  std::vector<std::pair<int, int>> qs;
  for (int y = kHalf; y + kHalf < query.height; y += kStride)
    for (int x = kHalf; x + kHalf < query.width; x += kStride) qs.emplace_back(x, y);
  std::vector<double> best(qs.size());
  tbb::parallel_for(std::size_t(0), qs.size(), [&](std::size_t q) {
    const auto [qx, qy] = qs[q];
    double b = std::numeric_limits<double>::infinity();
    for (int ry = kHalf; ry + kHalf < ref.height; ++ry)
      for (int rx = kHalf; rx + kHalf < ref.width; ++rx) {
        double s = 0.0;
        for (int dy = -kHalf; dy <= kHalf && s < b; ++dy)
          for (int dx = -kHalf; dx <= kHalf; ++dx) {
            const float* a = query.pixel(qx + dx, qy + dy);
            const float* r = ref.pixel(rx + dx, ry + dy);
            for (int c = 0; c < channels; ++c) {
              double d = static_cast<double>(a[c]) - r[c];
              s += d * d;
            }
          }
        b = std::min(b, s);
      }
    best[q] = b / (kPatch * kPatch * channels);
  });
  double sum = 0.0;
  for (double v : best) sum += v;
  return qs.empty() ? 0.0 : sum / qs.size();
}

struct Bds {
  double coherence, completeness, total;
};
Bds bidirectional(const Image& out, const Image& ex) {
  const int c = std::min(out.channels, ex.channels);
  Bds b;
  b.coherence = directed_patch_distance(out, ex, c);
  b.completeness = directed_patch_distance(ex, out, c);
  b.total = b.coherence + b.completeness;
  return b;
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
    if (e.path().extension() == ".png") files.push_back(e.path().string());
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
    Bds bo = bidirectional(r.image, ex);
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
        Image g = read_image(gm_png);
        Bds bg = bidirectional(g, ex);
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
