// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex demo [-o DIR]`: a tour of surftex on built-in inputs that the
// project generates itself (procedural textures and meshes built in code), so
// it runs on a fresh machine with no data. Each step writes its outputs into
// DIR and a line into DIR/report.json.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "batch/contact_sheet.h"
#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/render_view.h"
#include "geometry/timer.h"
#include "geometry/up_axis.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"
#include "surftex/demo_steps.h"
#include "texture/bidirectional_similarity.h"
#include "texture/efros_leung.h"
#include "texture/graphcut_synthesis.h"
#include "texture/histogram_distance.h"
#include "texture/procedural_texture.h"
#include "texture/tileable_tile.h"
#include "texture/wrap_seam_ratio.h"

namespace fs = std::filesystem;

namespace surftex::cli {

std::vector<DemoStep>& demo_steps() {
  static std::vector<DemoStep> steps;
  return steps;
}

namespace {
namespace demo_command {  // named: the unity build joins these files

constexpr const char* kMarker = ".surftex-demo";

// The demo owns DIR: it may replace its own earlier outputs there (marked by
// kMarker), but never writes into a non-empty folder it did not create.
void prepare_demo_dir(const std::string& dir, bool force) {
  std::error_code ec;
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) throw IOError("demo output '" + dir + "' exists and is not a folder");
    bool empty = fs::is_empty(dir, ec);
    if (!empty && !fs::exists(fs::path(dir) / kMarker, ec) && !force)
      throw IOError("demo folder '" + dir +
                    "' is not empty and was not made by `surftex demo` (pass --force or choose another -o)");
  }
  ensure_directory(dir);
  write_file_atomic((fs::path(dir) / kMarker).string(), "made by surftex demo\n", true);
}

// The files the steps named (ctx.path) or reported (ctx.wrote) that exist
// now, folders expanded, in the order first named; the marker and the report
// itself are left out.
std::vector<std::string> demo_outputs(const DemoContext& ctx, const std::string& report_path) {
  std::vector<std::string> out;
  auto add = [&](const fs::path& p) {
    std::error_code ec;
    // (a file of this run is still in its staging folder: geometry/output_file.h)
    if (p.filename() == kMarker || same_file(p.string(), report_path) || !fs::is_regular_file(staged_path(p.string()), ec))
      return;
    if (std::find(out.begin(), out.end(), p.string()) == out.end()) out.push_back(p.string());
  };
  for (const std::string& name : ctx.named) {
    const fs::path p = fs::path(ctx.dir) / name;
    std::error_code ec;
    if (fs::is_directory(staged_path(p.string()), ec)) {
      for (const std::string& f : files_in_folder(p.string())) add(f);
    } else {
      add(p);
    }
  }
  for (const std::string& f : ctx.written) add(f);
  return out;
}

// Step 1: image synthesis from a generated exemplar by the three 2D engines.
nlohmann::json step_synthesis(DemoContext& ctx) {
  nlohmann::json j;
  // A structured exemplar cut from a larger generated texture (not itself
  // periodic, so graph-cut cannot simply re-tile it).
  Image cells(80, 80, 3);
  {
    Image big = make_cells(160, 7, ctx.seed);
    for (int y = 0; y < 80; ++y)
      for (int x = 0; x < 80; ++x)
        for (int c = 0; c < 3; ++c) cells.at(x, y, c) = big.at(x + 13, y + 29, c);
  }
  write_image(ctx.path("exemplar_cells.png"), cells);
  Image stripes = make_stripes(64, 8, 0);
  write_image(ctx.path("exemplar_stripes.png"), stripes);
  ctx.exemplar = cells;

  // Efros-Leung suits stochastic textures: flat regions wider than the window
  // (the cells) make it grow flat areas, a known limit of the method.
  Image noise = make_noise(64, 4, ctx.seed + 1);
  write_image(ctx.path("exemplar_noise.png"), noise);
  Timer t;
  ElOptions el;
  el.window = 11;
  el.seed = ctx.seed;
  el.progress = ctx.progress;
  Image el_out = efros_leung_synthesize(noise, 128, 128, el);
  write_image(ctx.path("synth_el2pass.png"), el_out);
  j["seconds"]["el2pass"] = t.seconds();
  j["el2pass"] = {{"size", "128x128"},
                  {"bidirectional_similarity", bidirectional_similarity(el_out, noise, {.patch = 7, .periodic_exemplar = true, .stride = 2}).total},
                  {"histogram_chi2", histogram_chi_square(el_out, noise)}};

  // Oriented synthesis (Gorla 3.3.2): stripes following a smooth wavy angle
  // field (no singularity: a singular field seeded at its centre only grows rays).
  t.reset();
  ElInput in;
  in.exemplars = {stripes};
  in.target = Image(128, 128, 3);
  in.angle_fn = [](int x, int) { return 0.7 * std::sin(2 * 3.14159265358979 * x / 128.0); };
  ElOptions eo = el;
  eo.rotations = 32;
  Image oriented = efros_leung_synthesize(in, eo).image;
  write_image(ctx.path("synth_oriented_wavy.png"), oriented);
  j["seconds"]["oriented"] = t.seconds();
  j["oriented"] = {{"rotations", eo.rotations}};

  t.reset();
  GraphcutOptions gc;
  gc.seed = ctx.seed;
  gc.progress = ctx.progress;
  Image gc_out = graphcut_synthesize(cells, 256, 256, gc);
  write_image(ctx.path("synth_graphcut.png"), gc_out);
  j["seconds"]["graphcut"] = t.seconds();
  j["graphcut"] = {{"size", "256x256"},
                   {"bidirectional_similarity", bidirectional_similarity(gc_out, cells, {.patch = 7, .periodic_exemplar = false, .stride = 4}).total}};

  t.reset();
  TileOptions to;
  to.seed = ctx.seed;
  to.progress = ctx.progress;
  ctx.tile = make_tileable(make_noise(96, 4, ctx.seed), 128, to);
  write_image(ctx.path("tile_noise.png"), ctx.tile);
  j["seconds"]["tile"] = t.seconds();
  j["tile"] = {{"wrap_seam_ratio", wrap_seam_ratio(ctx.tile)}};
  return j;
}

// Step 2: a torus textured with the periodic tile, exported and rendered.
nlohmann::json step_textured_torus(DemoContext& ctx) {
  Mesh torus;
  make_torus(torus, 2.0, 0.7, 96, 48);
  assign_torus_uvs(torus, 2.0, 4.0, 2.0);
  z_up_to_y_up(torus);  // lying flat in glTF viewers (geometry/up_axis.h)
  WriteMeshOptions wo;
  wo.texture = &ctx.tile;
  // The OBJ's texture is torus_tiled.png (write_mesh), so the render is named apart.
  ctx.wrote(write_mesh(ctx.path("torus_tiled.obj"), torus, wo));
  write_mesh(ctx.path("torus_tiled.glb"), torus, wo);
  ViewOptions view;
  view.azimuth_deg = 20.f;
  view.elevation_deg = 35.f;
  view.texture = &ctx.tile;
  view.wrap = RenderOptions::Wrap::Repeat;  // the tile repeats 4 x 2 times around the torus
  write_image(ctx.path("torus_tiled_render.png"), render_view(torus, view));
  return {{"faces", torus.number_of_faces()},
          {"outputs", {"torus_tiled.obj", "torus_tiled.mtl", "torus_tiled.png", "torus_tiled.glb",
                       "torus_tiled_render.png"}}};
}

std::function<int()> setup(CLI::App& app) {
  auto dir = std::make_shared<std::string>("out/demo");
  auto common = std::make_shared<CommonOptions>();
  app.add_option("-o,--output", *dir,
                 "Folder for the demo's meshes, renders and report.json (default out/demo; created if "
                 "absent; the demo replaces its own earlier outputs there, and refuses a non-empty folder "
                 "it did not make unless --force)");
  add_common_options(app, *common);
  return [dir, common]() -> int {
    auto threads = apply_thread_limit(common->threads);
    prepare_demo_dir(*dir, common->force);
    DemoContext ctx;
    ctx.dir = *dir;
    ctx.seed = common->seed;
    ctx.progress = terminal_progress(common->quiet);
    std::vector<DemoStep> steps{{10, "synthesis", "2D synthesis: two-pass Efros-Leung, oriented, graph-cut, tile",
                                 step_synthesis},
                                {20, "textured_torus", "a torus textured with the tile (OBJ, GLB, render)",
                                 step_textured_torus}};
    for (auto& s : demo_steps()) steps.push_back(s);
    std::stable_sort(steps.begin(), steps.end(), [](auto& a, auto& b) { return a.order < b.order; });
    nlohmann::json report;
    Timer total;
    for (auto& s : steps) {
      std::fprintf(stderr, "demo: %s\n", s.description.c_str());
      Timer t;
      report["steps"][s.name] = s.run(ctx);
      report["seconds"][s.name] = t.seconds();
    }
    report["output_dir"] = *dir;
    CommonOptions ro = *common;
    if (ro.report_path.empty()) ro.report_path = (fs::path(*dir) / "report.json").string();
    const std::vector<std::string> outputs = demo_outputs(ctx, ro.report_path);
    write_report(ro, "demo", report, {{}, outputs});
    batch::write_demo_contact_sheet(*dir, report, outputs);  // DIR/index.html (issue 20, item 4)
    std::printf("demo: done in %.1f s; results in %s (report.json lists them)\n", total.seconds(), dir->c_str());
    return 0;
  };
}

SubcommandRegistrar reg{{"demo", "Tour of every method on built-in inputs the project generates (writes into out/demo)",
                         setup}};

}  // namespace demo_command
}  // namespace
}  // namespace surftex::cli
