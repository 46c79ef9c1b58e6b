// SPDX-License-Identifier: AGPL-3.0-or-later
// The surface-fidelity figure's nearest-neighbour search (surface_fidelity.h,
// texture/bidirectional_similarity): its cost and how far its bounded
// settings move the figures, on the charts of a real textured surface.
//
// Reads a textured mesh as the CLI writes it (OBJ with corner UVs and its
// atlas PNG, e.g. `surftex patches ... -o DIR`: DIR/mesh.obj, DIR/mesh.png),
// the exemplar and the texel size (the report's fidelity.texel_size), builds
// the charts once (surface_fidelity at its defaults, frames along the atlas's
// u axis) and then runs bidirectional_similarity on the charts and on the
// graph-cut reference with each setting MAX_CANDIDATES/SEARCH_EPS ("0/0" is
// the exact nearest neighbour, slow on big exemplars). The first line is
// surface_fidelity at its defaults (which builds the charts). One JSON line
// per setting: bds, bds_2d, ratio, the search's work (full distances and
// tree visits, surface + reference) and seconds.
//
// Usage: bench_bds_search MESH.obj ATLAS.png EXEMPLAR TEXEL_SIZE [threads]
//          [SETTINGS, e.g. "64/0;256/3;0/0"]
#include <tbb/global_control.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "geometry/timer.h"
#include "texture/bidirectional_similarity.h"
#include "texture/image_ops.h"
#include "texture/surface_fidelity.h"

using namespace surftex;

namespace {

struct Setting {
  std::string text;
  int max_candidates = 0;
  float search_eps = 0;
};

// "C/EPS;C/EPS;...", checked before any work.
std::vector<Setting> parse_settings(const std::string& list) {
  std::vector<Setting> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ';');) {
    Setting st{item};
    if (std::sscanf(item.c_str(), "%d/%f", &st.max_candidates, &st.search_eps) != 2 || st.max_candidates < 0 ||
        !(st.search_eps >= 0))
      throw InvalidInputError("setting '" + item + "' is not MAX_CANDIDATES/SEARCH_EPS (both >= 0)");
    out.push_back(st);
  }
  return out;
}

int run(int argc, char** argv) {
  const int threads = argc > 5 ? std::atoi(argv[5]) : 2;
  if (threads < 1) throw InvalidInputError("threads must be >= 1 (got '" + std::string(argv[5]) + "')");
  const std::vector<Setting> settings = parse_settings(argc > 6 ? argv[6] : "");
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  Mesh mesh;
  read_mesh(argv[1], mesh);
  const Image atlas = read_image(argv[2]);
  const Image exemplar = read_image(argv[3]);
  SurfaceFidelityOptions so;
  so.texel_size = std::atof(argv[4]);
  const TextureFrames frames = frames_from_atlas_uv(mesh, atlas.width, atlas.height);
  Timer t;
  const SurfaceFidelityResult base = surface_fidelity(mesh, exemplar, atlas_color_source(mesh, atlas), frames, so);
  std::printf("%s\n", nlohmann::json({{"setting", "surface_fidelity defaults"},
                                      {"bds", base.bds},
                                      {"bds_2d", base.bds_2d},
                                      {"ratio", base.ratio},
                                      {"evaluations", base.surface.evaluations + base.reference.evaluations},
                                      {"visits", base.surface.visits + base.reference.visits},
                                      {"seconds_bds", base.seconds_bds},
                                      {"seconds_reference", base.seconds_reference},
                                      {"seconds_total", t.seconds()},
                                      {"charts", base.charts},
                                      {"valid_texels", base.valid_texels}})
                          .dump()
                          .c_str());
  std::fflush(stdout);
  const Image ex3 = as_rgb(exemplar);
  for (const Setting& st : settings) {
    const std::string& item = st.text;
    BidirectionalOptions bo = fidelity_similarity_options(so, ex3);
    bo.output_valid = base.mosaic_valid;
    bo.max_candidates = st.max_candidates;
    bo.search_eps = st.search_eps;
    Timer ts;
    const BidirectionalResult s = bidirectional_similarity(base.mosaic, ex3, bo);
    const double t1 = ts.seconds();
    ts.reset();
    const BidirectionalResult r = bidirectional_similarity(base.reference_image, ex3, bo);
    const double t2 = ts.seconds();
    std::printf("%s\n", nlohmann::json({{"setting", item},
                                        {"bds", s.total},
                                        {"coherence", s.coherence},
                                        {"bds_2d", r.total},
                                        {"ratio", r.total > 0 ? s.total / r.total : 0.0},
                                        {"evaluations", s.evaluations + r.evaluations},
                                        {"visits", s.visits + r.visits},
                                        {"seconds_bds", t1},
                                        {"seconds_reference", t2}})
                            .dump()
                            .c_str());
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: bench_bds_search MESH.obj ATLAS.png EXEMPLAR TEXEL_SIZE [threads] [SETTINGS]\n");
    return 2;
  }
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
