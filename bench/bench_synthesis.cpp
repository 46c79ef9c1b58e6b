// SPDX-License-Identifier: AGPL-3.0-or-later
// Two-pass Efros-Leung synthesis speed. Cases (one JSON line each, best of 3
// runs; `sets` names what differs from the library's defaults, which are the
// `surftex synth` defaults):
//  - gorla_fig5_paper: Gorla et al. 2003, Figure 5 as published: a 64x64
//    exemplar grown to 256x256 with a 5x5 first pass, a 64-long preselect
//    list, a 12x12 second pass and the exhaustive first pass ("about 73 s" on
//    a Pentium III 933 MHz);
//  - gorla_fig5_defaults: the same exemplar and output at the defaults
//    (window 11, first pass 5, preselect = exemplar width, approximate
//    search);
//  - defaults_128_to_256: a 128x128 crop of pebbles_256 grown to 256x256 at
//    the defaults.
// Measurement history: docs/decisions/501-approximate-first-pass.md.
//
// Usage: bench_synthesis [texture.png] [out_prefix] [threads] [only_fig5]
// (default: leather_64.png from the shared data, no PNG output, all cores;
// out_prefix writes the results as PNG; "" keeps a default).
#include <nlohmann/json.hpp>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <ctime>
#include <cstdio>
#include <memory>
#include <cstdlib>
#include <string>

#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/bidirectional_similarity.h"
#include "texture/efros_leung.h"
#include "texture/histogram_distance.h"
#include "texture/image_ops.h"

using namespace surftex;

namespace {
void run_case(const std::string& name, const std::string& sets, const Image& ex, int size,
              const ElOptions& opt, const std::string& out_prefix) {
  double best = 1e30, best_cpu = 1e30;
  Image result;
  for (int i = 0; i < 3; ++i) {
    Timer t;
    const std::clock_t c0 = std::clock();
    result = efros_leung_synthesize(ex, size, size, opt);
    best = std::min(best, t.seconds());
    best_cpu = std::min(best_cpu, static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
  }
  BidirectionalOptions bo;
  bo.stride = 2;
  const BidirectionalResult bs = bidirectional_similarity(result, ex, bo);
  nlohmann::json j;
  j["case"] = name;
  j["sets"] = sets;
  j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height);
  j["output"] = std::to_string(size) + "x" + std::to_string(size);
  j["window"] = opt.window;
  j["first_pass_window"] = el_first_pass_window(opt);
  j["preselect"] = opt.preselect;
  j["search"] = opt.search == ElSearch::Approximate ? "approximate" : "exhaustive";
  j["seconds"] = best;
  j["texels_per_second"] = size * size / best;
  j["cpu_seconds"] = best_cpu;  // process CPU time (all threads): load-independent
  j["threads"] = tbb::this_task_arena::max_concurrency();
  if (name.rfind("gorla_fig5", 0) == 0) j["paper_seconds"] = 73.0;
  j["coherence"] = bs.coherence;
  j["completeness"] = bs.completeness;
  j["histogram_chi2"] = histogram_chi_square(result, ex);
  std::printf("%s\n", j.dump().c_str());
  std::fflush(stdout);
  if (!out_prefix.empty()) write_image(out_prefix + "_" + name + ".png", result);
}
}  // namespace

int main(int argc, char** argv) {
  const std::string data = SURFTEX_SHARED_DATA_DIR;
  const std::string small_path = argc > 1 && argv[1][0] ? argv[1] : data + "/textures/leather_64.png";
  const std::string out_prefix = argc > 2 ? argv[2] : "";
  std::unique_ptr<tbb::global_control> limit;
  if (argc > 3 && std::atoi(argv[3]) > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  std::atoi(argv[3]));
  const bool only_fig5 = argc > 4 && std::atoi(argv[4]) != 0;
  try {
    Image src = read_image(small_path);
    Image ex64 = crop(src, 0, 0, std::min(64, src.width), std::min(64, src.height));
    ElOptions gorla;
    gorla.window = 12;
    gorla.first_pass_window = 5;
    gorla.preselect = 64;
    gorla.search = ElSearch::Exhaustive;
    run_case("gorla_fig5_paper", "window 12, first pass 5, preselect 64, exhaustive search (Figure 5)", ex64, 256,
             gorla, out_prefix);
    run_case("gorla_fig5_defaults", "nothing (defaults)", ex64, 256, ElOptions{}, out_prefix);
    if (only_fig5) return 0;
    Image big = read_image(data + "/textures/pebbles_256.png");
    Image ex128 = crop(big, 0, 0, 128, 128);
    run_case("defaults_128_to_256", "nothing (defaults)", ex128, 256, ElOptions{}, out_prefix);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
