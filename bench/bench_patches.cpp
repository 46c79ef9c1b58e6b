// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch-based oriented surface synthesis speed and seams (Gorla et al. 2003,
// section 4 / Table 1: about 1,600 synthesised texels per second on a
// Pentium III 933 MHz, 96-99% of the time in synthesis): CGAL's
// triceratops.off (extracted with tar from SURFTEX_CGAL_DATA_TARBALL into a
// temporary folder), a stochastic texture from the shared data, 128x128
// texels per patch, "up" field, window 9, preselect = exemplar width (one
// scanline). Prints one JSON line.
//
// Measured (2 cores shared with other builds, load average 15, so wall times
// are inflated about 2-3x; the same binary pair back to back):
//   before (sequential patches, rotations per patch, nth_element pass 1):
//     synthesis 49.4 s wall, 18.1 s user for the whole run, 9,077 texels/s, seam 0.966
//   now: synthesis 27.3 s wall, 11.2 s user for the whole run (pipeline CPU
//     9.5 s), 16,424 texels/s under that load, seam 0.964; 664 patches,
//     448,593 texels; the patch dependency graph allows up to 8x parallelism
//     (critical path 55,951 texels), so on a quiet 2-core machine the wall
//     time should be about half the pipeline CPU time.
//
// Usage: bench_patches [texture.png] [out_dir] [patch_res] [max_patch_faces] [threads]
// (default leather_64.png, no file output, 128, 120, all cores; "" keeps a
// default). out_dir receives atlas.png and render.png. texels_per_second is
// texels over the synthesis wall time; synthesis_cpu_seconds is the process
// CPU time (all threads) of the whole pipeline call, which is load-independent.
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <ctime>
#include <memory>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "geometry/render_view.h"
#include "geometry/timer.h"
#include "texture/patch_atlas.h"
#include "texture/patch_seam_ratio.h"
#include "texture/patch_synthesis.h"

using namespace surftex;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  const std::string tex = argc > 1 && argv[1][0] ? argv[1]
                                                 : std::string(SURFTEX_SHARED_DATA_DIR) + "/textures/leather_64.png";
  const std::string out = argc > 2 ? argv[2] : "";
  const int res = argc > 3 && argv[3][0] ? std::atoi(argv[3]) : 128;
  const int max_faces = argc > 4 && argv[4][0] ? std::atoi(argv[4]) : 120;
  std::unique_ptr<tbb::global_control> limit;
  if (argc > 5 && std::atoi(argv[5]) > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  std::atoi(argv[5]));
  const fs::path tmp = fs::temp_directory_path() / ("surftex_bench_patches_" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  const std::string cmd = std::string("tar xzf '") + SURFTEX_CGAL_DATA_TARBALL + "' -C '" + tmp.string() +
                          "' data/meshes/triceratops.off";
  if (std::system(cmd.c_str()) != 0) {
    std::fprintf(stderr, "cannot extract triceratops.off from %s\n", SURFTEX_CGAL_DATA_TARBALL);
    return 1;
  }
  Mesh mesh;
  read_mesh((tmp / "data/meshes/triceratops.off").string(), mesh);
  fs::remove_all(tmp);
  Image ex = read_image(tex);
  if (ex.channels != 3) {
    Image rgb(ex.width, ex.height, 3);
    for (int y = 0; y < ex.height; ++y)
      for (int x = 0; x < ex.width; ++x)
        for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = ex.at(x, y, ex.channels >= 3 ? c : 0);
    ex = rgb;
  }
  PatchSynthesisOptions po;
  po.flatten.resolution = res;
  po.flatten.margin = std::max(2, res / 32);
  po.partition.max_faces = max_faces;
  po.field = PatchField::Constant;
  po.el.window = 9;
  po.el.preselect = ex.width;
  po.seed = 1;
  Timer total;
  const std::clock_t c0 = std::clock();
  PatchSynthesisResult r = synthesize_patches(mesh, {ex}, po);
  const double pipeline_cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  PatchAtlas at = pack_patch_atlas(mesh, r.flat, r.images);
  const SeamRatioResult s = patch_seam_ratio(mesh, r.flat, at.image);
  const double all = total.seconds();
  if (!out.empty()) {
    fs::create_directories(out);
    write_image(out + "/atlas.png", at.image);
    ViewOptions view;
    view.size = 1024;
    view.azimuth_deg = 60.f;
    view.elevation_deg = 15.f;
    view.texture = &at.image;
    write_image(out + "/render.png", render_view(mesh, view));
  }
  nlohmann::json j;
  j["bench"] = "patches_triceratops";
  j["faces"] = mesh.number_of_faces();
  j["texture"] = fs::path(tex).filename().string();
  j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height);
  j["patch_res"] = res;
  j["patches"] = r.flat.patches.size();
  j["texels_synthesized"] = r.texels;
  j["texels_per_second"] = r.texels / r.seconds_synthesis;
  j["seconds"] = {{"partition", r.seconds_partition}, {"field", r.seconds_field},
                  {"flatten", r.seconds_flatten},     {"synthesis", r.seconds_synthesis},
                  {"pipeline", r.seconds_total},      {"with_atlas_and_seam", all}};
  j["pipeline_cpu_seconds"] = pipeline_cpu;
  j["threads"] = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  j["synthesis_share"] = r.seconds_synthesis / r.seconds_total;
  j["seam_ratio"] = s.ratio;
  j["seam_pairs_across"] = s.pairs_across;
  j["window"] = po.el.window;
  j["preselect"] = po.el.preselect;
  std::printf("%s\n", j.dump().c_str());
  return 0;
}
