// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex render`: a preview image of a mesh from the software rasterizer
// (geometry/rasterizer.h), with its vertex colours or an image texture mapped
// through its texture coordinates.
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/face_material.h"
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
namespace render_command {  // named: the unity build joins these files

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

// True when the file's materials change how it looks (a texture or a
// colour other than white): then they are what a glTF viewer or Blender shows.
bool shows_materials(const std::vector<MeshMaterial>& materials) {
  for (const MeshMaterial& m : materials)
    if (m.has_texture() || m.base_color != std::array<float, 3>{1.f, 1.f, 1.f}) return true;
  return false;
}

RenderOptions::Wrap render_wrap(MeshMaterial::Wrap w) {
  switch (w) {
    case MeshMaterial::Wrap::ClampToEdge: return RenderOptions::Wrap::Clamp;
    case MeshMaterial::Wrap::MirroredRepeat: return RenderOptions::Wrap::Mirror;
    case MeshMaterial::Wrap::Repeat: break;
  }
  return RenderOptions::Wrap::Repeat;
}

// The base colour a glTF viewer shows (glTF 2.0 section 3.9.2): the
// material's baseColorFactor times its texture at the corner UVs (wrapped as
// its sampler says, or clamped with --clamp) times the vertex colour, each
// where present.
FragmentCallback material_shader(const Mesh& mesh, const RenderMesh& rm, const std::vector<MeshMaterial>& materials,
                                 bool clamp) {
  auto fm = find(mesh, kFaceMaterial);
  std::vector<int> tri_material(rm.triangles.size(), -1);
  if (fm.second)
    for (std::size_t t = 0; t < rm.triangles.size(); ++t) {
      const int m = fm.first[FaceIndex(static_cast<std::uint32_t>(rm.triangle_face[t]))];
      tri_material[t] = m >= 0 && static_cast<std::size_t>(m) < materials.size() ? m : -1;
    }
  return [&rm, &materials, clamp, tri_material](int t, const Vec3f& b) -> Vec3f {
    Vec3f c{1.f, 1.f, 1.f};
    const int m = tri_material[static_cast<std::size_t>(t)];
    if (m >= 0) {
      const MeshMaterial& mat = materials[static_cast<std::size_t>(m)];
      for (int k = 0; k < 3; ++k) c[k] = mat.base_color[k];
      if (!mat.texture.empty() && !rm.corner_uvs.empty()) {
        float u = 0, v = 0;
        for (int k = 0; k < 3; ++k) {
          u += b[k] * rm.corner_uvs[3 * t + k][0];
          v += b[k] * rm.corner_uvs[3 * t + k][1];
        }
        const Vec3f s = clamp ? sample_texture(mat.texture, u, v, RenderOptions::Wrap::Clamp)
                              : sample_texture(mat.texture, u, v, render_wrap(mat.wrap_s), render_wrap(mat.wrap_t));
        for (int k = 0; k < 3; ++k) c[k] *= s[k];
      }
    }
    if (!rm.vertex_colors.empty()) {
      const auto& tri = rm.triangles[static_cast<std::size_t>(t)];
      for (int k = 0; k < 3; ++k)
        c[k] *= b[0] * rm.vertex_colors[tri[0]][k] + b[1] * rm.vertex_colors[tri[1]][k] + b[2] * rm.vertex_colors[tri[2]][k];
    }
    return c;
  };
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
  MeshFileContents in = read_mesh_file(a.input, mesh);
  Image texture;
  if (!a.texture.empty()) texture = read_image(a.texture);
  const bool has_uvs = find(mesh, kCornerUV).second;
  const bool material_colors =
      a.texture.empty() && (a.colors == "material" || (a.colors == "auto" && shows_materials(in.materials)));
  if (a.colors == "material" && in.materials.empty())
    throw InvalidInputError("--colors material: mesh '" + a.input + "' has no materials");
  if (material_colors) load_material_textures(in.materials);
  const double t_read = t.seconds();
  report_progress(progress, "read", 1.0);

  const bool has_colors = find(mesh, kVertexColor).second;
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
  } else if (material_colors) {
    mopt.corner_uvs = has_uvs;
    mopt.vertex_colors = has_colors;
    opt.color_source = RenderOptions::ColorSource::Callback;
    source = "material";
  } else if (a.colors == "vertex" || (a.colors == "auto" && has_colors)) {
    if (!has_colors) throw InvalidInputError("--colors vertex: mesh '" + a.input + "' has no vertex colours");
    mopt.vertex_colors = true;
    opt.color_source = RenderOptions::ColorSource::VertexColors;
    source = "vertex";
  }

  t.reset();
  report_progress(progress, "render", 0.0);
  RenderMesh rm = make_render_mesh(mesh, mopt);
  if (material_colors) opt.callback = material_shader(mesh, rm, in.materials, a.clamp);
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
  rep["materials"] = in.materials.size();
  rep["warnings"] = in.warnings;
  rep["coverage"] = covered / (double(opt.width) * opt.height);
  rep["triangles_clipped"] = res.triangles_clipped;
  rep["seconds"] = {{"read", t_read}, {"render", t_render}, {"write", t_write}};
  RunFiles files{in.files_read, {a.output}};
  files.inputs.push_back(a.texture);
  for (const MeshMaterial& m : in.materials)
    if (!m.texture.empty()) files.inputs.push_back(m.texture_file);
  write_report(a.common, "render", rep, files);
  return 0;
}

SubcommandRegistrar reg{{"render", "Render a mesh to an image with the software rasterizer", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<RenderArgs>();
  app.add_option("input", a->input, "Mesh to render (OFF, OBJ with its .mtl, PLY, STL, GLB, glTF)")->required();
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
                 "Colours: auto (the file's materials if they carry a texture or a colour, as a glTF "
                 "viewer shows them: base colour x texture x vertex colour; else vertex colours if the mesh "
                 "has them; else --color), material (require materials), vertex (require vertex colours), "
                 "none (default auto; --texture takes precedence)")
      ->check(CLI::IsMember({"auto", "material", "vertex", "none"}));
  app.add_flag("--flat", a->flat, "Flat shading with face normals (default: smooth vertex normals)");
  app.add_flag("--no-shade", a->no_shade, "No lighting: the raw colours (default: Lambert + ambient 0.25)");
  app.add_flag("--clamp", a->clamp,
               "Clamp texture coordinates to [0,1] (default: a material's texture wraps as its glTF sampler "
               "says, REPEAT without one or for OBJ; --texture repeats)");
  add_common_options(app, a->common);
  return [a] { return run(*a); };
}}};

}  // namespace render_command
}  // namespace
}  // namespace surftex::cli
