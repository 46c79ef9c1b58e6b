// SPDX-License-Identifier: AGPL-3.0-or-later
// Quality and cost of the approximate Efros-Leung first pass against the
// exhaustive one (efros_leung.h, ElSearch), on every texture of
// ../shared/data/textures: the same 2D synthesis at the `surftex synth`
// defaults (window 11, first-pass window 5, preselect = exemplar width,
// pick 10 / 10%, epsilon 0.1, seed 1; library defaults for everything else,
// the approximate search's included) run once with ElSearch::Exhaustive
// (the published method, as before issue 19) and once with
// ElSearch::Approximate (the default). Sets: the output size (default 128 x
// 128, the cost of the exhaustive reference grows with exemplar area times
// output area; SURFTEX_BENCH_EL_SIZE=256 is the CLI's own default size).
//
// Similarity: bidirectional_similarity with bench_graphcut's setting (7x7
// patches, output patches at stride 2, exact nearest neighbours); lower is
// better; `ratio` = approximate / exhaustive. Times are process CPU seconds
// (load-independent) and wall seconds.
//
// Usage: bench_el_search [TEXTURE_DIR] [NAME,NAME,...|-] [threads]
// One JSON line per texture, then a summary line (how many within 5%).
// SURFTEX_BENCH_EL_ANN="K,D,EPS;K,D,EPS..." also runs these settings of
// (ann_candidates, ann_pca_dims, ann_eps[, ann_stride[, ann_coherent_candidates]])
// (tuning; "settings" in the lines; the last two default to the library's).
// SURFTEX_BENCH_EL_REFERENCE=FILE takes the exhaustive figures from an
// earlier run's output instead of recomputing them (the exhaustive search is
// deterministic): per seed when that run had at least as many seeds, so the
// approximate search over hundreds of seeds costs only its own runs.
// SURFTEX_BENCH_EL_SEEDS=N (default 1) runs both searches with seeds 1..N and
// compares their mean BDS (textures whose synthesis is bimodal, such as two
// flat colours in stripes wider than the window, make one seed's ratio a coin
// toss); the per-seed figures are printed as well. With both, each setting's
// ratio is the mean over the same seeds too.
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/bidirectional_similarity.h"
#include "texture/efros_leung.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

struct Run {
  double bds = 0, cpu = 0, wall = 0;
};

// One approximate-search setting (ann_candidates, ann_pca_dims, ann_eps,
// ann_stride, ann_coherent_candidates; 0 = the library's default).
struct AnnSetting {
  int candidates, dims;
  double eps;
  int stride = 0, coherent = 0;
};

Run synthesize(const Image& ex, int size, ElSearch search, const AnnSetting* ann = nullptr, std::uint64_t seed = 1) {
  ElOptions o;  // the `surftex synth` defaults are the library's
  o.search = search;
  if (ann) {
    o.ann_candidates = ann->candidates;
    o.ann_pca_dims = ann->dims;
    o.ann_eps = ann->eps;
    if (ann->stride > 0) o.ann_stride = ann->stride;
    if (ann->coherent > 0) o.ann_coherent_candidates = ann->coherent;
  }
  o.seed = seed;
  Run r;
  Timer t;
  const std::clock_t c0 = std::clock();
  const Image out = efros_leung_synthesize(ex, size, size, o);
  r.cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  r.wall = t.seconds();
  BidirectionalOptions bo;
  bo.patch = 7;
  bo.stride = 2;
  r.bds = bidirectional_similarity(out, ex, bo).total;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 && argv[1][0] ? argv[1] : std::string(SURFTEX_SHARED_DATA_DIR) + "/textures";
  std::vector<std::string> only;
  if (argc > 2 && std::string(argv[2]) != "-") {
    std::stringstream ss(argv[2]);
    for (std::string n; std::getline(ss, n, ',');) only.push_back(n);
  }
  std::unique_ptr<tbb::global_control> limit;
  if (argc > 3 && std::atoi(argv[3]) > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::atoi(argv[3]));
  const char* env = std::getenv("SURFTEX_BENCH_EL_SIZE");
  const int size = env && std::atoi(env) > 0 ? std::atoi(env) : 128;
  std::vector<AnnSetting> settings;
  if (const char* t = std::getenv("SURFTEX_BENCH_EL_ANN")) {
    std::stringstream ss(t);
    for (std::string item; std::getline(ss, item, ';');) {
      AnnSetting st{16, 10, 1.0, 0, 0};
      if (std::sscanf(item.c_str(), "%d,%d,%lf,%d,%d", &st.candidates, &st.dims, &st.eps, &st.stride,
                      &st.coherent) >= 3)
        settings.push_back(st);
    }
  }
  // SURFTEX_BENCH_EL_REFERENCE=FILE: exhaustive figures from an earlier run's
  // JSON lines (same size; the exhaustive search is deterministic).
  const char* seeds_env = std::getenv("SURFTEX_BENCH_EL_SEEDS");
  const int seeds = seeds_env && std::atoi(seeds_env) > 1 ? std::atoi(seeds_env) : 1;
  // Per texture: the exhaustive BDS of seeds 1..n and the CPU of all n.
  struct Reference {
    std::vector<double> bds;
    double cpu = 0;
  };
  std::map<std::string, Reference> reference;
  if (const char* ref = std::getenv("SURFTEX_BENCH_EL_REFERENCE")) {
    std::ifstream in(ref);
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] != '{') continue;
      const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
      if (j.is_discarded() || !j.contains("texture") || j.value("output", 0) != size) continue;
      Reference r;
      r.cpu = j["cpu_seconds"]["exhaustive"].get<double>();
      if (j.contains("seeds"))
        for (const auto& ps : j["seeds"]) r.bds.push_back(ps["exhaustive"].get<double>());
      else
        r.bds.push_back(j["bds_exhaustive"].get<double>());
      if (static_cast<int>(r.bds.size()) >= seeds) reference[j["texture"].get<std::string>()] = r;
    }
  }
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".png") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  int n = 0, within = 0;
  double worst = 0, cpu_ex = 0, cpu_ap = 0, log_sum = 0;
  try {
    for (const fs::path& f : files) {
      const std::string name = f.stem().string();
      if (!only.empty() && std::find(only.begin(), only.end(), name) == only.end()) continue;
      const Image ex = read_image(f.string());
      const auto ref = reference.find(name);
      // The exhaustive run of seed sd, or its figure from the reference (its
      // CPU: the reference's mean per seed).
      auto exhaustive = [&](int sd) {
        if (ref == reference.end())
          return synthesize(ex, size, ElSearch::Exhaustive, nullptr, static_cast<std::uint64_t>(sd));
        Run r;
        r.bds = ref->second.bds[sd - 1];
        r.cpu = ref->second.cpu / static_cast<double>(ref->second.bds.size());
        return r;
      };
      Run a = exhaustive(1);
      Run b = synthesize(ex, size, ElSearch::Approximate);
      nlohmann::json per_seed = nlohmann::json::array();
      if (seeds > 1) {
        per_seed.push_back({{"seed", 1}, {"exhaustive", a.bds}, {"approximate", b.bds}});
        for (int sd = 2; sd <= seeds; ++sd) {
          const Run a2 = exhaustive(sd);
          const Run b2 = synthesize(ex, size, ElSearch::Approximate, nullptr, static_cast<std::uint64_t>(sd));
          per_seed.push_back({{"seed", sd}, {"exhaustive", a2.bds}, {"approximate", b2.bds}});
          a.bds += a2.bds, a.cpu += a2.cpu, a.wall += a2.wall;
          b.bds += b2.bds, b.cpu += b2.cpu, b.wall += b2.wall;
        }
        a.bds /= seeds, b.bds /= seeds;
      }
      nlohmann::json tried = nlohmann::json::array();
      for (const AnnSetting& st : settings) {
        Run c = synthesize(ex, size, ElSearch::Approximate, &st);
        for (int sd = 2; sd <= seeds; ++sd) {  // the same seeds as the default's mean
          const Run c2 = synthesize(ex, size, ElSearch::Approximate, &st, static_cast<std::uint64_t>(sd));
          c.bds += c2.bds, c.cpu += c2.cpu;
        }
        c.bds /= seeds;
        tried.push_back({{"ann", {st.candidates, st.dims, st.eps, st.stride, st.coherent}},
                         {"ratio", c.bds / std::max(a.bds, 1e-12)},
                         {"cpu_seconds", c.cpu}});
      }
      const double ratio = b.bds / std::max(a.bds, 1e-12);
      ++n;
      within += ratio <= 1.05;
      worst = std::max(worst, ratio);
      log_sum += std::log(ratio);
      cpu_ex += a.cpu;
      cpu_ap += b.cpu;
      nlohmann::json j;
      j["texture"] = name;
      j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height);
      j["output"] = size;
      j["bds_exhaustive"] = a.bds;
      j["bds_approximate"] = b.bds;
      j["ratio"] = ratio;
      j["cpu_seconds"] = {{"exhaustive", a.cpu}, {"approximate", b.cpu}};
      j["wall_seconds"] = {{"exhaustive", a.wall}, {"approximate", b.wall}};
      if (!settings.empty()) j["settings"] = tried;
      if (seeds > 1) j["seeds"] = per_seed;  // (bds_* above: the means; cpu and wall: the sums)
      std::printf("%s\n", j.dump().c_str());
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  nlohmann::json s;
  s["summary"] = "el_search";
  s["textures"] = n;
  s["within_5_percent"] = within;
  s["worst_ratio"] = worst;
  s["geometric_mean_ratio"] = n ? std::exp(log_sum / n) : 0.0;
  s["cpu_seconds"] = {{"exhaustive", cpu_ex}, {"approximate", cpu_ap}};
  std::printf("%s\n", s.dump().c_str());
  return 0;
}
