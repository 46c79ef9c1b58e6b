// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark (issue 18 item 5): how close each image-texture method's surface
// texture is to its exemplar, at the CLI's defaults. The three methods
// (`surftex patches`, `surftex subdiv`, `surftex material-map`) run as a user
// runs them, one process per case, on a flat square and on three meshes of
// shared/data (bunny_6k.obj, goat_head.obj, spot.ply) with three textures
// (regular: brick_small_96.png, stochastic: pebbles_256.png, directional:
// wood_512.png); each case's report.json gives the surface fidelity
// (texture/surface_fidelity.h: bidirectional similarity of charts resampled
// at the synthesis texel, against graph-cut 2D synthesis of the same
// exemplar under the same mask) and the seam jump ratio (patches: across
// patch boundaries; subdiv: across the baked atlas's charts; material-map:
// across the (s,t) cuts of the parameterization).
//
// The flat square (a unit square of 32 x 32 cells, 2048 triangles) is given
// a scale of 256 texels across where the method has one: subdiv
// `--rscale 256`, material-map `--scale S` with S = tile side / 256; patches
// has no scale option (its texel follows from the patch size and
// --patch-res): its defaults are used and the texels across it got are
// printed. material-map needs a material tile: one per texture is made first
// (texture/material_space/material_tile.h, one key, one layer, side = the exemplar's shorter
// side up to 256), its time is printed apart.
//
// Usage: bench_fidelity [WORK_DIR] [METHODS] [SURFACES] [TEXTURES] [THREADS]
//   METHODS  comma list of patches,subdiv,material-map (default all)
//   SURFACES comma list of square,bunny_6k,goat_head,spot (default all)
//   TEXTURES comma list of file stems in shared/data/textures (default
//            brick_small_96,pebbles_256,wood_512)
//   THREADS  --threads of every run (default 2)
// One JSON line per case (fidelity ratio, bds, bds_2d, long-run share, seam
// ratio, wall and CPU seconds of the run, load average at its start), then a
// table. Figures and the machine load: README.md and
// docs/decisions/205-fidelity-benchmark.md.
#include <sys/resource.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/image_io.h"
#include "texture/material_space/material_tile.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string t;
  while (std::getline(ss, t, ','))
    if (!t.empty()) out.push_back(t);
  return out;
}

double load_average() {
  double l = 0;
  std::ifstream in("/proc/loadavg");
  in >> l;
  return l;
}

// Runs `cmd` (a shell command line); returns its exit code and the wall and
// user+system CPU seconds of the child.
int run(const std::string& cmd, double& wall, double& cpu) {
  rusage before{}, after{};
  getrusage(RUSAGE_CHILDREN, &before);
  const auto t0 = std::chrono::steady_clock::now();
  const int rc = std::system(cmd.c_str());
  wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  getrusage(RUSAGE_CHILDREN, &after);
  auto sec = [](const timeval& t) { return t.tv_sec + 1e-6 * t.tv_usec; };
  cpu = sec(after.ru_utime) - sec(before.ru_utime) + sec(after.ru_stime) - sec(before.ru_stime);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

// A unit square in z = 0 of n x n cells, two triangles each (OBJ).
void write_square(const std::string& path, int n) {
  std::ofstream o(path);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) o << "v " << double(i) / n << " " << double(j) / n << " 0\n";
  auto id = [n](int i, int j) { return j * (n + 1) + i + 1; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      o << "f " << id(i, j) << " " << id(i + 1, j) << " " << id(i + 1, j + 1) << "\n";
      o << "f " << id(i, j) << " " << id(i + 1, j + 1) << " " << id(i, j + 1) << "\n";
    }
}

// One key, one layer, side = the exemplar's shorter side up to 256.
int make_tile(const std::string& texture, const std::string& dir, double& seconds) {
  const Image ex = read_image(texture);
  MaterialTileOptions o;
  o.size = std::min(256, std::min(ex.width, ex.height));
  o.layers = 1;
  o.seed = 1;
  const auto t0 = std::chrono::steady_clock::now();
  const MaterialTileResult r = make_material_tile({MaterialKey{ex, Image(), fs::path(texture).filename().string()}}, o);
  MaterialTileInfo info;
  info.sources = {texture};
  info.masks = {""};
  info.layers_per_pair = 1;
  write_material_tile(dir, r, info, true);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return o.size;
}

double number(const nlohmann::json& j, const std::vector<std::string>& path) {
  const nlohmann::json* p = &j;
  for (const auto& k : path) {
    if (!p->is_object() || !p->contains(k)) return -1;
    p = &(*p)[k];
  }
  return p->is_number() ? p->get<double>() : -1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string work = argc > 1 ? argv[1] : (fs::temp_directory_path() / "bench_fidelity").string();
  const auto methods = split(argc > 2 && std::string(argv[2]) != "-" ? argv[2] : "patches,subdiv,material-map");
  const auto surfaces = split(argc > 3 && std::string(argv[3]) != "-" ? argv[3] : "square,bunny_6k,goat_head,spot");
  const auto textures =
      split(argc > 4 && std::string(argv[4]) != "-" ? argv[4] : "brick_small_96,pebbles_256,wood_512");
  const int threads = argc > 5 ? std::atoi(argv[5]) : 2;
  const std::string data = SURFTEX_SHARED_DATA_DIR;
  const std::string bin = SURFTEX_BINARY;
  fs::create_directories(work);
  const std::string square = (fs::path(work) / "square.obj").string();
  write_square(square, 32);
  auto mesh_path = [&](const std::string& s) -> std::string {
    if (s == "square") return square;
    if (s == "bunny_6k") return data + "/meshes/bunny_6k.obj";
    if (s == "goat_head") return data + "/meshes/goat_head.obj";
    if (s == "spot") return data + "/meshes/spot.ply";
    return data + "/meshes/" + s;
  };
  std::vector<nlohmann::json> rows;
  for (const std::string& tex : textures) {
    const std::string tpath = data + "/textures/" + tex + ".png";
    std::string tile_dir;
    int tile_size = 0;
    for (const auto& m : methods)
      if (m == "material-map") {
        tile_dir = (fs::path(work) / ("tile_" + tex)).string();
        double s = 0;
        tile_size = make_tile(tpath, tile_dir, s);
        std::printf("%s\n", nlohmann::json{{"texture", tex}, {"material_tile_seconds", s}, {"tile_size", tile_size}}
                                .dump()
                                .c_str());
        std::fflush(stdout);
      }
    for (const std::string& surf : surfaces)
      for (const std::string& m : methods) {
        const std::string out = (fs::path(work) / (m + "_" + surf + "_" + tex)).string();
        std::string cmd = bin + " " + m + " " + mesh_path(surf);
        if (m == "material-map") {
          cmd += " --tile " + tile_dir;
          if (surf == "square") cmd += " --scale " + std::to_string(tile_size / 256.0);
        } else {
          cmd += " " + tpath;
          if (m == "subdiv" && surf == "square") cmd += " --rscale 256";
        }
        cmd += " -o " + out + " --threads " + std::to_string(threads) + " --quiet --force > " + out + ".log 2>&1";
        const double load = load_average();
        double wall = 0, cpu = 0;
        const int rc = run(cmd, wall, cpu);
        nlohmann::json rep;
        std::ifstream in(fs::path(out) / "report.json");
        if (in) {
          try {
            rep = nlohmann::json::parse(in);
          } catch (const std::exception&) {
          }
        }
        const nlohmann::json& f = rep.contains("fidelity") ? rep["fidelity"] : nlohmann::json();
        double seam = number(f, {"seam", "ratio"});
        if (m == "subdiv") seam = number(rep, {"export", "atlas", "seam", "ratio"});
        const double texel = number(f, {"texel_size"});
        nlohmann::json row{{"method", m},
                           {"surface", surf},
                           {"texture", tex},
                           {"exit", rc},
                           {"fidelity_ratio", number(f, {"ratio"})},
                           {"bds", number(f, {"bds"})},
                           {"bds_2d", number(f, {"bds_2d"})},
                           {"long_run_fraction", number(f, {"long_run_fraction"})},
                           {"seam_ratio", seam},
                           {"texel_size", texel},
                           {"texels_across_square", surf == "square" && texel > 0 ? 1.0 / texel : -1.0},
                           {"charts", number(f, {"charts"})},
                           {"seconds_wall", wall},
                           {"seconds_cpu", cpu},
                           {"load_average", load},
                           {"threads", threads}};
        if (f.contains("error")) row["fidelity_error"] = f["error"];
        std::printf("%s\n", row.dump().c_str());
        std::fflush(stdout);
        rows.push_back(row);
      }
  }
  std::printf("# method        surface    texture          ratio   seam   long-run  wall s   cpu s\n");
  for (const auto& r : rows)
    std::printf("# %-13s %-10s %-16s %6.2f %6.2f %8.2f %7.1f %7.1f\n", r["method"].get<std::string>().c_str(),
                r["surface"].get<std::string>().c_str(), r["texture"].get<std::string>().c_str(),
                r["fidelity_ratio"].get<double>(), r["seam_ratio"].get<double>(),
                r["long_run_fraction"].get<double>(), r["seconds_wall"].get<double>(),
                r["seconds_cpu"].get<double>());
  return 0;
}
