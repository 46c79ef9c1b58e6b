// SPDX-License-Identifier: AGPL-3.0-or-later
// Load + repair time of CGAL's armadillo.off and bunny00.off (extracted from
// Debian's libcgal-demo tarball into a temporary folder). Best of 3 runs per
// phase; one JSON line per mesh:
//   {"mesh", "faces", "load_s", "repair_s", "selfint_s", "self_intersecting_pairs",
//    "valid", "peak_rss_mb"}
// repair_s includes self-intersection detection; selfint_s is that step alone.
// Usage: bench_load_repair [tarball]
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "geometry/repair_mesh.h"
#include "geometry/self_intersections.h"
#include "geometry/timer.h"

namespace fs = std::filesystem;
using namespace surftex;

namespace {

double peak_rss_mb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atof(line.c_str() + 6) / 1024.0;  // kB
  return -1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string tarball = argc > 1 ? argv[1] : SURFTEX_CGAL_DATA_TARBALL;
  const fs::path dir = fs::temp_directory_path() / ("surftex-bench-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const char* names[] = {"armadillo.off", "bunny00.off"};
  std::string cmd = "tar xzf '" + tarball + "' -C '" + dir.string() + "'";
  for (const char* n : names) cmd += std::string(" data/meshes/") + n;
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "error: cannot extract meshes from %s\n", tarball.c_str());
    fs::remove_all(dir);
    return 2;
  }
  for (const char* n : names) {
    const std::string path = (dir / "data" / "meshes" / n).string();
    double load = std::numeric_limits<double>::max(), repair = load, selfint = load;
    std::size_t faces = 0, pairs = 0;
    bool valid = false;
    for (int run = 0; run < 3; ++run) {
      Mesh m;
      Timer t;
      SoupToMeshOptions so;
      so.triangulate = false;
      soup_to_mesh(read_polygon_soup(path), m, so);
      load = std::min(load, t.seconds());
      t.reset();
      RepairReport r = repair_mesh(m);
      repair = std::min(repair, t.seconds());
      for (const auto& [step, s] : r.seconds)
        if (step == "self_intersections") selfint = std::min(selfint, s);
      faces = r.faces;
      pairs = r.self_intersecting_pairs;
      valid = r.valid;
    }
    nlohmann::json j = {{"mesh", n},           {"faces", faces},
                        {"load_s", load},      {"repair_s", repair},
                        {"selfint_s", selfint}, {"self_intersecting_pairs", pairs},
                        {"valid", valid},      {"peak_rss_mb", peak_rss_mb()}};
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
  }
  fs::remove_all(dir);
  return 0;
}
