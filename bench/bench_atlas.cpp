// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: compute_gutter_atlas (the baked atlas's chart step of `surftex
// subdiv`, and of material-space baking) on one triangle mesh, timed alone.
// Prints one JSON line: wall and process CPU seconds, charts, gutter, texels
// per unit length, area distortion, coverage of the atlas, gutter violations
// and a SHA-256 of the corner uvs and chart ids (equal for every thread count).
//
// Usage: bench_atlas MESH [SIZE=1024] [MAX_CHART_FACES=8000] [THREADS=2]
// MESH: any mesh read_mesh reads (quads are triangulated as the subdiv asset does).
// Measured times: docs/decisions/210-atlas-chart-speed.md.
#include <tbb/global_control.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/gutter_atlas.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/sha256.h"
#include "geometry/timer.h"
#include "geometry/triangulated_copy.h"

using namespace surftex;

namespace {
// SHA-256 of the corner uvs (halfedge order) and face charts as raw bytes.
std::string atlas_hash(const Mesh& m) {
  auto uv = find(m, kCornerUV).first;
  auto patch = find(m, kFacePatch).first;
  std::string bytes;
  for (HalfedgeIndex h : m.halfedges()) bytes.append(reinterpret_cast<const char*>(&uv[h]), sizeof(UV));
  for (FaceIndex f : m.faces()) bytes.append(reinterpret_cast<const char*>(&patch[f]), sizeof(int));
  return sha256_hex(bytes);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_atlas MESH [SIZE=1024] [MAX_CHART_FACES=8000] [THREADS=2]\n");
    return 2;
  }
  const int size = argc > 2 ? std::atoi(argv[2]) : 1024;
  const std::size_t max_faces = argc > 3 ? std::strtoul(argv[3], nullptr, 10) : 8000;
  const int threads = argc > 4 ? std::atoi(argv[4]) : 2;
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  Mesh in, tri;
  read_mesh(argv[1], in);
  triangulated_copy(in, tri);
  const std::clock_t c0 = std::clock();
  Timer t;
  const GutterAtlas g = compute_gutter_atlas(tri, size, 64, max_faces);
  const double wall = t.seconds(), cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
  std::size_t covered = 0;
  for (int c : g.chart) covered += c >= 0;
  const nlohmann::json j = {{"mesh", argv[1]}, {"faces", tri.number_of_faces()}, {"size", size},
                            {"max_chart_faces", max_faces}, {"threads", threads}, {"seconds", wall},
                            {"cpu_seconds", cpu}, {"charts", g.atlas.num_charts}, {"gutter", g.gutter},
                            {"texels_per_length", g.atlas.uv_per_length * size},
                            {"mean_area_distortion", g.atlas.mean_area_distortion},
                            {"coverage", double(covered) / (double(size) * size)},
                            {"violations", g.violations}, {"uv_sha256", atlas_hash(tri)}};
  std::printf("%s\n", j.dump().c_str());
  return 0;
}
