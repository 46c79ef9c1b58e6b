// SPDX-License-Identifier: AGPL-3.0-or-later
// Cost growth of every method at the CLI's defaults (issue 19 item 4): each
// method run as a user runs it -- the `surftex` binary with only its
// required arguments (and --quiet --force) -- at three input sizes, with the
// wall time, the CPU time (user + system) and the peak resident memory of
// the process, and the exponent b of a least-squares fit cpu = a * size^b
// over the sizes that ran.
//
// Inputs (sets nothing else):
//  - meshes: ../shared/data/meshes/fandisk.off (12,946 triangles) and its
//    sqrt(3) subdivisions (CGAL Subdivision_method_3, 2 and 4 steps:
//    116,514 and 1,048,626 triangles), written as OFF to a temporary folder;
//  - exemplars: rock_512.png cropped to 64, 256 and 512 px (top-left corner,
//    same texel scale);
//  - patches and subdiv on the meshes with the 256 px exemplar; material-map
//    on the meshes with a tile made once by `material-tile` (pebbles_256 and
//    box_tree_leaves_256, its defaults but --size 64 --layers 2, so that the
//    tile's own cost stays out of the table); quilt on the meshes with a
//    generated weave swatch (`swatch weave`); synth and patches (on the
//    12.9K mesh) with the three exemplars.
// The 1M-face tier runs only with SURFTEX_BENCH_SCALING_1M=1 (minutes to
// hours per method); a run the CLI refuses up front (its memory budget) is
// reported with the CLI's message, a run that fails otherwise with its exit
// code. SURFTEX_BENCH_SCALING_ONLY=patches,synth,... restricts the methods.
//
// Usage: bench_scaling [threads (default 2)]
// One JSON line per run, then one per method (exponent, fitted on CPU
// seconds against faces or exemplar pixels).
#include <CGAL/subdivision_method_3.h>
#include <nlohmann/json.hpp>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "texture/image_ops.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

struct Outcome {
  int exit_code = -1;
  double wall = 0, cpu = 0, peak_mib = 0;
  std::string message;  // first error line (refusals)
};

// Runs `args` (argv[0] = the binary) in a child process; stderr to `err_file`.
Outcome run(const std::vector<std::string>& args, const std::string& err_file) {
  Outcome o;
  Timer t;
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    if (!std::freopen(err_file.c_str(), "w", stderr)) _exit(127);
    if (!std::freopen("/dev/null", "w", stdout)) _exit(127);
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  rusage ru{};
  wait4(pid, &status, 0, &ru);
  o.wall = t.seconds();
  o.cpu = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  o.peak_mib = ru.ru_maxrss / 1024.0;  // KiB on Linux
  o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(err_file);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("error:", 0) == 0) {
      o.message = line;
      break;
    }
  return o;
}

// Exponent b of cpu = a * size^b, least squares in log-log.
double fit_exponent(const std::vector<std::pair<double, double>>& pts) {
  if (pts.size() < 2) return std::nan("");
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& [x, y] : pts) {
    const double lx = std::log(x), ly = std::log(std::max(y, 1e-3));
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
  }
  const double n = static_cast<double>(pts.size());
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

bool wanted(const std::string& method) {
  const char* only = std::getenv("SURFTEX_BENCH_SCALING_ONLY");
  if (!only || !*only) return true;
  std::stringstream ss(only);
  for (std::string m; std::getline(ss, m, ',');)
    if (m == method) return true;
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string threads = argc > 1 ? argv[1] : "2";
  const bool big = std::getenv("SURFTEX_BENCH_SCALING_1M") && std::string(std::getenv("SURFTEX_BENCH_SCALING_1M")) == "1";
  const std::string data = SURFTEX_SHARED_DATA_DIR;
  const std::string bin = SURFTEX_BINARY;
  const fs::path tmp = fs::temp_directory_path() / ("surftex_bench_scaling_" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  try {
    // Meshes: fandisk and its sqrt(3) subdivisions.
    std::vector<std::pair<std::string, std::size_t>> meshes;
    {
      Mesh m;
      read_mesh(data + "/meshes/fandisk.off", m);
      const int tiers = big ? 3 : 2;
      for (int tier = 0; tier < tiers; ++tier) {
        if (tier > 0) CGAL::Subdivision_method_3::Sqrt3_subdivision(m, CGAL::parameters::number_of_iterations(2));
        const std::string path = (tmp / ("fandisk_" + std::to_string(tier) + ".off")).string();
        write_mesh(path, m);
        meshes.push_back({path, m.number_of_faces()});
      }
    }
    // Exemplars: crops of one 512 px photo.
    std::vector<std::pair<std::string, int>> exemplars;
    const Image rock = read_image(data + "/textures/rock_512.png");
    for (int side : {64, 256, 512}) {
      const std::string path = (tmp / ("rock_" + std::to_string(side) + ".png")).string();
      write_image(path, crop(rock, 0, 0, side, side));
      exemplars.push_back({path, side});
    }
    const std::string ex256 = exemplars[1].first;
    const std::string common_threads = "--threads=" + threads;
    std::map<std::string, std::vector<std::pair<double, double>>> fits;
    auto record = [&](const std::string& method, const std::string& input, double size, const char* unit,
                      const Outcome& o) {
      nlohmann::json j;
      j["method"] = method;
      j["input"] = input;
      j[unit] = size;
      j["exit_code"] = o.exit_code;
      j["wall_seconds"] = o.wall;
      j["cpu_seconds"] = o.cpu;
      j["peak_mib"] = o.peak_mib;
      j["threads"] = std::stoi(threads);
      if (!o.message.empty()) j["message"] = o.message;
      std::printf("%s\n", j.dump().c_str());
      std::fflush(stdout);
      if (o.exit_code == 0) fits[method].push_back({size, o.cpu});
    };
    const std::string err = (tmp / "stderr.txt").string();
    const std::string out = (tmp / "out").string();
    auto method_run = [&](const std::string& method, std::vector<std::string> args) {
      args.insert(args.begin(), bin);
      args.push_back("--quiet");
      args.push_back("--force");
      args.push_back(common_threads);
      const Outcome o = run(args, err);
      std::error_code ec;
      fs::remove_all(out, ec);
      return o;
    };
    if (wanted("synth"))
      for (const auto& [path, side] : exemplars)
        record("synth", fs::path(path).filename().string(), double(side) * side, "exemplar_pixels",
               method_run("synth", {"synth", path, "-o", out + ".png"}));
    if (wanted("patches-exemplar"))
      for (const auto& [path, side] : exemplars)
        record("patches-exemplar", fs::path(path).filename().string(), double(side) * side, "exemplar_pixels",
               method_run("patches", {"patches", meshes[0].first, path, "-o", out}));
    for (const auto& [mesh, faces] : meshes) {
      const std::string name = fs::path(mesh).filename().string();
      if (wanted("patches"))
        record("patches", name, double(faces), "faces", method_run("patches", {"patches", mesh, ex256, "-o", out}));
      if (wanted("subdiv"))
        record("subdiv", name, double(faces), "faces", method_run("subdiv", {"subdiv", mesh, ex256, "-o", out}));
    }
    if (wanted("material-map")) {
      const std::string tile = (tmp / "tile").string();
      const Outcome t = run({bin, "material-tile", data + "/textures/pebbles_256.png",
                             data + "/textures/box_tree_leaves_256.png", "-o", tile, "--size", "64", "--layers", "2",
                             "--quiet", common_threads},
                            err);
      if (t.exit_code != 0) throw std::runtime_error("material-tile for the material-map runs failed: " + t.message);
      for (const auto& [mesh, faces] : meshes)
        record("material-map", fs::path(mesh).filename().string(), double(faces), "faces",
               method_run("material-map", {"material-map", mesh, "--tile", tile, "-o", out}));
    }
    if (wanted("quilt")) {
      const std::string swatch = (tmp / "weave.obj").string();
      const Outcome s = run({bin, "swatch", "weave", "-o", swatch, "--quiet"}, err);
      if (s.exit_code != 0) throw std::runtime_error("swatch weave failed: " + s.message);
      for (const auto& [mesh, faces] : meshes)
        record("quilt", fs::path(mesh).filename().string(), double(faces), "faces",
               method_run("quilt", {"quilt", mesh, swatch, "-o", out + ".obj"}));
    }
    for (const auto& [method, pts] : fits) {
      nlohmann::json j;
      j["summary"] = method;
      j["exponent_cpu"] = fit_exponent(pts);
      j["sizes"] = pts.size();
      std::printf("%s\n", j.dump().c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    fs::remove_all(tmp);
    return 2;
  }
  fs::remove_all(tmp);
  return 0;
}
