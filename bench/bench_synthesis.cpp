// SPDX-License-Identifier: AGPL-3.0-or-later
// Two-pass Efros-Leung synthesis speed (Gorla et al. 2003, Figure 5: a 64x64
// exemplar grown to 256x256 with a 5x5 first pass, a 64-long preselect list
// and a 12x12 second pass, "about 73 s" on a Pentium III 933 MHz), and a
// larger case (128x128 -> 256x256, window 11, default first pass and
// preselect). Prints one JSON line per case: best of 3 runs.
//
// Measured (2 cores shared with other builds, load average 15-17; the old
// and new binaries back to back, same output bytes):
//   Fig 5 before: 2.63 s CPU, 6.60 s wall (9.9K texels/s under that load)
//   Fig 5 now:    1.37 s CPU, 3.64 s wall (18.0K texels/s under that load);
//                 single thread 1.30-1.34 s CPU (was 2.42-2.50 s)
//   w11 128 -> 256 now: 4.16 s CPU, 12.0 s wall under that load.
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
void run_case(const std::string& name, const Image& ex, int size, const ElOptions& opt,
              const std::string& out_prefix) {
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
  j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height);
  j["output"] = std::to_string(size) + "x" + std::to_string(size);
  j["window"] = opt.window;
  j["first_pass_window"] = el_first_pass_window(opt);
  j["preselect"] = opt.preselect;
  j["seconds"] = best;
  j["texels_per_second"] = size * size / best;
  j["cpu_seconds"] = best_cpu;  // process CPU time (all threads): load-independent
  j["threads"] = tbb::this_task_arena::max_concurrency();
  j["paper_seconds"] = 73.0;
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
    run_case("gorla_fig5_64_to_256", ex64, 256, gorla, out_prefix);

    if (only_fig5) return 0;
    Image big = read_image(data + "/textures/pebbles_256.png");
    Image ex128 = crop(big, 0, 0, 128, 128);
    ElOptions w11;
    w11.window = 11;
    run_case("w11_128_to_256", ex128, 256, w11, out_prefix);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
