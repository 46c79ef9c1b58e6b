// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex quilt`: mesh quilting of a swatch over a base mesh (Zhou et al.
// 2006, section 3: surface quilting, shell-map embedding) or a plane (section
// 2); `surftex elements`: edit the elements of a result by id; the demo step
// "quilt".

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "geometry/render_view.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "shell/element_colors.h"
#include "shell/quilting/edit_elements.h"
#include "shell/quilting/quilt_driver.h"
#include "shell/quilting/quilt_json.h"
#include "shell/swatch_generators.h"
#include "surftex/command.h"
#include "surftex/demo_steps.h"

namespace surftex::cli {
namespace {
namespace quilt_command {  // named: the unity build joins these files

struct QuiltArgs {
  std::string base, swatch, output, plane, render, field = "up", swatch_up = "auto", fill_smaller = "0.7,0.5,0.35";
  bool no_render = false, no_check = false, no_align = false, smooth_field = false;
  double scale = 0, cell = 0, shell_height = 1.0, max_turn = 15.0, align_bound = 45.0, split_edges = 2.5;
  std::vector<double> up{0, 1, 0};
  int subpatch = 0, stretch_iterations = 20, thread_pieces = 4;
  CommonOptions common;
};

// --fill-smaller: "none" or up to 8 comma-separated factors, each in (0, 1).
std::vector<double> parse_fill_smaller(const std::string& text) {
  std::vector<double> out;
  if (text == "none") return out;
  auto bad = [&text](const std::string& why) {
    return InvalidInputError("quilt: --fill-smaller must be none or comma-separated factors in (0, 1), e.g. "
                             "0.7,0.5 (got '" + text + "': " + why + ")");
  };
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    char* end = nullptr;
    const double f = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size()) throw bad("'" + item + "' is not a number");
    if (!(f > 0 && f < 1)) throw bad(item + " is not in (0, 1)");
    out.push_back(f);
    start = comma + 1;
  }
  if (out.size() > 8) throw bad("more than 8 factors");
  return out;
}

SwatchAxis swatch_axis(const std::string& s) {
  return s == "x" ? SwatchAxis::kX : s == "y" ? SwatchAxis::kY : s == "z" ? SwatchAxis::kZ : SwatchAxis::kAuto;
}

std::string sibling(const std::string& out, const std::string& ext) {
  const auto dot = out.find_last_of('.');
  const auto slash = out.find_last_of('/');
  const std::string stem = (dot == std::string::npos || (slash != std::string::npos && dot < slash)) ? out : out.substr(0, dot);
  return stem + ext;
}

std::string lower_ext(const std::string& path) {
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos) return "";
  std::string e = path.substr(dot);
  for (char& ch : e) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return e;
}

// The inputs of a run (the swatch file unless generated, the base mesh),
// after checking the arguments that need no file read. With --plane the
// positional arguments are just the swatch.
std::vector<std::string> check_quilt_args(QuiltArgs& a) {
  if (!a.plane.empty() && !a.base.empty() && a.swatch.empty()) std::swap(a.base, a.swatch);
  if (!a.plane.empty() && !a.base.empty())
    throw InvalidInputError("quilt: give either a base MESH or --plane WxH, not both");
  if (a.plane.empty() && a.base.empty()) throw InvalidInputError("quilt: missing MESH (or --plane WxH)");
  if (a.swatch.empty()) throw InvalidInputError("quilt: missing SWATCH (a mesh file or chainmail|weave|scatter|tori)");
  if (!is_generated_swatch(a.swatch)) require_input_file(a.swatch, "swatch");
  std::vector<std::string> inputs;
  if (!is_generated_swatch(a.swatch)) inputs.push_back(a.swatch);
  if (!a.base.empty()) {
    require_input_file(a.base, "base mesh");
    inputs.push_back(a.base);
  }
  if (a.field != "up" && a.field != "none")
    throw InvalidInputError("quilt: --field must be up or none (got '" + a.field + "')");
  if (a.up.size() != 3 || !(a.up[0] * a.up[0] + a.up[1] * a.up[1] + a.up[2] * a.up[2] > 0))
    throw InvalidInputError("quilt: --up must be three numbers, not all zero");
  parse_fill_smaller(a.fill_smaller);  // (checked before any output)
  return inputs;
}

// The output files: OUT, its .ply and .glb siblings (mesh mode), the render
// (last, when there is one); each checked against the inputs and the others.
std::vector<std::string> quilt_outputs(QuiltArgs& a, const std::vector<std::string>& inputs) {
  const std::string ext = lower_ext(a.output);
  if (ext != ".obj" && ext != ".ply" && ext != ".off" && ext != ".glb")
    throw InvalidInputError("quilt: unknown output format '" + a.output + "' (use .obj, .ply, .off, .glb)");
  std::vector<std::string> outputs{a.output};
  if (!a.base.empty())
    for (const std::string& e : {std::string(".ply"), std::string(".glb")})
      if (ext != e) outputs.push_back(sibling(a.output, e));
  if (a.render.empty() && !a.no_render) a.render = sibling(a.output, "_render.png");
  if (!a.render.empty()) outputs.push_back(a.render);
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    std::vector<std::string> others = inputs;
    others.insert(others.end(), outputs.begin(), outputs.begin() + static_cast<long>(i));
    check_output(outputs[i], others, a.common.force);
  }
  return outputs;
}

// --plane WxH in swatch sizes; {0, 0} without --plane.
std::pair<double, double> parse_plane(const std::string& plane) {
  double w = 0, h = 0;
  if (plane.empty()) return {w, h};
  char x = 0;
  std::istringstream is(plane);
  if (!(is >> w >> x >> h) || (x != 'x' && x != 'X') || !(w > 0) || !(h > 0) || !std::isfinite(w) ||
      !std::isfinite(h) || !(is >> std::ws).eof())
    throw InvalidInputError("quilt: --plane must be WxH with positive numbers in swatch sizes (got '" +
                            plane + "')");
  return {w, h};
}

// Planar mesh quilting (section 2) of the swatch over w x h swatch sizes
// into `out`; its figures into the report.
void quilt_on_plane(const QuiltArgs& a, const Mesh& sm, double w, double h, Mesh& out, nlohmann::json& rep) {
  // --scale: factor applied to the swatch (the paper's s); the plane is in swatch sizes.
  QuiltSwatchOnPlaneOptions o;
  o.scale = a.scale > 0 ? a.scale : 1.0;
  o.swatch_up = swatch_axis(a.swatch_up);
  o.quilt.cell_size = a.cell * o.scale;
  o.quilt.subpatch_radius = a.subpatch;
  o.quilt.progress = terminal_progress(a.common.quiet);
  o.seed = a.common.seed;
  o.plane_name = a.plane;
  o.check_work = [&a](const WorkEstimate& e) { check_budget(e, a.common); };
  rep.update(to_json(quilt_swatch_on_plane(sm, w, h, out, o)));
}

// The options of quilt_swatch_on_surface from the command line.
QuiltSwatchOnSurfaceOptions surface_quilt_options(const QuiltArgs& a) {
  QuiltSwatchOnSurfaceOptions d;
  d.swatch_up = swatch_axis(a.swatch_up);
  SurfaceQuiltOptions& o = d.quilt;
  o.relative_size = a.scale;  // (0: the swatch's default, default_surface_quilt_size)
  o.field = a.field == "up" ? SurfaceQuiltOptions::Field::kUp : SurfaceQuiltOptions::Field::kNone;
  o.up = {a.up[0], a.up[1], a.up[2]};
  o.cell_size = a.cell;
  o.subpatch_radius = a.subpatch;
  o.rotation_max_deg = a.max_turn;
  o.align_to_overlap = !a.no_align;
  o.align_field_max_deg = a.align_bound;
  o.smooth_field = a.smooth_field;
  o.scatter_thread_parts = a.thread_pieces;
  o.progress = terminal_progress(a.common.quiet);
  d.split_edges_over_median = a.split_edges;
  d.fill_smaller = parse_fill_smaller(a.fill_smaller);
  d.embed.shell_height = a.shell_height;
  d.embed.stretch.iterations = a.stretch_iterations;
  d.embed.check_self_intersections = !a.no_check;
  d.embed.progress = o.progress;
  d.seed = a.common.seed;
  d.mesh_name = a.base;
  d.swatch_name = "the swatch '" + a.swatch + "'";
  d.check_work = [&a](const WorkEstimate& e) { check_budget(e, a.common); };
  return d;
}

// Surface mesh quilting (section 3) of the swatch over the base mesh into
// `out`; `scene` is the base with `out` joined (for the render). Its figures
// into the report.
void quilt_on_mesh(const QuiltArgs& a, const Mesh& sm, Mesh& out, Mesh& scene, nlohmann::json& rep) {
  Timer t;
  Mesh base;
  rep["input_mesh"] = to_json(load_method_mesh(a.base, base, a.common));
  base.collect_garbage();
  const double read_seconds = t.seconds();
  rep.update(to_json(quilt_swatch_on_surface(base, sm, out, surface_quilt_options(a))));
  rep["mesh"] = a.base;
  rep["seconds"]["read"] = read_seconds;
  surface_quilt_scene(base, out, scene);
}

// The quilt into every mesh output, and the render of `scene` when asked.
void write_quilt_outputs(const QuiltArgs& a, const std::vector<std::string>& outputs, const Mesh& out,
                         const Mesh& scene, nlohmann::json& rep) {
  WriteMeshOptions wo;
  wo.overwrite = a.common.force;
  wo.write_uvs = false;
  for (std::size_t i = 0; i + (a.render.empty() ? 0 : 1) < outputs.size(); ++i)
    write_mesh(outputs[i], out, wo);
  if (a.render.empty()) return;
  WriteImageOptions io;
  io.overwrite = a.common.force;
  // The render stands the mesh on the axis nearest --up (+Y by default, as
  // glTF viewers do); a plane lies in xy and is seen from above (+Z).
  ViewOptions vo;
  vo.size = 800;
  vo.elevation_deg = 35.f;
  const bool y_up = a.plane.empty() && std::abs(a.up[1]) >= std::abs(a.up[2]);
  vo.up = y_up ? ViewOptions::Up::Y : ViewOptions::Up::Z;
  write_image(a.render, render_view(scene, vo), io);
  rep["render"] = a.render;
}

std::string format_percent(double fraction) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f%%", 100 * fraction);
  return buf;
}

// The summary lines on stderr (unless --quiet).
// Over 4% of a height band bare (issue 17's goal): parts thinner than the
// elements, which stay whole, are left bare; a smaller --scale is the remedy.
void print_thin_parts_note(const nlohmann::json& rep) {
  if (!rep.contains("bare_by_height") || !rep.contains("scale")) return;
  static const char* kBand[4] = {"lowest", "second", "third", "highest"};
  const std::vector<double> bands = rep["bare_by_height"].get<std::vector<double>>();
  std::size_t worst = 0;
  for (std::size_t b = 1; b < bands.size() && b < 4; ++b)
    if (bands[b] > bands[worst]) worst = b;
  if (bands.empty() || !(bands[worst] > 0.04)) return;
  std::fprintf(stderr,
               "note: %s of the %s quarter of the mesh's height (along --up) is bare: parts thinner than the "
               "swatch's elements (at --scale %g, and the smaller copies of --fill-smaller) are not covered, as "
               "elements stay whole; a smaller --scale places smaller elements there\n",
               format_percent(bands[worst]).c_str(), kBand[worst], rep["scale"].get<double>());
}

void print_quilt_summary(const QuiltArgs& a, const nlohmann::json& rep, const Mesh& out, double seconds) {
  if (a.common.quiet) return;
  std::string elements = std::to_string(rep["elements"].get<int>()) + " elements";
  if (rep.contains("elements_embedded") && rep["elements_embedded"] != rep["elements"])
    elements = rep["elements_embedded"].dump() + " elements (" + std::to_string(rep["elements"].get<int>()) +
               (rep.value("scatter_only", false) ? " placed" : " quilted") +
               "; the embedding removed or cut those that crossed or stretched)";
  if (rep.value("scatter_only", false)) elements += ", whole copies of the swatch's few elements";
  if (rep.contains("bare_fraction") && rep.contains("base_faces"))
    elements += ", " + format_percent(rep["bare_fraction"].get<double>()) + " of the surface bare";
  std::fprintf(stderr, "quilt: %s, %zu faces (%.1f s) -> %s\n", elements.c_str(),
               static_cast<std::size_t>(out.number_of_faces()), seconds, a.output.c_str());
  print_thin_parts_note(rep);
  if (!rep.contains("stretch_before")) return;
  const auto& si = rep["self_intersections"];
  std::string what = "not checked (--no-check)";
  if (!si.is_null())
    what = si.dump() + " intersecting face pairs (" + rep["self_intersections_within_elements"].dump() +
           " within elements, " + rep["self_intersections_between_elements"].dump() + " between)";
  if (rep.value("elements_self_crossing_kept", 0) > 0)
    what += ", of which the swatch's own crossings in " + rep["elements_self_crossing_kept"].dump() + " elements";
  std::fprintf(stderr, "quilt: stretch %.4f -> %.4f, self-intersections %s\n",
               rep["stretch_before"].get<double>(), rep["stretch_after"].get<double>(), what.c_str());
}

int run_quilt(QuiltArgs& a) {
  const std::vector<std::string> inputs = check_quilt_args(a);
  const std::vector<std::string> outputs = quilt_outputs(a, inputs);
  const auto [w, h] = parse_plane(a.plane);
  auto limit = apply_thread_limit(a.common.threads);
  Timer total;
  Timer t;
  Mesh sm = load_or_generate_swatch(a.swatch, a.common.seed);
  const double swatch_seconds = t.seconds();
  nlohmann::json rep;
  rep["swatch"] = a.swatch;
  rep["output"] = a.output;
  Mesh out, scene;
  if (!a.plane.empty()) {
    quilt_on_plane(a, sm, w, h, out, rep);
    scene = out;
  } else {
    quilt_on_mesh(a, sm, out, scene, rep);
  }
  rep["seconds"]["swatch"] = swatch_seconds;
  t.reset();
  write_quilt_outputs(a, outputs, out, scene, rep);
  rep["seconds"]["write"] = t.seconds();
  write_report(a.common, "quilt", rep, {inputs, outputs});
  print_quilt_summary(a, rep, out, total.seconds());
  return 0;
}

SubcommandRegistrar reg_quilt{
    {"quilt", "Mesh quilting: grow a geometric texture from a mesh swatch over a base mesh or a plane",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<QuiltArgs>();
       app.add_option("mesh", a->base, "Base mesh (OFF/OBJ/PLY/STL) or, with --plane, the swatch");
       app.add_option("swatch", a->swatch,
                      "Swatch: a mesh file (elements = connected components, those passing through each other "
                      "joined; its thin axis, see --swatch-up, becomes the height over the surface; a swatch of "
                      "at most 3 compact elements is scattered as whole copies, not quilted) or chainmail, weave, scatter or tori to generate one "
                      "(seeded by --seed)");
       app.add_option("--swatch-up", a->swatch_up,
                      "The swatch's thin axis, which stands on the surface normal: auto (the axis of the smallest "
                      "bounding-box extent, z on ties), x, y or z (default auto)")
           ->check(CLI::IsMember({"auto", "x", "y", "z"}));
       app.add_option("--plane", a->plane, "Quilt over a plane of W x H swatch sizes, e.g. 4x4, instead of a mesh (runs that would build more than 5e7 faces, here or on a mesh, are refused)");
       app.add_option("-o,--output", a->output,
                      "Output mesh; format by extension: .obj, .ply (binary), .off, .glb; element colours as vertex "
                      "colours. On a base mesh the .ply and .glb siblings (same stem) are written too")
           ->required();
       app.add_option("--render", a->render, "Render PNG (default: <output stem>_render.png)");
       app.add_flag("--no-render", a->no_render, "Do not write a render");
       app.add_option("--scale", a->scale,
                      "The paper's s. On a mesh: the swatch's larger side as a fraction of the base mesh's "
                      "bounding-box diagonal, (0, 10]; 0 = 0.25, or less: for a swatch of few large compact "
                      "elements (a single pebble) so that one element is at most 1/16 of the diagonal wide; for tall "
                      "elements (a pebble, standing chain-mail rings) so that the median one is at most 1/32 of it "
                      "tall (a tall element splays over curved ground); and for threads (a weave) so that the "
                      "longest is at most 1/8 of the diagonal long (a longer one is cut where the surface curves). On a "
                      "plane: factor applied to the swatch, 0 = 1 (default 0)")
           ->check(number_above(0, false));
       app.add_option("--field", a->field,
                      "Guidance field aligning the swatch's +y on a mesh: up (the projected --up vector) or none "
                      "(each patch's own flattening) (default up)")
           ->check(CLI::IsMember({"up", "none"}));
       app.add_option("--up", a->up,
                      "The up vector of --field up in the mesh's own coordinates, three numbers; the swatch's +y "
                      "follows its projection on the surface (default 0 1 0: the mesh's +Y, glTF's up axis)")
           ->expected(3);
       app.add_option("--shell-height", a->shell_height,
                      "Shell thickness in scaled swatch heights, > 0 (default 1); clamped locally where the "
                      "shell would fold")
           ->check(number_above(0, true));
       app.add_option("--split-edges", a->split_edges,
                      "Split the swatch's edges longer than this many of its median edges before quilting, so "
                      "that the shell map bends them with the surface (a CAD part's long flat edges); 0 = never, "
                      "else 1.5..1e6 (default 2.5)")
           ->check(zero_or_between(1.5, 1e6, "never"));
       app.add_option("--thread-pieces", a->thread_pieces,
                      "On a mesh, what stays bare after the quilting, and again after the embedding (threads "
                      "the shell map folds over a sharp rim are cut there), is filled: with whole copies of the "
                      "swatch's compact elements (rings, tubes, pebbles; rigid, resting on the surface), or for a "
                      "swatch with none (a weave) with pieces of its threads, each thread cut into this many; "
                      "0 = no pieces (0..16, default 4)")
           ->check(CLI::Range(0, 16));
       app.add_option("--fill-smaller", a->fill_smaller,
                      "On a mesh, where a whole copy of a compact element (ring, tube, pebble) rests nowhere in "
                      "what stays bare (a leg or a horn narrower than the element, a rim), smaller copies are tried: "
                      "these factors of its size in turn, comma-separated, each in (0, 1), at most 8; none = the "
                      "full size only (default 0.7,0.5,0.35)");
       app.add_option("--stretch-iterations", a->stretch_iterations,
                      "Sweeps of the shell-map stretch minimisation, 0..1000 (default 20)")
           ->check(CLI::Range(0, 1000));
       app.add_flag("--no-check", a->no_check, "Skip the exact self-intersection count of the embedded result");
       app.add_option("--cell", a->cell, "Grid cell size in swatch units; 0 = swatch extent / 10; at most 200 cells across the swatch (default 0)")
           ->check(number_above(0, false));
       app.add_option("--subpatch", a->subpatch, "Output sub-patch half-size in cells; 0 = automatic (0..100, default 0)")
           ->check(CLI::Range(0, 100));
       app.add_option("--max-turn", a->max_turn,
                      "On a mesh: largest turn of a placement away from the field's direction, in degrees, "
                      "searched in steps of 5 so that the swatch lines up with the texture already placed; "
                      "0 = translations only; patches aligned to the threads already placed (see --no-align) "
                      "are not turned (0..90, default 15)")
           ->check(CLI::Range(0.0, 90.0));
       app.add_flag("--no-align", a->no_align,
                    "On a mesh: orient each patch by the guidance field at its seed only, not by the threads "
                    "already placed over the whole overlap (default: aligned to the overlap where there is one)");
       app.add_option("--align-bound", a->align_bound,
                      "On a mesh: largest turn of an aligned patch away from the field at its seed, in degrees; "
                      "45 = unbounded (0..45, default 45)")
           ->check(CLI::Range(0.0, 45.0));
       app.add_flag("--smooth-field", a->smooth_field,
                    "On a mesh with --field up: guide by a smooth 4-symmetric field interpolated from the projected "
                    "up vector (no poles) instead of the projected vector itself (default: off)");
       add_common_options(app, a->common);
       return [a] { return run_quilt(*a); };
     }}};

struct ElementsArgs {
  std::string input, output;
  std::vector<std::string> recolor;
  std::vector<int> remove;
  CommonOptions common;
};

int run_elements(const ElementsArgs& a) {
  require_input_file(a.input, "input mesh");
  check_output(a.output, {a.input}, a.common.force);
  Mesh m;
  read_mesh(a.input, m);
  EditElementsOptions o;
  o.recolor = a.recolor;
  o.remove = a.remove;
  o.seed = a.common.seed;
  const EditElementsResult r = edit_elements(m, o);
  WriteMeshOptions wo;
  wo.overwrite = a.common.force;
  write_mesh(a.output, m, wo);
  nlohmann::json rep = to_json(r);
  rep["input"] = a.input;
  rep["output"] = a.output;
  write_report(a.common, "elements", rep, {{a.input}, {a.output}});
  if (!a.common.quiet)
    std::fprintf(stderr, "elements: %d elements, %zu faces removed -> %s\n", r.elements, r.faces_removed, a.output.c_str());
  return 0;
}

SubcommandRegistrar reg_elements{
    {"elements", "Edit geometric-texture elements (connected components) by id: recolour or remove",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<ElementsArgs>();
       app.add_option("input", a->input,
                      "Input mesh; element ids = connected components numbered in order of first face")
           ->required();
       app.add_option("-o,--output", a->output, "Output mesh (.obj, .ply, .off, .glb), vertex colours written")
           ->required();
       app.add_option("--recolor", a->recolor, "ID=r,g,b (colour components in [0,1]); repeatable");
       app.add_option("--remove", a->remove, "Element ids to delete, comma separated")->delimiter(',');
       add_common_options(app, a->common);
       return [a] { return run_elements(*a); };
     }}};

// Demo step: chain mail quilted over a small plane and over an icosphere
// (surface quilting + shell-map embedding), meshes and renders written.
nlohmann::json step_quilt(DemoContext& ctx) {
  ChainmailOptions co;
  co.rings_x = co.rings_y = 3;
  co.segments = 12;
  co.sides = 6;
  co.seed = ctx.seed;
  Mesh sm;
  make_chainmail_swatch(sm, co);
  nlohmann::json j;
  Timer t;
  QuiltSwatchOnPlaneOptions po;
  po.swatch_up = SwatchAxis::kZ;
  po.seed = ctx.seed;
  po.plane_name = "2x2";
  Mesh plane;
  const QuiltSwatchOnPlaneResult pr = quilt_swatch_on_plane(sm, 2, 2, plane, po);
  write_mesh(ctx.path("quilt_plane_chainmail.ply"), plane);
  write_image(ctx.path("quilt_plane_chainmail.png"), render_preview(plane));
  j["plane"] = {{"elements", pr.quilt.elements}, {"faces", pr.quilt.faces}, {"outputs", {"quilt_plane_chainmail.ply", "quilt_plane_chainmail.png"}}};
  j["seconds"]["plane"] = t.seconds();
  t.reset();
  Mesh base;
  make_icosphere(base, 2);
  QuiltSwatchOnSurfaceOptions so;
  so.swatch_up = SwatchAxis::kZ;
  so.quilt.relative_size = 0;  // the CLI's default, default_surface_quilt_size of the swatch
  so.quilt.progress = ctx.progress;
  so.embed.stretch.iterations = 10;
  so.seed = ctx.seed;
  so.mesh_name = "icosphere";
  Mesh out;
  const QuiltSwatchOnSurfaceResult sr = quilt_swatch_on_surface(base, sm, out, so);
  write_mesh(ctx.path("quilt_sphere_chainmail.ply"), out);
  write_mesh(ctx.path("quilt_sphere_chainmail.glb"), out);
  Mesh scene;
  surface_quilt_scene(base, out, scene);
  write_image(ctx.path("quilt_sphere_chainmail.png"), render_preview(scene));
  j["sphere"] = {{"elements", sr.quilt.elements},
                 {"faces", sr.faces},
                 {"stretch_before", sr.embedding.stretch.stretch_before},
                 {"stretch_after", sr.embedding.stretch.stretch_after},
                 {"self_intersections", sr.embedding.embed.self_intersecting_pairs},
                 {"bare_fraction", sr.bare.overall},
                 {"outputs", {"quilt_sphere_chainmail.ply", "quilt_sphere_chainmail.glb", "quilt_sphere_chainmail.png"}}};
  j["seconds"]["sphere"] = t.seconds();
  return j;
}

DemoStepRegistrar reg_demo_quilt{
    {60, "quilt", "mesh quilting: chain mail on a plane and on an icosphere (shell-map embedding)", step_quilt}};

}  // namespace quilt_command
}  // namespace
}  // namespace surftex::cli
