// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch-based oriented surface synthesis speed and seams (Gorla et al. 2003,
// section 4 / Table 1: about 1,600 synthesised texels per second on a
// Pentium III 933 MHz, 96-99% of the time in synthesis), at the CLI's
// defaults (`surftex patches MESH EXEMPLAR`: PatchSynthesisOptions{}, i.e.
// field up, 128 texels per patch side, at most 200 faces per patch, window
// 11, preselect = exemplar width, 64 rotations, the approximate search).
// Sets nothing else. Cases (one JSON line each):
//  - triceratops: CGAL's triceratops.off (5,660 triangles) with leather_64
//    (the paper's 64 x 64 sample size, Table 1);
//  - bear: CGAL's bear.off (27.6K triangles) with pebbles_256 (issue 19's
//    goal: a 256 px exemplar at defaults in <= 60 s on 2 threads);
//  - bear_512: the same with rock_512 (issue 19: >= 100K texels/s up to 512 px);
//  - lion: shared/data's guardian_lion_20k.off with woven_tissue_512 (2,475
//    small patches: the per-texel cost of small patches);
//  - stripes: shared/data's bunny_6k.obj with stripes_blue_white_256 (flat
//    stripes wider than the window: most pixels widen their short list).
// CGAL meshes are extracted with tar from SURFTEX_CGAL_DATA_TARBALL into a
// temporary folder. Measurement history: docs/decisions/501-*.md.
//
// Usage: bench_patches [triceratops|bear|bear_512|lion|stripes|all] [out_dir] [threads]
// (default all, no file output, all cores). out_dir receives
// CASE_atlas.png and CASE_render.png. texels_per_second is texels over the
// synthesis wall time; pipeline_cpu_seconds is the process CPU time (all
// threads) of the synthesis (texture/patches/patch_texture.h step 1), which is
// load-independent; with_atlas_and_seam is the wall time of the driver call
// (synthesis, atlas, seam figure).
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <stdexcept>
#include <unistd.h>
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
#include "texture/image_ops.h"
#include "texture/patches/patch_texture.h"

using namespace surftex;
namespace fs = std::filesystem;

namespace {

Mesh cgal_mesh(const std::string& name) {
  const fs::path tmp = fs::temp_directory_path() / ("surftex_bench_patches_" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  const std::string cmd = std::string("tar xzf '") + SURFTEX_CGAL_DATA_TARBALL + "' -C '" + tmp.string() +
                          "' data/meshes/" + name;
  if (std::system(cmd.c_str()) != 0)
    throw std::runtime_error("cannot extract " + name + " from " + SURFTEX_CGAL_DATA_TARBALL);
  Mesh mesh;
  read_mesh((tmp / "data/meshes" / name).string(), mesh);
  fs::remove_all(tmp);
  return mesh;
}

// "shared:NAME" is shared/data/meshes/NAME, any other name a CGAL mesh.
Mesh load_mesh(const std::string& name) {
  if (name.rfind("shared:", 0) != 0) return cgal_mesh(name);
  Mesh mesh;
  read_mesh(std::string(SURFTEX_SHARED_DATA_DIR) + "/meshes/" + name.substr(7), mesh);
  return mesh;
}

void run_case(const std::string& name, const std::string& mesh_file, const std::string& texture,
              const std::string& out) {
  Mesh mesh = load_mesh(mesh_file);
  const Image ex = as_rgb(read_image(std::string(SURFTEX_SHARED_DATA_DIR) + "/textures/" + texture));
  PatchTextureOptions to;  // the CLI's synthesis defaults; no PBR maps, no fidelity (not measured here)
  to.pbr_maps = false;
  to.fidelity = false;
  const PatchSynthesisOptions& po = to.synthesis;
  Timer total;
  const PatchTextureResult t = synthesize_patch_texture(mesh, {ex}, {}, to);
  const double all = total.seconds();
  const PatchSynthesisResult& r = t.synthesis;
  const PatchAtlas& at = t.atlas;
  const SeamRatioResult& s = t.seam;
  if (!out.empty()) {
    fs::create_directories(out);
    write_image(out + "/" + name + "_atlas.png", at.image);
    ViewOptions view;
    view.size = 1024;
    view.azimuth_deg = 60.f;
    view.elevation_deg = 15.f;
    view.texture = &at.image;
    write_image(out + "/" + name + "_render.png", render_view(mesh, view));
  }
  nlohmann::json j;
  j["bench"] = "patches_" + name;
  j["sets"] = "nothing (CLI defaults)";
  j["mesh"] = mesh_file;
  j["faces"] = mesh.number_of_faces();
  j["texture"] = texture;
  j["exemplar"] = std::to_string(ex.width) + "x" + std::to_string(ex.height);
  j["patch_res"] = po.flatten.resolution;
  j["window"] = po.el.window;
  j["preselect"] = po.el.preselect > 0 ? po.el.preselect : ex.width;
  j["rotations"] = po.el.rotations;
  j["search"] = po.el.search == ElSearch::Approximate ? "approximate" : "exhaustive";
  j["patches"] = r.flat.patches.size();
  j["texels_synthesized"] = r.texels;
  j["texels_per_second"] = r.texels / r.seconds_synthesis;
  j["seconds"] = {{"partition", r.seconds_partition}, {"field", r.seconds_field},
                  {"flatten", r.seconds_flatten},     {"synthesis", r.seconds_synthesis},
                  {"pipeline", r.seconds_total},      {"with_atlas_and_seam", all}};
  j["pipeline_cpu_seconds"] = t.cpu_seconds_synthesis;
  j["threads"] = tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  j["synthesis_share"] = r.seconds_synthesis / r.seconds_total;
  j["seam_ratio"] = s.ratio;
  j["seam_pairs_across"] = s.pairs_across;
  std::printf("%s\n", j.dump().c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string which = argc > 1 && argv[1][0] ? argv[1] : "all";
  const std::string out = argc > 2 ? argv[2] : "";
  std::unique_ptr<tbb::global_control> limit;
  if (argc > 3 && std::atoi(argv[3]) > 0)
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  std::atoi(argv[3]));
  try {
    if (which == "all" || which == "triceratops") run_case("triceratops", "triceratops.off", "leather_64.png", out);
    if (which == "all" || which == "bear") run_case("bear", "bear.off", "pebbles_256.png", out);
    if (which == "all" || which == "bear_512") run_case("bear_512", "bear.off", "rock_512.png", out);
    if (which == "all" || which == "lion") run_case("lion", "shared:guardian_lion_20k.off", "woven_tissue_512.png", out);
    if (which == "all" || which == "stripes") run_case("stripes", "shared:bunny_6k.obj", "stripes_blue_white_256.png", out);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
