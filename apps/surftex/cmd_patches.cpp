// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex patches`: patch-based oriented surface texture synthesis (Gorla,
// Interrante & Sapiro 2003): partition, flatten, two-pass Efros-Leung per
// patch following a direction field; writes an atlas, OBJ+MTL, GLB, a render
// and a report with timings and the on-surface seam figure.
#include <CLI/CLI.hpp>
#include <tbb/parallel_invoke.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "geometry/render_view.h"
#include "geometry/timer.h"
#include "geometry/up_axis.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"
#include "surftex/demo_steps.h"
#include "texture/image_ops.h"
#include "texture/patches/patch_texture.h"
#include "texture/procedural_texture.h"

namespace fs = std::filesystem;

namespace surftex::cli {
namespace {
namespace patches_command {  // named: the unity build joins these files

struct PatchArgs {
  std::string exemplar_normal, exemplar_height, exemplar_roughness;
  std::string mesh, exemplar, outdir, field = "up", order = "random", resynth, exemplar2,
                                     multi = "none", fill = "onion", search = "approximate";
  int patch_res = 128, max_faces = 200, window = 11, preselect = 0, rotations = 64,
      exemplar_size = 0;
  double max_angle = 30.0, bump = 2.0, coherence = ElOptions{}.coherence;
  double min_widths = PatchSynthesisOptions{}.min_exemplar_widths;
  bool patch_res_given = false;  ///< --patch-res on the command line: refused, not lowered, when the atlas cannot hold it
  CommonOptions common;
};

// Exemplars as RGB (grey replicated, alpha dropped), optionally resized so
// that the longer side is `size`.
Image sized_rgb(const Image& in, int size) {
  Image img = in;
  if (size > 0 && std::max(img.width, img.height) != size) {
    const double s = static_cast<double>(size) / std::max(img.width, img.height);
    img = resize_bilinear(img, std::max(1, static_cast<int>(std::lround(img.width * s))),
                          std::max(1, static_cast<int>(std::lround(img.height * s))));
  }
  return as_rgb(img);
}

std::vector<int> parse_ids(const std::string& s) {
  std::vector<int> ids;
  std::stringstream ss(s);
  std::string tok;
  while (std::getline(ss, tok, ',')) {
    if (tok.empty()) continue;
    std::size_t used = 0;
    int v = -1;
    try {
      v = std::stoi(tok, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != tok.size() || v < 0)
      throw InvalidInputError("--resynth '" + s + "': '" + tok + "' is not a patch id >= 0");
    ids.push_back(v);
  }
  return ids;
}

PatchField parse_field(const std::string& f) {
  if (f == "up") return PatchField::Constant;
  if (f == "kmax") return PatchField::Kmax;
  if (f == "kmin") return PatchField::Kmin;
  if (f == "kmax-abs") return PatchField::KmaxAbs;
  if (f == "kmin-abs") return PatchField::KminAbs;
  if (f == "none") return PatchField::None;
  throw InvalidInputError("--field '" + f + "' is not up|kmax|kmin|kmax-abs|kmin-abs|none");
}

MultiTexture parse_multi(const std::string& m) {
  if (m == "none") return MultiTexture::None;
  if (m == "illumination") return MultiTexture::Illumination;
  if (m == "curvature") return MultiTexture::Curvature;
  if (m == "height") return MultiTexture::Height;
  throw InvalidInputError("--multi '" + m + "' is not none|illumination|curvature|height");
}

// The driver (texture/patches/patch_texture.h) and every output into `dir`;
// returns the report. The atlas (mesh.png, power of two, mip gutters) comes
// with a height map (mesh_height.png, 16-bit) and a tangent-space normal map
// (mesh_normal.png), with --exemplar-roughness mesh_roughness.png and the
// GLB's metallicRoughnessTexture; render.png shows the atlas.
nlohmann::json run_pipeline(Mesh& mesh, const std::vector<Image>& exemplars, const PatchTextureOptions& o,
                            const std::string& dir, const PatchExemplarMaps& maps = {}) {
  const PatchTextureResult r = synthesize_patch_texture(mesh, exemplars, maps, o);
  Timer tout;
  ensure_directory(dir);
  WriteMeshOptions wo;
  wo.texture = &r.atlas.image;
  wo.normal_texture = &r.normal;
  wo.height_texture = &r.height;
  wo.metallic_roughness_texture = &r.metallic_roughness;
  wo.texture_repeat = false;
  wo.write_colors = false;
  WriteMeshOptions go = wo;
  go.height_texture = nullptr;
  // The OBJ and the GLB share their encoded maps; the render beside them.
  tbb::parallel_invoke(
      [&] { write_obj_and_glb((fs::path(dir) / "mesh.obj").string(), (fs::path(dir) / "mesh.glb").string(), mesh, wo, go); },
      [&] {
        ViewOptions view;
        view.texture = &r.atlas.image;
        write_image((fs::path(dir) / "render.png").string(), render_view(mesh, view));
      });
  const double s_write = tout.seconds();
  nlohmann::json j = to_json(r);
  j["seconds"]["write"] = s_write;
  j["seconds"]["total"] = r.seconds_total + s_write;
  j["outputs"] = {"mesh.obj", "mesh.mtl", "mesh.png", "mesh_normal.png", "mesh_height.png", "mesh.glb", "render.png"};
  if (!r.metallic_roughness.empty()) j["outputs"].push_back("mesh_roughness.png");
  return j;
}

int run(const PatchArgs& a) {
  require_input_file(a.mesh, "mesh");
  require_input_file(a.exemplar, "exemplar");
  std::vector<std::string> inputs{a.mesh, a.exemplar};
  if (!a.exemplar2.empty()) {
    require_input_file(a.exemplar2, "exemplar2");
    inputs.push_back(a.exemplar2);
  }
  for (const auto& [path, what] : {std::pair{a.exemplar_normal, "--exemplar-normal"},
                                   {a.exemplar_height, "--exemplar-height"},
                                   {a.exemplar_roughness, "--exemplar-roughness"}})
    if (!path.empty()) {
      require_input_file(path, what);
      inputs.push_back(path);
      if (!a.exemplar2.empty())
        throw InvalidInputError(std::string(what) + " with --exemplar2: exemplar maps follow the first exemplar "
                                "only; multi-texturing with maps is not supported");
    }
  PatchTextureOptions to;
  to.bump = a.bump;
  PatchSynthesisOptions& po = to.synthesis;
  po.field = parse_field(a.field);
  po.multi = parse_multi(a.multi);
  if (po.multi != MultiTexture::None && a.exemplar2.empty())
    throw InvalidInputError("--multi " + a.multi + " needs --exemplar2");
  po.resynthesize = parse_ids(a.resynth);
  for (const char* name : {"mesh.obj", "mesh.mtl", "mesh.png", "mesh_normal.png", "mesh_height.png",
                           "mesh_roughness.png", "mesh.glb", "render.png", "report.json"})
    check_output((fs::path(a.outdir) / name).string(), inputs, a.common.force, false);
  auto limit = apply_thread_limit(a.common.threads);
  Mesh mesh;
  const LoadInputReport loaded = load_method_mesh(a.mesh, mesh, a.common);
  Image colour = read_image(a.exemplar);
  // Exemplar maps: the colour exemplar's size, cropped to its opaque part and
  // resized with it.
  PatchExemplarMaps maps;
  maps.normal = read_exemplar_map(a.exemplar_normal, "--exemplar-normal", a.exemplar, colour);
  maps.height = read_exemplar_map(a.exemplar_height, "--exemplar-height", a.exemplar, colour);
  maps.roughness = read_exemplar_map(a.exemplar_roughness, "--exemplar-roughness", a.exemplar, colour);
  const nlohmann::json opaque = use_opaque_part(colour, {&maps.normal, &maps.height, &maps.roughness}, a.common);
  for (Image* m : {&maps.normal, &maps.height, &maps.roughness})
    if (!m->empty()) *m = sized_rgb(*m, a.exemplar_size);
  std::vector<Image> ex{sized_rgb(colour, a.exemplar_size)};
  nlohmann::json opaque2;
  if (!a.exemplar2.empty()) {
    Image second = read_image(a.exemplar2);
    opaque2 = use_opaque_part(second, {}, a.common, "the second exemplar (--exemplar2)");
    ex.push_back(sized_rgb(second, a.exemplar_size));
  }
  po.partition.max_angle_deg = a.max_angle;
  po.partition.max_faces = a.max_faces;
  po.flatten.resolution = a.patch_res;
  po.flatten.margin = std::max(2, a.patch_res / 32);
  po.fit_resolution = !a.patch_res_given;
  po.min_exemplar_widths = a.min_widths;
  po.order = a.order == "curvature" ? PatchOrder::Curvature : PatchOrder::Random;
  po.el.window = a.window;
  po.el.preselect = a.preselect;
  po.el.coherence = a.coherence;
  po.el.rotations = a.rotations;
  po.el.search = a.search == "exhaustive" ? ElSearch::Exhaustive : ElSearch::Approximate;
  po.el.order = a.fill == "direction" ? FillOrder::Direction : FillOrder::OnionPeel;
  po.seed = a.common.seed;
  po.progress = terminal_progress(a.common.quiet);
  check_budget(estimate_patches(mesh.number_of_faces(), ex[0].width, ex[0].height, static_cast<int>(ex.size()),
                                a.patch_res, a.max_faces, a.window, a.rotations, a.search == "exhaustive",
                                a.patch_res_given ? 0.0 : a.min_widths),
               a.common);
  nlohmann::json rep = run_pipeline(mesh, ex, to, a.outdir, maps);
  if (rep.contains("patch_resolution_raised_from") && !a.common.quiet)
    std::fprintf(stderr, "note: %d texels a side showed %.2f exemplar widths across the mesh's longest side: raised "
                         "to %d for at least %g (--min-widths; --patch-res to choose)\n",
                 a.patch_res, rep["exemplar_widths"]["at_patch_resolution"].get<double>(),
                 rep.value("patch_resolution_requested", rep["patch_resolution"].get<int>()), a.min_widths);
  if (rep.contains("patch_resolution_requested") && !a.common.quiet)
    std::fprintf(stderr, "note: %d patches at %d texels a side do not fit one %d px atlas: %d texels a side used "
                         "(--patch-res to choose; --max-patch-faces for fewer, larger patches)\n",
                 rep["patches"].get<int>(), rep["patch_resolution_requested"].get<int>(), po.atlas.max_size,
                 rep["patch_resolution"].get<int>());
  rep["mesh"] = a.mesh;
  rep["input_mesh"] = to_json(loaded);
  rep["exemplar"] = a.exemplar;
  if (!opaque.is_null()) rep["exemplar_transparency"] = opaque;
  if (!opaque2.is_null()) rep["exemplar2_transparency"] = opaque2;
  rep["field"] = a.field;
  rep["order"] = a.order;
  rep["fill"] = a.fill;
  rep["search"] = a.search;
  rep["multi"] = a.multi;
  rep["resynthesized"] = po.resynthesize;
  rep["faces"] = mesh.number_of_faces();
  RunFiles files{inputs, {}};
  for (const auto& name : rep["outputs"]) files.outputs.push_back((fs::path(a.outdir) / name.get<std::string>()).string());
  rep.erase("outputs");  // a shared report key (surftex/report.h): paths, not names
  write_file_atomic((fs::path(a.outdir) / "report.json").string(),
                    make_report(a.common, "patches", rep, files).dump(2) + "\n", true);
  write_report(a.common, "patches", rep, files);
  if (!a.common.quiet)
    std::printf("%s: %d patches at %d texels a side (%.2f exemplar widths across), %zu texels in %.2f s (%.0f "
                "texels/s), seam ratio %.3f\n",
                a.outdir.c_str(), rep["patches"].get<int>(), rep["patch_resolution"].get<int>(),
                rep["exemplar_widths"]["across_longest_side"].get<double>(),
                rep["texels_synthesized"].get<std::size_t>(), rep["seconds"]["synthesis"].get<double>(),
                rep["texels_per_second"].get<double>(), rep["seam"]["ratio"].get<double>());
  return 0;
}

SubcommandRegistrar reg{
    {"patches",
     "Patch-based oriented texture synthesis on a mesh (Gorla, Interrante & Sapiro 2003)",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<PatchArgs>();
       app.add_option("MESH", a->mesh, "Input mesh (OFF/OBJ/PLY/STL)")->required();
       app.add_option("EXEMPLAR", a->exemplar, "Exemplar image (grey or colour). With transparent pixels (a hole, "
                      "a cut-out) its largest opaque block is used when that holds a quarter of it (the atlas has no alpha)")->required();
       app.add_option("-o,--output", a->outdir,
                      "Output folder: mesh.obj/.mtl with mesh.png (the atlas: power of two, mip gutters), "
                      "mesh_normal.png (tangent-space, +Y up), mesh_height.png (16-bit), mesh.glb (base colour "
                      "and normal texture), render.png, report.json")
           ->required();
       app.add_option("--field", a->field,
                      "Texture orientation. up: the exemplar stands upright, its top edge towards +y projected on "
                      "the surface, its rows horizontal (a photograph of a wall keeps its bricks in rows); on flat "
                      "faces facing +y or -y (floors, a part's top) its top edge points to -z, rows parallel; "
                      "kmax|kmin (greatest/least signed normal curvature), kmax-abs|kmin-abs (greatest/least "
                      "absolute curvature): the exemplar's +x (its rows) follows that principal direction (Gorla "
                      "2003, Fig. 11); none: no orientation, for isotropic textures (default up)")
           ->check(CLI::IsMember({"up", "kmax", "kmin", "kmax-abs", "kmin-abs", "none"}));
       app.add_option("--patch-res", a->patch_res,
                      "Texels per patch side, 16..1024: with the largest patch's extent it sets the texture's "
                      "scale (default 128, raised when that would show fewer than --min-widths exemplar widths "
                      "across the mesh, lowered by eighths when the patches would not fit one 4096 px atlas; "
                      "given: kept as given, refused before any synthesis when the atlas cannot hold it)")
           ->check(CLI::Range(16, 1024))
           ->each([a](const std::string&) { a->patch_res_given = true; });
       app.add_option("--min-widths", a->min_widths,
                      "Texture scale floor: when the patch resolution would show fewer than this many exemplar "
                      "widths across the mesh's longest bounding-box side (a large exemplar on a small or coarse "
                      "mesh: every texel magnified), the resolution is raised until it shows them, as far as one "
                      "4096 px atlas holds; 0..1000, 0 = off; not with --patch-res (default 1)")
           ->check(CLI::Range(0.0, 1000.0));
       app.add_option("--max-angle", a->max_angle,
                      "Largest angle between a triangle normal and its patch's reference normal, "
                      "degrees, 1..89 (default 30)")
           ->check(CLI::Range(1.0, 89.0));
       app.add_option("--max-patch-faces", a->max_faces,
                      "Most triangles per patch (also sets the patch size), 1..100000 (default 200)")
           ->check(CLI::Range(1, 100000));
       app.add_option("--order", a->order,
                      "Patch order: random (seeded, connected) or curvature (greatest principal "
                      "curvature difference first) (default random)")
           ->check(CLI::IsMember({"random", "curvature"}));
       app.add_option("--fill", a->fill,
                      "Pixel order inside a patch: onion (most constrained first) or direction "
                      "(sweep along the field) (default onion)")
           ->check(CLI::IsMember({"onion", "direction"}));
       app.add_option("--resynth", a->resynth,
                      "Comma-separated patch ids to re-synthesise after the main pass, keeping the "
                      "others as boundary (default none)");
       app.add_option("--exemplar2", a->exemplar2, "Second exemplar for multi-texturing");
       app.add_option("--exemplar-normal", a->exemplar_normal,
                      "Tangent-space normal map of the exemplar (RGB = (n+1)/2, +Y up, the exemplar's size): "
                      "resampled through the same synthesis into mesh_normal.png (default: from the height)");
       app.add_option("--exemplar-height", a->exemplar_height,
                      "Height map of the exemplar (grey, the exemplar's size): resampled into mesh_height.png "
                      "(default: the luminance of the synthesised colour)");
       app.add_option("--exemplar-roughness", a->exemplar_roughness,
                      "Roughness map of the exemplar (grey, the exemplar's size): resampled into "
                      "mesh_roughness.png, the GLB's metallicRoughnessTexture (metallic 0) and the MTL's map_Pr");
       app.add_option("--bump", a->bump,
                      "Normal-map strength (mesh_normal.png, from the height = luminance): tilt per unit "
                      "height slope, height per exemplar texel, 0..100 (default 2)")
           ->check(CLI::Range(0.0, 100.0));
       app.add_option("--multi", a->multi,
                      "Multi-texturing index function: none, illumination (Lambert with a fixed "
                      "light), curvature (mean curvature) or height (along +y); needs --exemplar2 "
                      "(default none)")
           ->check(CLI::IsMember({"none", "illumination", "curvature", "height"}));
       app.add_option("--window", a->window, "Efros-Leung window, 3..51 (default 11)")
           ->check(CLI::Range(3, 51));
       app.add_option("--coherence", a->coherence,
                      "Continue a neighbour's source region when its error is within (1 + this) of the best "
                      "match, so that bricks and tiles come out whole; 0 = Gorla's random pick among the best "
                      "(default 5)")
           ->check(CLI::Range(0.0, 100.0));
       app.add_option("--preselect", a->preselect,
                      "First-pass candidates kept, >= 0; 0 = exemplar width (one scanline) (default 0)")
           ->check(CLI::NonNegativeNumber);
       app.add_option("--rotations", a->rotations, "Pre-rotated exemplars, 1..128 (default 64)")
           ->check(CLI::Range(1, 128));
       app.add_option("--search", a->search,
                      "First-pass search: approximate (coherent and kd-tree candidates, cost independent "
                      "of the exemplar size) or exhaustive (every exemplar position, Gorla 2003 as "
                      "published; slow on large exemplars) (default approximate)")
           ->check(CLI::IsMember({"approximate", "exhaustive"}));
       app.add_option("--exemplar-size", a->exemplar_size,
                      "Resize exemplars so the longer side is this many pixels, 0 = as is, "
                      "16..1024 (default 0)")
           ->check(CLI::Range(0, 1024));
       add_common_options(app, a->common);
       return [a] { return run(*a); };
     }}};

// Demo: a torus with a generated stripe exemplar following kmax, patch-res 48.
DemoStepRegistrar demo{{30, "patches",
                        "patch-based oriented synthesis (Gorla 2003) on a torus, stripes along kmax",
                        [](DemoContext& ctx) {
                          Mesh mesh;
                          make_torus(mesh, 1.0, 0.4, 48, 24);
                          z_up_to_y_up(mesh);  // lying flat in glTF viewers
                          const Image ex = make_stripes(48, 8, 0);
                          write_image(ctx.path("patches_exemplar.png"), ex);
                          PatchTextureOptions to;  // bump 2
                          PatchSynthesisOptions& po = to.synthesis;
                          po.field = PatchField::Kmax;
                          po.flatten.resolution = 48;
                          po.flatten.margin = 3;
                          po.partition.max_faces = 60;
                          po.el.window = 9;
                          po.el.rotations = 32;
                          po.seed = ctx.seed;
                          nlohmann::json j = run_pipeline(mesh, {ex}, to, ctx.path("patches"));
                          write_file_atomic(ctx.path("patches/report.json"), j.dump(2) + "\n", true);
                          for (auto& name : j["outputs"]) name = "patches/" + name.get<std::string>();  // under the demo folder
                          return j;
                        }}};

}  // namespace patches_command
}  // namespace
}  // namespace surftex::cli
