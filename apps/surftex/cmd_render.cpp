// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex render`: a preview image of a mesh from the software rasterizer
// (geometry/rasterizer.h), with its vertex colours or an image texture mapped
// through its texture coordinates.
#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/rasterizer.h"
#include "geometry/read_mesh.h"
#include "geometry/render_mesh.h"
#include "geometry/timer.h"
#include "surftex/command.h"

namespace surftex::cli {
namespace {

struct RenderArgs {
  std::string input, output, texture;
  int size = 1024;
  std::vector<float> view{30.f, 20.f};
  bool ortho = false;
  int supersample = 2;
  std::vector<float> background{1.f, 1.f, 1.f};
  std::vector<float> color{0.8f, 0.78f, 0.74f};
  std::string colors = "auto";
  bool flat = false;
  bool no_shade = false;
  bool clamp = false;
  CommonOptions common;
};

Vec3f rgb(const std::vector<float>& v, const std::string& name) {
  if (v.size() != 3) throw InvalidInputError(name + " needs 3 comma-separated values r,g,b, got " + std::to_string(v.size()));
  for (float x : v)
    if (!(x >= 0.f && x <= 1.f))
      throw InvalidInputError(name + " value " + std::to_string(x) + " out of range [0,1]");
  return {v[0], v[1], v[2]};
}

int run(RenderArgs& a) {
  auto limit = apply_thread_limit(a.common.threads);
  ProgressCallback progress = terminal_progress(a.common.quiet);
  require_input_file(a.input, "input mesh");
  if (!a.texture.empty()) require_input_file(a.texture, "texture");
  check_output(a.output, {a.input, a.texture}, a.common.force);
  if (a.view.size() != 2 || !std::isfinite(a.view[0]) || !std::isfinite(a.view[1]))
    throw InvalidInputError("--view needs two finite angles az,el in degrees");
  if (!(a.view[1] >= -90.f && a.view[1] <= 90.f))
    throw InvalidInputError("--view elevation " + std::to_string(a.view[1]) + " out of range [-90,90]");
  const Vec3f background = rgb(a.background, "--background");
  const Vec3f color = rgb(a.color, "--color");

  Timer total, t;
  report_progress(progress, "read", 0.0);
  Mesh mesh;
  SoupRepairCounts counts;
  read_mesh(a.input, mesh, {}, &counts);
  Image texture;
  if (!a.texture.empty()) texture = read_image(a.texture);
  const double t_read = t.seconds();
  report_progress(progress, "read", 1.0);

  const bool has_colors = find(mesh, kVertexColor).second;
  const bool has_uvs = find(mesh, kCornerUV).second;
  RenderOptions opt;
  opt.width = opt.height = a.size;
  opt.supersample = a.supersample;
  opt.background = background;
  opt.constant_color = color;
  opt.shade = !a.no_shade;
  opt.wrap = a.clamp ? RenderOptions::Wrap::Clamp : RenderOptions::Wrap::Repeat;
  RenderMeshOptions mopt;
  mopt.smooth_normals = !a.flat;
  std::string source = "constant";
  if (!a.texture.empty()) {
    if (!has_uvs)
      throw InvalidInputError("--texture: mesh '" + a.input + "' has no texture coordinates (e.g. OBJ vt) to map it with");
    mopt.corner_uvs = true;
    opt.color_source = RenderOptions::ColorSource::Texture;
    opt.texture = &texture;
    source = "texture";
  } else if (a.colors == "vertex" || (a.colors == "auto" && has_colors)) {
    if (!has_colors) throw InvalidInputError("--colors vertex: mesh '" + a.input + "' has no vertex colours");
    mopt.vertex_colors = true;
    opt.color_source = RenderOptions::ColorSource::VertexColors;
    source = "vertex";
  }

  t.reset();
  report_progress(progress, "render", 0.0);
  RenderMesh rm = make_render_mesh(mesh, mopt);
  const Camera cam = fit_camera(bounding_box(rm), a.view[0], a.view[1],
                                a.ortho ? Camera::Projection::Orthographic : Camera::Projection::Perspective, 1.f);
  RenderResult res = render(rm, cam, opt);
  const double t_render = t.seconds();
  report_progress(progress, "render", 1.0);

  t.reset();
  report_progress(progress, "write", 0.0);
  write_image(a.output, res.color, {.eight_bit = true, .overwrite = true});
  const double t_write = t.seconds();
  report_progress(progress, "write", 1.0);

  double covered = 0;
  for (float c : res.coverage.data) covered += c;
  nlohmann::json rep;
  rep["input"] = a.input;
  rep["output"] = a.output;
  rep["texture"] = a.texture;
  rep["vertices"] = mesh.number_of_vertices();
  rep["faces"] = mesh.number_of_faces();
  rep["triangles"] = rm.triangles.size();
  rep["width"] = opt.width;
  rep["height"] = opt.height;
  rep["supersample"] = opt.supersample;
  rep["view"] = {a.view[0], a.view[1]};
  rep["projection"] = a.ortho ? "orthographic" : "perspective";
  rep["colors"] = source;
  rep["coverage"] = covered / (double(opt.width) * opt.height);
  rep["triangles_clipped"] = res.triangles_clipped;
  rep["seconds"] = {{"read", t_read}, {"render", t_render}, {"write", t_write}, {"total", total.seconds()}};
  write_report(a.common, "render", rep);
  return 0;
}

SubcommandRegistrar reg{{"render", "Render a mesh to an image with the software rasterizer", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<RenderArgs>();
  app.add_option("input", a->input, "Mesh to render (OFF, OBJ, PLY, STL)")->required();
  app.add_option("-o,--output", a->output, "Image to write (PNG, JPEG, TIFF, EXR: by extension)")->required();
  app.add_option("--texture", a->texture,
                 "Image texture mapped through the mesh's texture coordinates (the mesh must have them)");
  app.add_option("--size", a->size, "Image width and height in pixels (16..8192, default 1024)")
      ->check(CLI::Range(16, 8192));
  app.add_option("--view", a->view,
                 "Camera direction az,el in degrees: azimuth about +Y (0 = from +Z, 90 = from +X), "
                 "elevation -90..90 (default 30,20); the camera frames the whole mesh")
      ->delimiter(',')
      ->expected(2);
  app.add_flag("--ortho", a->ortho, "Orthographic projection (default: perspective, 35 degree field of view)");
  app.add_option("--supersample", a->supersample,
                 "Anti-aliasing: K x K samples per pixel (1..4, default 2)")
      ->check(CLI::Range(1, 4));
  app.add_option("--background", a->background, "Background colour r,g,b in [0,1] (default 1,1,1)")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--color", a->color,
                 "Surface colour r,g,b in [0,1] when neither texture nor vertex colours are used (default 0.8,0.78,0.74)")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--colors", a->colors,
                 "Vertex colours: auto (use them if the mesh has them), vertex (require them), none "
                 "(default auto; --texture takes precedence)")
      ->check(CLI::IsMember({"auto", "vertex", "none"}));
  app.add_flag("--flat", a->flat, "Flat shading with face normals (default: smooth vertex normals)");
  app.add_flag("--no-shade", a->no_shade, "No lighting: the raw colours (default: Lambert + ambient 0.25)");
  app.add_flag("--clamp", a->clamp, "Clamp texture coordinates to [0,1] (default: repeat)");
  add_common_options(app, a->common);
  return [a] { return run(*a); };
}}};

}  // namespace
}  // namespace surftex::cli
