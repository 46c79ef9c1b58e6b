// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex material-map MESH --tile DIR -o OUTDIR`: maps a material-space 3D
// tile onto a mesh (Ray et al. 2009, sections 2-3): orientation field, scale
// and material interpolation, periodic global parameterization, singular
// zones, exports and renders with and without the singularity fix.
// `--update C2.json --state S.json` reuses a previous run's solution and only
// solves inside the effect area of the new constraints.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/direction_field.h"
#include "geometry/effect_area.h"
#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "texture/material_space/material_constraints.h"
#include "geometry/mesh.h"
#include "geometry/mesh_util.h"
#include "geometry/output_file.h"
#include "texture/material_space/periodic_global_parameterization.h"
#include "texture/material_space/pgp_singularities.h"
#include "geometry/primitive_meshes.h"
#include "geometry/principal_curvatures.h"
#include "geometry/properties.h"
#include "geometry/rasterizer.h"
#include "geometry/read_mesh.h"
#include "geometry/render_mesh.h"
#include "geometry/scalar_field_interpolation.h"
#include "geometry/timer.h"
#include "geometry/up_axis.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"
#include "surftex/demo_steps.h"
#include "texture/material_space/material_tile.h"
#include "texture/material_space/material_tile_io.h"
#include "texture/procedural_texture.h"
#include "texture/material_space/bake_material_space.h"
#include "texture/material_space/material_mapping.h"
#include "texture/pbr_maps.h"
#include "texture/material_space/render_material_space.h"
#include "texture/surface_fidelity.h"

namespace surftex::cli {
namespace {
namespace material_map_command {  // named: the unity build joins these files

namespace fs = std::filesystem;

struct Args {
  std::string mesh, tile, constraints, update, state, out;
  double scale = 0;             // 0 = auto
  double edges_per_period = 8;  // auto scale
  std::string field = "curvature";
  int render_size = 768;
  int atlas_size = 2048;
  std::vector<float> view{30.f, 20.f};
  double bump = 0.03;
  bool curl_correction = false;
  bool no_swap = false;  // PgpOptions::swap_coordinates = false
  CommonOptions common;
};

// ---- pipeline --------------------------------------------------------------

// OBJ (+MTL, base colour, normal and 16-bit height maps), GLB (base colour
// and normal texture, the material m as a vertex attribute) with the atlas
// uv; PLY with m as a vertex scalar.
// Returns every file written (write_mesh's lists: the OBJ's .mtl and maps too).
std::vector<std::string> write_meshes(Mesh& mesh, const MaterialAsset& a, const std::string& obj, const std::string& glb,
                                      const std::string& ply, bool force) {
  auto mat = find(mesh, kVertexMaterial).first;
  auto scalar = mesh.add_property_map<VertexIndex, double>("material", 0.0).first;
  for (VertexIndex v : mesh.vertices()) scalar[v] = mat[v];
  WriteMeshOptions wo;
  wo.overwrite = force;
  wo.texture = &a.bake.color;
  wo.normal_texture = &a.normal;
  wo.height_texture = &a.bake.height;
  wo.metallic_roughness_texture = &a.metallic_roughness;
  wo.texture_repeat = false;
  WriteMeshOptions go = wo;
  go.height_texture = nullptr;
  go.vertex_scalar_property = "material";
  std::vector<std::string> files = write_obj_and_glb(obj, glb, mesh, wo, go);
  WriteMeshOptions po;
  po.overwrite = force;
  po.write_uvs = false;
  po.vertex_scalar_property = "material";
  for (const std::string& f : write_mesh(ply, mesh, po)) files.push_back(f);
  mesh.remove_property_map(scalar);
  return files;
}

// The map kinds the tile carries (tile.json "maps").
nlohmann::json tile_maps(const MaterialTile& t) {
  nlohmann::json m = nlohmann::json::array();
  if (!t.normal_layers.empty()) m.push_back("normal");
  if (!t.height_layers.empty()) m.push_back("height");
  if (!t.roughness_layers.empty()) m.push_back("roughness");
  return m;
}

MaterialMappingOptions mapping_options(const Args& a) {
  MaterialMappingOptions o;
  o.scale = a.scale;
  o.edges_per_period = a.edges_per_period;
  o.field = a.field == "constant" ? MaterialMappingOptions::Field::Constant : MaterialMappingOptions::Field::Curvature;
  o.curl_correction = a.curl_correction;
  o.swap_coordinates = !a.no_swap;
  return o;
}

const char* const kOutputs[] = {"mesh.obj",         "mesh.mtl",         "mesh.png",         "mesh_normal.png",
                                "mesh_height.png",  "mesh.glb",         "mesh.ply",         "render_plain.png",
                                "render_fixed.png", "render_normalmap.png", "report.json",  "state.json"};

// Written only when the tile has roughness layers (the OBJ's map_Pr).
const char* const kRoughnessOutput = "mesh_roughness.png";

void check_args(const Args& a) {
  require_input_file(a.mesh, "mesh");
  if (!a.constraints.empty()) require_input_file(a.constraints, "--constraints");
  if (!a.update.empty() != !a.state.empty())
    throw InvalidInputError("--update and --state go together (the new constraints and the previous state)");
  if (!a.update.empty()) {
    require_input_file(a.update, "--update");
    require_input_file(a.state, "--state");
    if (!a.constraints.empty())
      throw InvalidInputError("--constraints and --update exclude each other (an update reads the state instead)");
  }
  if (a.view.size() != 2 || !(a.view[1] >= -90.f && a.view[1] <= 90.f) || !std::isfinite(a.view[0]))
    throw InvalidInputError("--view needs two angles az,el in degrees (el in [-90,90])");
  std::vector<std::string> ins;
  for (const auto& i : {a.mesh, a.constraints, a.update, a.state})
    if (!i.empty()) ins.push_back(i);
  for (const char* f : kOutputs) check_output(a.out + "/" + f, ins, a.common.force, false);
  check_output(a.out + "/" + kRoughnessOutput, ins, a.common.force, false);
}

int run(const Args& a) {
  auto keep = apply_thread_limit(a.common.threads);
  Timer total;
  nlohmann::json rep;
  check_args(a);
  Timer t;
  const MaterialTile tile = read_material_tile(a.tile);
  const double s_tile = t.seconds();
  t.reset();
  Mesh mesh;
  rep["input_mesh"] = to_json(load_method_mesh(a.mesh, mesh, a.common));
  require_triangle_mesh(mesh, "material-map");
  const double s_mesh = t.seconds();
  rep["vertices"] = mesh.number_of_vertices();
  rep["faces"] = mesh.number_of_faces();
  check_budget(estimate_material_map(mesh.number_of_faces(), tile.layers.size() * tile.layers[0].data.size() * 4,
                                     a.render_size, a.atlas_size),
               a.common);

  MaterialMapping mapping(mesh, mapping_options(a));
  if (a.update.empty()) {
    t.reset();
    MaterialConstraints c;
    if (!a.constraints.empty()) c = read_material_constraints(a.constraints, mesh);
    const double s_c = t.seconds();
    mapping.map(c);
    rep.update(to_json(mapping.result()));
    rep["seconds"]["read_constraints"] = s_c;
  } else {
    mapping.load_state(a.state);
    const double s_state = mapping.result().seconds.at("read_state");
    t.reset();
    const MaterialConstraints c = read_material_constraints(a.update, mesh);
    if (c.seed_vertices.empty())
      throw InvalidInputError("--update '" + a.update + "' holds no constraint (strokes, scale or material)");
    const double s_c = t.seconds();
    mapping.update(c);
    rep.update(to_json(mapping.result()));
    rep["seconds"]["read_state"] = s_state;
    rep["seconds"]["read_constraints"] = s_c;
  }
  nlohmann::json& sec = rep["seconds"];
  sec["read_tile"] = s_tile;
  sec["read_mesh"] = s_mesh;
  const PgpSingularities& sing = mapping.result().singularities;
  rep["fidelity"] = material_map_fidelity_report(mesh, sing.corners, tile, a.common.seed);  // issue 18 item 3

  ensure_directory(a.out);
  // Renders first: the bake replaces the corner uv by the atlas's.
  t.reset();
  const MaterialViews img = render_material_views(mesh, sing, tile, a.render_size, a.view[0], a.view[1], a.bump);
  sec["render"] = t.seconds();
  t.reset();
  const MaterialAsset baked = bake_material_asset(mesh, sing, tile, a.atlas_size, a.bump, mapping.result().default_scale);
  sec["bake"] = t.seconds();
  rep["atlas"] = to_json(baked);
  t.reset();
  write_meshes(mesh, baked, a.out + "/mesh.obj", a.out + "/mesh.glb", a.out + "/mesh.ply", a.common.force);
  sec["write_meshes"] = t.seconds();
  WriteImageOptions io;
  io.overwrite = a.common.force;
  write_image(a.out + "/render_plain.png", img.plain, io);
  write_image(a.out + "/render_fixed.png", img.fixed, io);
  write_image(a.out + "/render_normalmap.png", img.normal, io);
  mapping.save_state(a.out + "/state.json", a.common.force);
  sec["total"] = total.seconds();
  rep["tile"] = {{"dir", a.tile}, {"layers", tile.layers.size()}, {"size", tile.size}, {"maps", tile_maps(tile)}};
  rep["mesh"] = a.mesh;
  RunFiles run_files{{a.mesh, a.tile, a.constraints, a.update, a.state}, {}};
  for (const char* f : kOutputs)
    if (std::string(f) != "report.json") run_files.outputs.push_back(a.out + "/" + f);
  if (!baked.bake.roughness.empty()) run_files.outputs.push_back(a.out + "/" + kRoughnessOutput);
  write_file_atomic(a.out + "/report.json", make_report(a.common, "material-map", rep, run_files).dump(2) + "\n",
                    a.common.force);
  write_report(a.common, "material-map", rep, run_files);
  if (!a.common.quiet)
    std::fprintf(stderr, "material-map: %zu faces, %.1f%% singular, written to %s (%.2f s)\n",
                 static_cast<std::size_t>(mesh.number_of_faces()), 100 * sing.singular_fraction, a.out.c_str(),
                 total.seconds());
  return 0;
}

SubcommandRegistrar reg{
    {"material-map",
     "Map a material-space 3D tile onto a mesh (orientation/scale/material constraints, periodic global "
     "parameterization, singularity-fixed renders); --update re-solves only inside a new constraint's effect area",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<Args>();
       app.add_option("mesh", a->mesh, "Input triangle mesh (OFF/OBJ/PLY/STL)")->required();
       app.add_option("--tile", a->tile, "Material tile folder written by `surftex material-tile` (tile.json, layer_NNN.png)")
           ->required()
           ->check(CLI::ExistingDirectory);
       app.add_option("--constraints", a->constraints,
                      "Constraints JSON (strokes, scale and material at points, effect_radius; see "
                      "texture/material_space/material_constraints.h). Default: none (field from --field, constant scale, m = 0)");
       app.add_option("--update", a->update,
                      "New constraints JSON applied to the state given by --state: only the effect area "
                      "(effect_radius around them) is re-solved; the rest stays bit for bit");
       app.add_option("--state", a->state, "state.json of a previous run (with --update)");
       app.add_option("-o,--output", a->out,
                      "Output folder: mesh.obj/.mtl and mesh.glb with the mapping baked into a uv atlas "
                      "(mesh.png base colour with the singularity fix and the material blend, mesh_normal.png "
                      "tangent-space normal map, mesh_height.png 16-bit height; with the tile's map layers "
                      "(material-tile --exemplar-*): height and normal from them, mesh_roughness.png as the "
                      "GLB's metallicRoughnessTexture and the MTL's map_Pr), mesh.ply (material m as vertex "
                      "scalar, also in the GLB as _material), render_plain.png, render_fixed.png, "
                      "render_normalmap.png, report.json, state.json")
           ->required();
       app.add_option("--scale", a->scale,
                      "Texture period S in mesh units where no scale constraint applies (> 0; default 0 = "
                      "--edges-per-period times the mean edge length)")
           ->check(CLI::Range(0.0, 1e300));
       app.add_option("--edges-per-period", a->edges_per_period,
                      "Automatic period in mean edge lengths (1..1000, default 8)")
           ->check(CLI::Range(1.0, 1000.0));
       app.add_option("--field", a->field,
                      "Orientation without strokes: curvature (principal directions of the 10% most anisotropic "
                      "faces, smoothed) or constant (world +Y projected: the tile's axes run level and upright, but the cross "
                      "field is 4-symmetric, so which axis points up is not fixed, unlike patches --field up); "
                      "default curvature")
           ->check(CLI::IsMember({"curvature", "constant"}));
       app.add_option("--render-size", a->render_size, "Side of the renders in pixels (16..4096, default 768)")
           ->check(CLI::Range(16, 4096));
       app.add_option("--atlas-size", a->atlas_size,
                      "Side of the baked texture atlas (mesh.png, mesh_normal.png, mesh_height.png) in texels, "
                      "64..8192 (default 2048; powers of two mip-map best)")
           ->check(CLI::Range(64, 8192));
       app.add_option("--view", a->view, "Render view: azimuth elevation in degrees (default 30 20)")->expected(2);
       app.add_option("--bump", a->bump,
                      "Normal-map strength (render_normalmap.png and mesh_normal.png; height = tile luminance): "
                      "tilt per unit height slope, height per period (0..10, default 0.03)")
           ->check(CLI::Range(0.0, 10.0));
       app.add_flag("--curl-correction", a->curl_correction,
                    "Rescale the PGP's target gradients d/S towards curl-free before the solve (Ray et al. "
                    "2006): fewer singular faces (armadillo 29.6% -> 24.0%), but the period departs from "
                    "the scale S by up to 2x and updates re-solve every gradient (default off: d/S as "
                    "given, as in Ray et al. 2009). With --update the state's setting is used");
       app.add_flag("--no-swap", a->no_swap,
                    "Paper's simplified PGP (Ray et al. 2009 section 2.3): s and t solved as two independent "
                    "systems, never swapped across the orientation field's quarter-turn cuts; faster "
                    "initialisation (about a quarter of the factorisation's work) but more singular faces "
                    "(three texture lookups) along the cuts. Default off (s and t coupled). With --update the "
                    "state's setting is used");
       add_common_options(app, a->common);
       return [a] { return run(*a); };
     }}};

// ---- demo step ---------------------------------------------------------------

nlohmann::json demo_material_map(DemoContext& ctx) {
  // A small 3D tile morphing noise into cells.
  std::vector<MaterialKey> keys(2);
  keys[0].texture = make_noise(64, 4, ctx.seed);
  keys[0].name = "noise";
  keys[1].texture = make_cells(64, 4, ctx.seed + 1);
  keys[1].name = "cells";
  MaterialTileOptions to;
  to.size = 64;
  to.layers = 3;  // 4 layers
  to.keys_are_tileable = true;
  to.seed = ctx.seed;
  MaterialTileResult tr = make_material_tile(keys, to);
  MaterialTileInfo info;
  info.sources = {"noise", "cells"};
  info.masks = {"", ""};
  info.seed = ctx.seed;
  info.layers_per_pair = to.layers;
  const std::string tile_dir = ctx.path("material_tile");
  write_material_tile(tile_dir, tr, info, true);
  const MaterialTile tile = read_material_tile(staged_path(tile_dir));

  Mesh mesh;
  make_torus(mesh, 1.0, 0.4, 96, 40);
  // A stroke along the big circle on top, and a material gradient from one
  // side to the other, through the same driver as the CLI (6 edges per period).
  MaterialConstraints c;
  for (FaceIndex f : mesh.faces()) {
    Vector3 p(0, 0, 0);
    for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) p = p + (mesh.point(v) - CGAL::ORIGIN) / 3.0;
    if (p.z() > 0.35 && f.idx() % 7 == 0) c.directions.push_back({static_cast<std::uint32_t>(f.idx()), {-p.y(), p.x(), 0.0}});
  }
  for (VertexIndex v : mesh.vertices()) {
    if (mesh.point(v).x() < -1.2) c.material.push_back({static_cast<std::uint32_t>(v.idx()), 0.0});
    if (mesh.point(v).x() > 1.2) c.material.push_back({static_cast<std::uint32_t>(v.idx()), 1.0});
  }
  MaterialMappingOptions mo;
  mo.edges_per_period = 6;
  MaterialMapping mapping(mesh, mo);
  mapping.map(c);
  const PgpSingularities& sing = mapping.result().singularities;
  z_up_to_y_up(mesh);  // the torus was built around z: lying flat in glTF viewers
  const MaterialViews img = render_material_views(mesh, sing, tile, 384, 20.f, 45.f, 0.03);
  const MaterialAsset baked = bake_material_asset(mesh, sing, tile, 512, 0.03, mapping.result().default_scale);
  ctx.wrote(write_meshes(mesh, baked, ctx.path("material_map.obj"), ctx.path("material_map.glb"),
                         ctx.path("material_map.ply"), true));
  write_image(ctx.path("material_map_plain.png"), img.plain);
  write_image(ctx.path("material_map_fixed.png"), img.fixed);
  write_image(ctx.path("material_map_normalmap.png"), img.normal);
  return {{"faces", mesh.number_of_faces()},
          {"tile_layers", tile.layers.size()},
          {"singular_fraction", sing.singular_fraction},
          {"atlas", to_json(baked)},
          {"outputs",
           {"material_tile/tile.json", "material_map.obj", "material_map.mtl", "material_map.png", "material_map_normal.png",
            "material_map_height.png", "material_map.glb", "material_map.ply", "material_map_plain.png",
            "material_map_fixed.png", "material_map_normalmap.png"}}};
}

DemoStepRegistrar demo_reg{{40, "material-map",
                            "a 4-layer noise-to-cells material tile mapped on a torus with a stroke and a material gradient",
                            demo_material_map}};

}  // namespace material_map_command
}  // namespace
}  // namespace surftex::cli
