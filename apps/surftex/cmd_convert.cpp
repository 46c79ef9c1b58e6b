// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex convert IN -o OUT`: read any supported mesh, repair it, write it,
// with its materials and textures (OBJ .mtl + map_Kd, glTF materials) when the
// output format carries them (OBJ, GLB).
#include <cstdio>
#include <filesystem>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"

namespace fs = std::filesystem;

namespace surftex::cli {
namespace {
namespace convert_command {  // named: the unity build joins these files

struct ConvertArgs {
  std::string input, output, texture;
  bool no_triangulate = false;
  CommonOptions common;
};

std::string lower_extension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// The files an OBJ output writes beside itself (its .mtl and textures) must
// not replace an input (the source's own texture, say).
void check_obj_siblings(const std::string& output, const std::vector<std::string>& inputs, std::size_t materials) {
  const fs::path p(output);
  std::vector<std::string> sib{(p.parent_path() / (p.stem().string() + ".mtl")).string(),
                               (p.parent_path() / (p.stem().string() + ".png")).string()};
  for (std::size_t k = 0; k < materials; ++k)
    sib.push_back((p.parent_path() / (p.stem().string() + "_" + std::to_string(k) + ".png")).string());
  for (const std::string& s : sib)
    for (const std::string& in : inputs)
      if (same_file(s, in))
        throw InvalidInputError("writing '" + output + "' would replace its input '" + in + "' (as '" + s +
                                "'): choose another output name");
}

int run(const ConvertArgs& a) {
  auto limit = apply_thread_limit(a.common.threads);
  require_input_file(a.input, "input mesh");
  RunFiles files{{a.input}, {}};
  if (!a.texture.empty()) {
    require_input_file(a.texture, "texture");
    files.inputs.push_back(a.texture);
  }
  check_output(a.output, files.inputs, a.common.force);
  Timer timer;
  Mesh mesh;
  SoupToMeshOptions ropt;
  ropt.triangulate = !a.no_triangulate;
  MeshFileContents in = read_mesh_file(a.input, mesh, ropt);
  const bool has_uvs = find(mesh, kCornerUV).second;
  if (!a.texture.empty() && !has_uvs)
    throw InvalidInputError("--texture: mesh '" + a.input +
                            "' has no texture coordinates (UVs, e.g. OBJ vt) to map the texture with");
  const std::string ext = lower_extension(a.output);
  const bool keeps_materials = ext == ".obj" || ext == ".glb";
  WriteMeshOptions wopt;
  wopt.overwrite = a.common.force;
  Image tex;
  if (!a.texture.empty()) {
    tex = read_image(a.texture);
    wopt.texture = &tex;
  } else if (keeps_materials && !in.materials.empty()) {
    load_material_textures(in.materials);
    for (MeshMaterial& m : in.materials)
      if (!m.texture.empty() && !has_uvs) {
        in.warnings.push_back("material '" + m.name + "' has a texture but the mesh has no UVs: written without it");
        m.texture = Image();
      }
    wopt.materials = &in.materials;
  }
  for (std::size_t i = 1; i < in.files_read.size(); ++i) files.inputs.push_back(in.files_read[i]);
  for (const MeshMaterial& m : in.materials)
    if (!m.texture_file.empty() && !m.texture.empty()) files.inputs.push_back(m.texture_file);
  if (ext == ".obj") check_obj_siblings(a.output, files.inputs, in.materials.size());
  const double read_s = timer.seconds();
  timer.reset();
  files.outputs = write_mesh(a.output, mesh, wopt);
  const double write_s = timer.seconds();
  const SoupRepairCounts& c = in.counts;
  if (!a.common.quiet) {
    for (const std::string& w : in.warnings) std::fprintf(stderr, "note: %s: %s\n", a.input.c_str(), w.c_str());
    std::printf("%s: %zu vertices, %zu faces, %zu materials -> %s\n", a.input.c_str(), c.output_vertices,
                c.output_faces, in.materials.size(), a.output.c_str());
  }
  nlohmann::json r;
  r["input"] = a.input;
  r["output"] = a.output;
  r["vertices"] = c.output_vertices;
  r["faces"] = c.output_faces;
  r["points_in_file"] = c.input_points;
  r["polygons_in_file"] = c.input_polygons;
  r["materials"] = keeps_materials && a.texture.empty() ? in.materials.size() : std::size_t(a.texture.empty() ? 0 : 1);
  r["warnings"] = in.warnings;
  r["seconds"] = {{"read", read_s}, {"write", write_s}};
  write_report(a.common, "convert", r, files);
  return 0;
}

SubcommandRegistrar reg{
    {"convert", "Convert a mesh between formats (in: OFF, OBJ, PLY, STL, GLB, glTF; out: OBJ, PLY, OFF, GLB)",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<ConvertArgs>();
       app.add_option("input", a->input,
                      "Input mesh (.off, .obj with its .mtl, .ply, .stl, .glb, .gltf; other names by content)")
           ->required();
       app.add_option("-o,--output", a->output,
                      "Output mesh; the format follows the extension: .obj (+ .mtl and textures), .ply (binary), "
                      ".off, .glb. OBJ and GLB keep the input's materials and base-colour textures (one per "
                      "material); PLY and OFF keep geometry and vertex colours")
           ->required();
       app.add_option("--texture", a->texture,
                      "Image to attach as the one texture, replacing the input's materials (OBJ: written as "
                      "<stem>.png with an .mtl; GLB: embedded); the mesh must have texture coordinates. "
                      "Default: none");
       app.add_flag("--no-triangulate", a->no_triangulate,
                    "Keep polygons instead of triangulating them (default: triangulate; GLB always "
                    "stores triangles)");
       add_common_options(app, a->common);
       return [a] { return run(*a); };
     }}};

}  // namespace convert_command
}  // namespace
}  // namespace surftex::cli
