// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex subdiv MESH EXEMPLAR -o OUTDIR`: texture synthesis on a surface by
// graph matching over a sqrt(2)-subdivision hierarchy (Bangay & Morkel 2006),
// and its demo step.
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/render_view.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"
#include "surftex/demo_steps.h"
#include "texture/displace_by_vertex_color.h"
#include "texture/procedural_texture.h"
#include "texture/subdivision/subdivision_asset.h"
#include "texture/subdivision/subdivision_synthesis.h"

namespace fs = std::filesystem;

namespace surftex::cli {
namespace {
namespace subdiv_command {  // named: the unity build joins these files

struct Outputs {
  std::string ply, glb, obj, render;
};

Outputs output_paths(const std::string& dir) {
  auto p = [&](const char* n) { return (fs::path(dir) / n).string(); };
  return {p("surface.ply"), p("surface.glb"), p("surface_atlas.obj"), p("render.png")};
}

/// Every file written into the output folder (for the overwrite check).
std::vector<std::string> output_files(const std::string& dir) {
  std::vector<std::string> f;
  for (const char* n : {"surface.ply", "surface.glb", "surface_atlas.obj", "surface_atlas.mtl", "surface_atlas.png",
                        "surface_atlas_normal.png", "surface_atlas_height.png", "surface_atlas_roughness.png", "render.png",
                        "report.json"})
    f.push_back((fs::path(dir) / n).string());
  return f;
}

// Writes the synthesised `mesh` and its baked asset: surface.ply keeps the
// polygons with COLOR_0-style vertex colours; surface_atlas.obj (+MTL, maps)
// and surface.glb hold the asset's triangle copy (the atlas as base colour,
// normal map, vertex colours kept as _COLOR beside the texture that holds
// them: COLOR_0 would multiply it; roughness as the GLB's
// metallicRoughnessTexture); render.png shows the atlas on the copy, as the
// GLB shows it. Returns
// the report's "export" block with "files" (every path written).
nlohmann::json write_outputs(const Mesh& mesh, const SubdivisionAsset& asset, const Outputs& o, bool force) {
  nlohmann::json j;
  Timer t;
  WriteMeshOptions wo;
  wo.overwrite = force;
  wo.write_uvs = false;
  WriteMeshOptions ao;
  ao.overwrite = force;
  ao.write_colors = false;
  ao.texture = &asset.color.image;
  ao.normal_texture = &asset.normal;
  ao.height_texture = &asset.height;
  ao.metallic_roughness_texture = &asset.metallic_roughness;
  ao.texture_repeat = false;
  WriteMeshOptions go = ao;
  go.height_texture = nullptr;
  go.write_colors = true;
  go.color_attribute = "_COLOR";
  // The PLY, and the OBJ and GLB sharing their encoded maps (each file mostly
  // one thread's PNG or text encoding); the render beside them (it reads the
  // mesh only).
  std::vector<std::string> ply_files, obj_glb_files;
  double seconds_write = 0, seconds_render = 0;
  tbb::parallel_invoke(
      [&] {
        tbb::parallel_invoke([&] { ply_files = write_mesh(o.ply, mesh, wo); },
                             [&] { obj_glb_files = write_obj_and_glb(o.obj, o.glb, *asset.mesh, ao, go); });
        seconds_write = t.seconds();
      },
      [&] {
        Timer tr;
        ViewOptions view;  // what a glTF viewer shows: the atlas on the triangle copy
        view.colors = ViewOptions::Colors::Texture;
        view.texture = &asset.color.image;
        WriteImageOptions io;
        io.overwrite = force;
        write_image(o.render, render_view(*asset.mesh, view), io);
        seconds_render = tr.seconds();
      });
  std::vector<std::string> files = ply_files;
  files.insert(files.end(), obj_glb_files.begin(), obj_glb_files.end());
  j["seconds_write_mesh"] = seconds_write;
  j["atlas"] = to_json(asset);
  j["seconds_render"] = seconds_render;
  files.push_back(o.render);
  j["files"] = files;
  return j;
}

// --texel-size: "Nx" = N exemplar widths across the longest bounding-box
// side, "N/edge" = N exemplar texels per mean edge of the input mesh.
void parse_texel_size(const std::string& spec, SubdivisionSynthesisOptions& o) {
  if (spec.empty()) return;
  auto number = [&](const std::string& t) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != t.size() || !(v > 0) || !std::isfinite(v))
      throw InvalidInputError("--texel-size '" + spec +
                              "' must be Nx (N > 0 exemplar widths across the object, e.g. 3x) or N/edge (N > 0 "
                              "exemplar texels per mean edge of the mesh, e.g. 2/edge)");
    return v;
  };
  const std::string edge = "/edge";
  if (spec.size() > edge.size() && spec.compare(spec.size() - edge.size(), edge.size(), edge) == 0) {
    o.texels_per_edge = number(spec.substr(0, spec.size() - edge.size()));
  } else if (spec.size() > 1 && (spec.back() == 'x' || spec.back() == 'X')) {
    o.repeats = number(spec.substr(0, spec.size() - 1));
    o.repeats_fixed = true;
  } else {
    number("");  // throws the explanation
  }
}

void print_scale(const SubdivisionSynthesisResult& r) {
  const SubdivisionScale& s = r.scale;
  std::fprintf(stderr,
               "subdiv: scale from %s: %.3g exemplar widths across (r_scale %.4g, %.3g texels per mean edge), "
               "texel %.4g mesh units; %d uniform levels%s (vertex spacing %.2f texels, ~%zu vertices); exemplar "
               "%dx%d%s; %s (wrap-seam ratio %.2f)\n",
               s.scale_from, s.repeats, s.r_scale, s.texels_per_edge, s.texel_size, s.levels,
               s.levels_chosen ? (s.budget_limited ? " (chosen, limited by --max-vertices)" : " (chosen)") : "",
               s.spacing_texels, s.predicted_vertices, s.exemplar_width, s.exemplar_height,
               s.exemplar_scale < 1 ? " (reduced to fit --max-vertices)" : "",
               r.periodic ? "wrapped as periodic" : "not wrapped", r.wrap_seam_ratio);
  if (s.repeats < s.repeats_requested)
    std::fprintf(stderr,
                 "subdiv: %.3g exemplar widths across instead of the default %.3g: reduced further to fit "
                 "--max-vertices, the exemplar would lose its fine detail (%.0f%% of it kept now; give "
                 "--texel-size %gx to insist)\n",
                 s.repeats, s.repeats_requested, 100 * s.relative_detail, s.repeats_requested);
}

struct SubdivArgs {
  std::string mesh, exemplar, outdir, texel_size, wrap = "auto";
  std::string exemplar_normal, exemplar_height, exemplar_roughness;
  double rscale = 0, adaptive = 1.5, displace = 0, region = 9, sigma = 1, repetition = 0.3;
  int levels = -1, passes = 1, adaptive_steps = 4, atlas = 0, exhaustive_levels = 1;
  std::size_t max_vertices = SubdivisionSynthesisOptions{}.max_vertices;
  double bump = 2;
  bool pyramid = false, fixed_region = false, no_antialias = false, no_averaging = false, no_cut = false, projection = false;
  CommonOptions common;
};

// Exemplar maps (--exemplar-normal, --exemplar-height, --exemplar-roughness):
// each the colour exemplar's size, a normal map RGB. Read before the
// synthesis, so a bad map stops the run before any output.
SubdivisionExemplarMaps read_exemplar_maps(const SubdivArgs& a, const Image& colour) {
  auto read_map = [&](const std::string& path, const char* what) -> Image {
    return read_exemplar_map(path, what, a.exemplar, colour);
  };
  SubdivisionExemplarMaps maps;
  maps.normal = read_map(a.exemplar_normal, "--exemplar-normal");
  if (!maps.normal.empty() && maps.normal.channels < 3)
    throw InvalidInputError("--exemplar-normal '" + a.exemplar_normal + "' has " +
                            std::to_string(maps.normal.channels) + " channel(s): a tangent-space normal map is RGB");
  maps.height = read_map(a.exemplar_height, "--exemplar-height");
  maps.roughness = read_map(a.exemplar_roughness, "--exemplar-roughness");
  return maps;
}

int run_subdiv(const SubdivArgs& a) {
  require_input_file(a.mesh, "mesh");
  require_input_file(a.exemplar, "exemplar");
  std::vector<std::string> inputs{a.mesh, a.exemplar};
  for (const auto& [path, what] : {std::pair{a.exemplar_normal, "--exemplar-normal"},
                                   {a.exemplar_height, "--exemplar-height"},
                                   {a.exemplar_roughness, "--exemplar-roughness"}})
    if (!path.empty()) {
      require_input_file(path, what);
      inputs.push_back(path);
    }
  const Outputs out = output_paths(a.outdir);
  for (const std::string& p : output_files(a.outdir)) {
    if (fs::path(p).filename() == "report.json") continue;  // the report is replaced (as before)
    check_output(p, inputs, a.common.force, false);
  }
  auto limit = apply_thread_limit(a.common.threads);
  Timer total, t;
  Mesh mesh;
  LoadInputReport loaded;
  Image ex;
  SubdivisionExemplarMaps maps;
  // The mesh and the images side by side (the first image read also loads
  // the image library); a broken mesh is reported before a broken image.
  std::exception_ptr mesh_error, image_error;
  tbb::parallel_invoke(
      [&] {
        try {  // sqrt(2)-subdivision takes any polygons: they are kept when they need no repair.
          loaded = load_method_mesh(a.mesh, mesh, a.common, true);
        } catch (...) {
          mesh_error = std::current_exception();
        }
      },
      [&] {
        try {
          ex = read_image(a.exemplar);
          maps = read_exemplar_maps(a, ex);
        } catch (...) {
          image_error = std::current_exception();
        }
      });
  if (mesh_error) std::rethrow_exception(mesh_error);
  if (image_error) std::rethrow_exception(image_error);
  const nlohmann::json opaque = use_opaque_part(ex, {&maps.normal, &maps.height, &maps.roughness}, a.common);
  const double seconds_read = t.seconds();
  SubdivisionSynthesisOptions o;
  o.r_scale = a.rscale;
  parse_texel_size(a.texel_size, o);
  o.levels = a.levels;
  o.max_vertices = a.max_vertices;
  o.wrap = a.wrap == "periodic" ? ExemplarWrap::Periodic : a.wrap == "bounded" ? ExemplarWrap::Bounded : ExemplarWrap::Auto;
  o.repetition_penalty = a.repetition;
  o.exhaustive_levels = a.exhaustive_levels;
  o.adaptive_factor = a.adaptive;
  o.adaptive_steps = a.adaptive_steps;
  o.passes = a.passes;
  o.region_texels = a.region;
  o.sigma = a.sigma;
  o.pyramid = a.pyramid;
  o.level_relative_region = !a.fixed_region;
  o.antialias = !a.no_antialias;
  o.averaging = !a.no_averaging;
  o.graph_cut = !a.no_cut;
  o.coordinates = a.projection ? LocalCoordinates::kTangentProjection : LocalCoordinates::kUnfolding;
  o.seed = a.common.seed;
  o.progress = terminal_progress(a.common.quiet);
  // --levels -1 (chosen from the scale) is bounded by --max-vertices: the
  // estimate takes the levels that reach it (each sqrt(2) level doubles the faces).
  int est_levels = a.levels;
  if (est_levels < 0) {
    const double faces = std::max<double>(1.0, static_cast<double>(mesh.number_of_faces()));
    est_levels = std::max(0, static_cast<int>(std::floor(std::log2(2.0 * static_cast<double>(a.max_vertices) / faces))));
  }
  // --atlas-size 0 follows the final vertex count: about half the faces,
  // which double with each level (at most max_vertices when the levels follow the scale).
  double est_vertices = 0.5 * static_cast<double>(mesh.number_of_faces()) * std::ldexp(1.0, est_levels);
  if (a.levels < 0) est_vertices = std::min(est_vertices, static_cast<double>(a.max_vertices));
  const int est_atlas = a.atlas > 0 ? a.atlas
                                    : default_subdivision_atlas_size(static_cast<std::size_t>(std::min(est_vertices, 1e12)));
  check_budget(estimate_subdiv(mesh.number_of_faces(), ex.width, ex.height, est_levels, est_atlas), a.common);
  const SubdivisionSynthesisResult r = synthesize_on_subdivision(mesh, ex, o);
  if (!a.common.quiet) print_scale(r);
  SubdivisionAssetOptions ao;
  ao.atlas_size = a.atlas > 0 ? a.atlas : default_subdivision_atlas_size(mesh.number_of_vertices());
  ao.bump = a.bump;
  ao.texels_per_length = r.scale.r_scale / r.object_unit;
  ao.texel_size = r.scale.texel_size;
  nlohmann::json fidelity;
  SubdivisionVertexMaps vmaps;
  SubdivisionAsset asset;
  DisplaceResult disp;
  // the texture between the vertices follows the surface as synthesised
  const SubdivisionSurfaceSources between = subdivision_surface_sources(mesh, r, maps, ex.width, ex.height, &ex);
  // frames of the surface as written (after --displace)
  auto bake = [&] {
    vmaps = exemplar_maps_at_vertices(mesh, r, maps, ex.width, ex.height);
    vmaps.between = between;
    asset = bake_subdivision_asset(mesh, vmaps, ao);
  };
  auto measure = [&] { fidelity = subdivision_fidelity_report(mesh, r, a.common.seed); };
  if (a.displace != 0) {  // the fidelity is measured on the undisplaced surface
    measure();
    disp = displace_by_vertex_color(mesh, a.displace * r.object_unit);
    bake();
  } else {  // both only read the mesh: side by side (each is deterministic alone)
    tbb::parallel_invoke(measure, bake);
  }
  ensure_directory(a.outdir);
  nlohmann::json rep = to_json(r, o);
  rep["fidelity"] = fidelity;
  if (a.displace != 0) rep["displace_offset_range"] = {disp.min_offset, disp.max_offset};
  rep["mesh"] = a.mesh;
  rep["input_mesh"] = to_json(loaded);
  rep["exemplar"] = a.exemplar;
  if (!opaque.is_null()) rep["exemplar_transparency"] = opaque;
  rep["displace"] = a.displace;
  if (!a.exemplar_normal.empty() || !a.exemplar_height.empty() || !a.exemplar_roughness.empty())
    rep["exemplar_maps"] = {{"normal", a.exemplar_normal}, {"height", a.exemplar_height},
                            {"roughness", a.exemplar_roughness}, {"vertices_without_lookup", vmaps.filled}};
  nlohmann::json written = write_outputs(mesh, asset, out, a.common.force);
  const RunFiles files{inputs, written["files"].get<std::vector<std::string>>()};
  rep["seconds"] = {{"read", seconds_read},
                    {"synthesis", r.seconds_total},
                    {"write_mesh", written["seconds_write_mesh"]},
                    {"atlas", written["atlas"]["seconds"]["bake"]},
                    {"render", written["seconds_render"]}};
  written.erase("files");
  rep["export"] = written;
  CommonOptions ro = a.common;
  if (ro.report_path.empty()) {
    ro.report_path = (fs::path(a.outdir) / "report.json").string();
    ro.force = true;
  }
  write_report(ro, "subdiv", rep, files);
  if (!a.common.quiet)
    std::fprintf(stderr, "subdiv: %zu vertices after %d levels, fidelity %.2fx graph-cut 2D, %.1f s -> %s\n",
                 static_cast<std::size_t>(mesh.number_of_vertices()), r.scale.levels,
                 fidelity.value("ratio", 0.0), total.seconds(), a.outdir.c_str());
  return 0;
}

SubdivisionSynthesisResult demo_run(Mesh& mesh, const Image& ex, std::uint64_t seed, const ProgressCallback& pr) {
  SubdivisionSynthesisOptions o;
  // Cells of 16 texels, 4 per cube side; 10 levels bring the final edges to
  // about 2 texels (stack level 1), fine enough to show the mortar lines (at 7
  // levels the finest vertices were 8 texels apart: only blurred blotches).
  o.r_scale = 64;
  o.levels = 10;
  o.passes = 2;
  o.seed = seed;
  o.progress = pr;
  return synthesize_on_subdivision(mesh, ex, o);
}

SubcommandRegistrar reg_subdiv{
    {"subdiv", "Texture synthesis by graph matching on a sqrt(2)-subdivision hierarchy (Bangay & Morkel 2006)",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<SubdivArgs>();
       app.add_option("mesh", a->mesh, "Input mesh (OFF/OBJ/PLY/STL; polygons kept, any genus)")->required();
       app.add_option("exemplar", a->exemplar,
                      "Exemplar image (any format OpenImageIO reads); wrapped around only if it tiles (see --wrap). "
                      "With transparent pixels (a hole, a cut-out) its largest opaque block is used when that holds "
                      "a quarter of it (the output has no alpha)")
           ->required();
       app.add_option("-o,--output", a->outdir,
                      "Output folder: surface.ply (vertex colours), surface.glb (baked atlas as base colour, "
                      "normal map, vertex colours as _COLOR), surface_atlas.obj/.mtl/.png (baked atlas: the exemplar "
                      "read between the vertices where their colours were read) with "
                      "surface_atlas_normal.png and surface_atlas_height.png (16-bit) (and surface_atlas_roughness.png "
                      "with --exemplar-roughness), render.png (the atlas as a glTF viewer shows it), report.json")
           ->required();
       auto* ts = app.add_option("--texel-size", a->texel_size,
                                 "Texture scale: Nx = N exemplar widths across the longest bounding-box side, or "
                                 "N/edge = N exemplar texels per mean edge of the input mesh (default 3x; fewer, down to 1x, "
                                 "when --max-vertices would reduce the exemplar so far that less than a third of "
                                 "its fine detail survives: a given Nx is kept)");
       app.add_option("--rscale", a->rscale,
                      "The paper's r_scale instead of --texel-size: exemplar texels per object unit, the object "
                      "unit being the longest bounding-box side; larger = smaller texture features; 1e-3..1e6 "
                      "(default: from --texel-size)")
           ->check(CLI::Range(1e-3, 1e6))
           ->excludes(ts);
       app.add_option("--levels", a->levels,
                      "Uniform sqrt(2)-subdivision steps after the base mesh, 0..12, each about doubling the vertex "
                      "count; -1 (default) = the fewest that bring the vertex spacing down to one texel")
           ->check(CLI::Range(-1, 12));
       app.add_option("--max-vertices", a->max_vertices,
                      "With --levels -1: most vertices of the finest level, >= 1000 (default 300000); when the "
                      "exemplar's resolution needs more, the synthesis texel grows (the exemplar is reduced, the "
                      "scale kept)")
           ->check(CLI::Range(std::size_t(1000), std::size_t(50000000)));
       app.add_option(
              "--wrap", a->wrap,
              "auto (default): wrap the exemplar around its edges only if it tiles: its wrap-seam ratio is "
              "<= 1.3, or, where a feature runs along the wrap, its wrap lines and neighbourhoods look like "
              "its interior ones (report: wrap); periodic: always (a seamless tile, e.g. from `surftex "
              "tile`); bounded: never")
           ->check(CLI::IsMember({"auto", "periodic", "bounded"}));
       app.add_option("--repetition-penalty", a->repetition,
                      "Weight of the penalty for matching exemplar areas that nearby regions already show more "
                      "than average, >= 0 (default 0.3; 0 = off)")
           ->check(CLI::Range(0.0, 100.0));
       app.add_option("--exhaustive-levels", a->exhaustive_levels,
                      "Mesh levels from the base on that search the whole exemplar (the paper's Algorithm 1), "
                      "0..13; later levels only try the exemplar positions their neighbours' sources imply "
                      "(coherence search, far faster) and search exhaustively where none fits (default 1; 13 = "
                      "exhaustive everywhere)")
           ->check(CLI::Range(0, 13));
       app.add_option("--adaptive", a->adaptive,
                      "Adaptive subdivision threshold f (faces with area > f x mean are refined) before the "
                      "hierarchy; 0 = off (default 1.5, the paper's choice)")
           ->check(CLI::Range(0.0, 1e6));
       app.add_option("--adaptive-steps", a->adaptive_steps, "Adaptive steps when --adaptive > 0, 0..32 (default 4)")
           ->check(CLI::Range(0, 32));
       app.add_option("--displace", a->displace,
                      "Displace every vertex along its normal by H x its synthesised grey level (luminance in "
                      "[0, 1]), H in object units (longest bounding-box side = 1), in [-1, 1]; 0 = off (default 0)")
           ->check(CLI::Range(-1.0, 1.0));
       app.add_option("--passes", a->passes, "Synthesis passes per level (fill passes not counted), 1..16 (default 1)")
           ->check(CLI::Range(1, 16));
       app.add_option("--region", a->region, "Neighbourhood size n in texels (n x n), > 0 (default 9; the paper's Table 1 uses 3, too small for structured textures)")
           ->check(CLI::Range(0.5, 64.0));
       app.add_option("--sigma", a->sigma, "sigma of the graph-cut edge weight (equation 1), > 0 (default 1)")
           ->check(CLI::Range(1e-3, 1e3));
       app.add_option("--atlas-size", a->atlas,
                      "Baked atlas width = height in pixels, 64..8192, or 0 (default) = from the synthesised "
                      "vertices: 1024 up to 157K, 2048 up to 629K, else 4096 (about a texel per vertex); charts "
                      "keep a gutter of size/64 texels so every mip level down to 64 px is free of bleeding")
           ->check(zero_or_range(64, 8192, "from the vertices"));
       app.add_option("--bump", a->bump,
                      "Normal-map strength (surface_atlas_normal.png, from the height = luminance or "
                      "--exemplar-height): tilt per unit height slope, height per exemplar texel, 0..100 (default 2)")
           ->check(CLI::Range(0.0, 100.0));
       app.add_option("--exemplar-normal", a->exemplar_normal,
                      "Tangent-space normal map of the exemplar (RGB = (n+1)/2, x right, +Y up, the exemplar's "
                      "size): read at every vertex where its colour was read, turned onto the surface as the "
                      "exemplar was laid there, into surface_atlas_normal.png in the GLB's tangent frames "
                      "(default: from the height)");
       app.add_option("--exemplar-height", a->exemplar_height,
                      "Height map of the exemplar (grey, or RGB luminance; the exemplar's size): read where the "
                      "colour was into surface_atlas_height.png, and the normal map from it unless "
                      "--exemplar-normal (default: the luminance of the synthesised colour)");
       app.add_option("--exemplar-roughness", a->exemplar_roughness,
                      "Roughness map of the exemplar (grey, the exemplar's size): read where the colour was into "
                      "surface_atlas_roughness.png, the GLB's metallicRoughnessTexture (metallic 0) and the MTL's "
                      "map_Pr (default: none)");
       app.add_flag("--pyramid", a->pyramid, "Match against a Gaussian pyramid instead of the stack (faster, coarser)");
       app.add_flag("--fixed-region", a->fixed_region,
                    "Region size n in level-0 texels at every level (the paper's a = 1 for a stack); default: n "
                    "texels of each vertex's stack level, so coarse levels match n x n vertices, not 1-rings");
       app.add_flag("--no-antialias", a->no_antialias, "Do not pick the stack level per vertex (section 3.3.4)");
       app.add_flag("--no-averaging", a->no_averaging, "Compare every vertex, not per-texel averages (section 3.3.3)");
       app.add_flag("--no-cut", a->no_cut, "Colour only the matched vertex (no graph-cut transfer, section 3.4)");
       app.add_flag("--projection", a->projection, "Local (u,v) by tangent-plane projection instead of unfolding");
       add_common_options(app, a->common);
       return [a] { return run_subdiv(*a); };
     }}};

DemoStepRegistrar demo_subdiv{{50, "subdiv",
                               "subdivision graph matching: a cube, sqrt(2) hierarchy, cells exemplar (PLY, GLB, atlas, render)",
                               [](DemoContext& ctx) -> nlohmann::json {
                                 Mesh mesh;
                                 make_cube(mesh, 1.0);
                                 const Image ex = make_cells(64, 4, ctx.seed);
                                 write_image(ctx.path("subdiv_exemplar.png"), ex);
                                 const auto r = demo_run(mesh, ex, ctx.seed, ctx.progress);
                                 const std::string dir = ctx.path("subdiv");
                                 ensure_directory(dir);
                                 nlohmann::json j = to_json(r, {});
                                 SubdivisionAssetOptions ao;
                                 ao.atlas_size = 512;
                                 ao.texels_per_length = 64 / r.object_unit;  // demo_run's r_scale
                                 SubdivisionVertexMaps vm;
                                 vm.between = subdivision_surface_sources(mesh, r, {}, ex.width, ex.height, &ex);
                                 const SubdivisionAsset asset = bake_subdivision_asset(mesh, vm, ao);
                                 nlohmann::json written = write_outputs(mesh, asset, output_paths(dir), true);
                                 // Report keys as the CLI's (issue 16 item 7): names under the demo folder.
                                 for (const auto& f : written["files"])
                                   j["outputs"].push_back(fs::relative(f.get<std::string>(), ctx.dir).string());
                                 written.erase("files");
                                 j["export"] = written;
                                 return j;
                               }}};

}  // namespace subdiv_command
}  // namespace
}  // namespace surftex::cli
