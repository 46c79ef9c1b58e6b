// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark of the software rasterizer: a 100,000-triangle torus (procedural,
// smooth normals, vertex colours) rendered at 1024 x 1024 with supersampling 1
// and 2, best of 5 runs each. Usage: bench_render [THREADS] (default: all
// cores). Prints one JSON line per configuration:
// {"bench":"render","mesh":..,"faces":..,"width":..,"height":..,"supersample":..,
//  "seconds":..,"cpu_seconds":..,"megapixels_per_s":..,"threads":..}
// (wall seconds of the best run; megapixels = output pixels).
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <limits>

#include "geometry/rasterizer.h"
#include "geometry/timer.h"

using namespace surftex;

namespace {
// Torus of nu x nv quads (2 nu nv triangles), radii R = 1, r = 0.35.
RenderMesh torus(int nu, int nv) {
  const double pi = 3.14159265358979323846, R = 1.0, r = 0.35;
  RenderMesh m;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      double a = 2 * pi * i / nu, b = 2 * pi * j / nv;
      double cx = std::cos(a), cz = std::sin(a), nx = std::cos(b) * cx, ny = std::sin(b), nz = std::cos(b) * cz;
      m.positions.push_back({float(R * cx + r * nx), float(r * ny), float(R * cz + r * nz)});
      m.vertex_normals.push_back({float(nx), float(ny), float(nz)});
      m.vertex_colors.push_back({float(0.5 + 0.5 * std::sin(8 * a)), float(0.5 + 0.5 * std::cos(3 * b)), 0.6f});
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      int p = j * nu + i, q = j * nu + (i + 1) % nu, s = ((j + 1) % nv) * nu + i, t = ((j + 1) % nv) * nu + (i + 1) % nu;
      m.triangles.push_back({p, s, t});
      m.triangles.push_back({p, t, q});
    }
  return m;
}
}  // namespace

int main(int argc, char** argv) {
  // Optional argument: worker threads (default: all cores).
  const int threads = argc > 1 ? std::max(1, std::atoi(argv[1])) : tbb::info::default_concurrency();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  RenderMesh mesh = torus(250, 200);
  Camera cam = fit_camera(bounding_box(mesh), 30.f, 35.f);
  for (int ss : {1, 2}) {
    RenderOptions opt;
    opt.width = opt.height = 1024;
    opt.supersample = ss;
    opt.color_source = RenderOptions::ColorSource::VertexColors;
    double best = std::numeric_limits<double>::infinity(), best_cpu = best;
    std::size_t fragments = 0;
    for (int run = 0; run < 5; ++run) {
      Timer t;
      std::clock_t c0 = std::clock();
      RenderResult r = render(mesh, cam, opt);
      best = std::min(best, t.seconds());
      best_cpu = std::min(best_cpu, double(std::clock() - c0) / CLOCKS_PER_SEC);
      fragments = r.fragments;
    }
    nlohmann::json j;
    j["bench"] = "render";
    j["mesh"] = "torus_250x200";
    j["faces"] = mesh.triangles.size();
    j["width"] = opt.width;
    j["height"] = opt.height;
    j["supersample"] = ss;
    j["fragments"] = fragments;
    j["seconds"] = best;
    j["cpu_seconds"] = best_cpu;  // process CPU time, all threads: meaningful on a busy machine
    j["megapixels_per_s"] = opt.width * double(opt.height) / 1e6 / best;
    j["threads"] = threads;
    std::printf("%s\n", j.dump().c_str());
  }
  return 0;
}
