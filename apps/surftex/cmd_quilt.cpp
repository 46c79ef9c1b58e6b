// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex quilt`: mesh quilting of a swatch over a plane (Zhou et al. 2006,
// section 2) and `surftex elements`: edit the elements of a result by id.
#include <cstdio>
#include <sstream>
#include <string>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "shell/element_colors.h"
#include "shell/mesh_quilting.h"
#include "shell/swatch.h"
#include "surftex/command.h"

namespace surftex::cli {
namespace {

std::string render_path_for(const std::string& out) {
  const auto dot = out.find_last_of('.');
  const auto slash = out.find_last_of('/');
  const std::string stem = (dot == std::string::npos || (slash != std::string::npos && dot < slash)) ? out : out.substr(0, dot);
  return stem + "_render.png";
}

struct QuiltArgs {
  std::string base, swatch, output, plane, render;
  bool no_render = false;
  double scale = 1.0, cell = 0;
  int subpatch = 0;
  CommonOptions common;
};

int run_quilt(QuiltArgs& a) {
  // With --plane the positional arguments are just the swatch.
  if (!a.plane.empty() && !a.base.empty() && a.swatch.empty()) std::swap(a.base, a.swatch);
  if (a.plane.empty())
    throw InvalidInputError("quilt: quilting over a base mesh is not available in this build; use --plane WxH");
  if (a.swatch.empty()) throw InvalidInputError("quilt: missing SWATCH");
  require_input_file(a.swatch, "swatch");
  check_output(a.output, {a.swatch}, a.common.force);
  if (a.render.empty() && !a.no_render) a.render = render_path_for(a.output);
  if (!a.render.empty()) check_output(a.render, {a.swatch, a.output}, a.common.force);
  double w = 0, h = 0;
  {
    char x = 0;
    std::istringstream is(a.plane);
    if (!(is >> w >> x >> h) || (x != 'x' && x != 'X') || !(w > 0) || !(h > 0))
      throw InvalidInputError("quilt: --plane must be WxH with positive numbers in swatch sizes (got '" + a.plane + "')");
  }
  auto limit = apply_thread_limit(a.common.threads);
  Mesh sm;
  read_mesh(a.swatch, sm);
  // --scale: size of the swatch relative to the output (the paper's s).
  for (VertexIndex v : sm.vertices()) {
    const Point3 p = sm.point(v);
    sm.point(v) = Point3(p.x() * a.scale, p.y() * a.scale, p.z() * a.scale);
  }
  const Swatch s = make_swatch(sm);
  PlanarQuiltOptions o;
  o.seed = a.common.seed;
  o.cell_size = a.cell;
  o.subpatch_radius = a.subpatch;
  o.progress = terminal_progress(a.common.quiet);
  Mesh out;
  const QuiltResult r = quilt_plane(s, w * s.length(), h * s.width(), out, o);
  Timer t;
  color_by_element(out, a.common.seed);
  WriteMeshOptions wo;
  wo.overwrite = a.common.force;
  write_mesh(a.output, out, wo);
  if (!a.render.empty()) {
    WriteImageOptions io;
    io.overwrite = a.common.force;
    write_image(a.render, render_preview(out), io);
  }
  nlohmann::json rep;
  rep["swatch"] = a.swatch;
  rep["output"] = a.output;
  if (!a.render.empty()) rep["render"] = a.render;
  rep["plane"] = {w, h};
  rep["swatch_faces"] = s.mesh.tris.size();
  rep["swatch_elements"] = s.elements.size();
  rep["elements"] = r.elements;
  rep["faces"] = r.faces;
  rep["vertices"] = r.vertices;
  rep["steps"] = r.steps;
  rep["stitched"] = r.stats.stitched;
  rep["stitch_refused"] = r.stats.stitch_refused;
  rep["seconds"] = {{"total", r.seconds}, {"match", r.stats.seconds_match}, {"correspond", r.stats.seconds_correspond},
                    {"deform", r.stats.seconds_deform}, {"merge", r.stats.seconds_merge}, {"write", t.seconds()}};
  write_report(a.common, "quilt", rep);
  if (!a.common.quiet)
    std::fprintf(stderr, "quilt: %d elements, %zu faces in %d steps (%.1f s), %zu stitched, %zu refused -> %s\n",
                 r.elements, r.faces, r.steps, r.seconds, r.stats.stitched, r.stats.stitch_refused, a.output.c_str());
  return 0;
}

SubcommandRegistrar reg_quilt{
    {"quilt", "Mesh quilting: grow a geometric texture from a mesh swatch over a plane",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<QuiltArgs>();
       app.add_option("mesh", a->base, "Base mesh (not available yet) or, with --plane, the swatch");
       app.add_option("swatch", a->swatch, "Swatch mesh (any format read_mesh reads); elements = connected components");
       app.add_option("--plane", a->plane, "Quilt over a plane of W x H swatch sizes, e.g. 4x4 (required for now)");
       app.add_option("-o,--output", a->output,
                      "Output mesh; format by extension: .obj (+ vertex colours), .ply (binary, colours), .off, "
                      ".glb. Element colours are written as vertex colours; element ids are the connected "
                      "components (surftex elements recomputes them)")
           ->required();
       app.add_option("--render", a->render, "Render PNG (default: <output stem>_render.png)");
       app.add_flag("--no-render", a->no_render, "Do not write a render");
       app.add_option("--scale", a->scale, "Scale applied to the swatch (the paper's s), > 0 (default 1)")
           ->check(CLI::PositiveNumber);
       app.add_option("--cell", a->cell, "Grid cell size in swatch units; 0 = swatch extent / 10 (default 0)")
           ->check(CLI::NonNegativeNumber);
       app.add_option("--subpatch", a->subpatch, "Output sub-patch half-size in cells; 0 = automatic (0..100, default 0)")
           ->check(CLI::Range(0, 100));
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
  // Element ids are recomputed as connected components, numbered in order of
  // their first face in the file (the same numbering quilt writes).
  const int n = label_elements(m);
  auto elem = find(m, kFaceElement).first;
  auto col_found = find(m, kVertexColor);
  if (!col_found.second) color_by_element(m, a.common.seed);
  auto col = get_or_add(m, kVertexColor, Color3f{0.8f, 0.8f, 0.8f});
  for (const std::string& rc : a.recolor) {
    int id = -1;
    float r = 0, g = 0, b = 0;
    if (std::sscanf(rc.c_str(), "%d=%f,%f,%f", &id, &r, &g, &b) != 4 || id < 0 || id >= n)
      throw InvalidInputError("elements: --recolor wants ID=r,g,b with 0 <= ID < " + std::to_string(n) +
                              " and colours in [0,1] (got '" + rc + "')");
    for (float c : {r, g, b})
      if (!(c >= 0 && c <= 1)) throw InvalidInputError("elements: colour out of [0,1] in '" + rc + "'");
    for (FaceIndex f : m.faces())
      if (elem[f] == id)
        for (VertexIndex v : m.vertices_around_face(m.halfedge(f))) col[v] = {r, g, b};
  }
  std::size_t removed = 0;
  for (int id : a.remove) {
    if (id < 0 || id >= n)
      throw InvalidInputError("elements: --remove id " + std::to_string(id) + " out of range 0.." + std::to_string(n - 1));
  }
  if (!a.remove.empty()) {
    std::vector<char> gone(static_cast<std::size_t>(n), 0);
    for (int id : a.remove) gone[id] = 1;
    std::vector<FaceIndex> faces(m.faces().begin(), m.faces().end());
    for (FaceIndex f : faces)
      if (gone[elem[f]]) {
        CGAL::Euler::remove_face(m.halfedge(f), m);
        ++removed;
      }
    m.collect_garbage();
  }
  WriteMeshOptions wo;
  wo.overwrite = a.common.force;
  write_mesh(a.output, m, wo);
  nlohmann::json rep;
  rep["input"] = a.input;
  rep["output"] = a.output;
  rep["elements"] = n;
  rep["faces_removed"] = removed;
  write_report(a.common, "elements", rep);
  if (!a.common.quiet) std::fprintf(stderr, "elements: %d elements, %zu faces removed -> %s\n", n, removed, a.output.c_str());
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

}  // namespace
}  // namespace surftex::cli
