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

#include <tbb/parallel_invoke.h>

#include "geometry/direction_field.h"
#include "geometry/effect_area.h"
#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/material_constraints.h"
#include "geometry/mesh.h"
#include "geometry/mesh_util.h"
#include "geometry/output_file.h"
#include "geometry/periodic_global_parameterization.h"
#include "geometry/pgp_singularities.h"
#include "geometry/primitive_meshes.h"
#include "geometry/principal_curvatures.h"
#include "geometry/properties.h"
#include "geometry/rasterizer.h"
#include "geometry/read_mesh.h"
#include "geometry/render_mesh.h"
#include "geometry/scalar_field_interpolation.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"
#include "surftex/demo_steps.h"
#include "texture/material_tile.h"
#include "texture/material_tile_io.h"
#include "texture/procedural_texture.h"
#include "texture/render_material_space.h"
#include "texture/surface_fidelity.h"

namespace surftex::cli {
namespace {

namespace fs = std::filesystem;
using Cplx = std::complex<double>;

struct Args {
  std::string mesh, tile, constraints, update, state, out;
  double scale = 0;             // 0 = auto
  double edges_per_period = 8;  // auto scale
  std::string field = "curvature";
  int render_size = 768;
  std::vector<float> view{30.f, 20.f};
  double bump = 0.03;
  bool curl_correction = false;
  bool no_swap = false;  // PgpOptions::swap_coordinates = false
  CommonOptions common;
};

// ---- solver state (S.json) -------------------------------------------------

// Version 2: z_s, z_t are stored in per-vertex frames (s/t coupled across
// field cuts); version-1 states (independent s and t) are refused.
// "swap_coordinates": false when solved with --no-swap (the paper's
// simplified PGP: no frames, every corner turn 0); absent = true.
const char* const kStateFormat = "surftex material-map state v2";

void save_state(const std::string& path, const Mesh& mesh, const PeriodicGlobalParameterization& pgp,
                double default_scale, bool curl_correction, bool swap_coordinates, bool overwrite) {
  nlohmann::json j;
  j["format"] = kStateFormat;
  j["curl_correction"] = curl_correction;
  j["swap_coordinates"] = swap_coordinates;
  j["vertices"] = mesh.num_vertices();
  j["faces"] = mesh.num_faces();
  j["default_scale"] = default_scale;
  auto dir = find(mesh, kFaceDirection).first;
  auto sc = find(mesh, kVertexScale).first;
  auto mat = find(mesh, kVertexMaterial).first;
  std::vector<double> zs, zt, d, s, m;
  for (std::size_t i = 0; i < mesh.num_vertices(); ++i) {
    zs.push_back(pgp.z_s()[i].real());
    zs.push_back(pgp.z_s()[i].imag());
    zt.push_back(pgp.z_t()[i].real());
    zt.push_back(pgp.z_t()[i].imag());
    s.push_back(sc[VertexIndex(static_cast<std::uint32_t>(i))]);
    m.push_back(mat[VertexIndex(static_cast<std::uint32_t>(i))]);
  }
  for (std::size_t i = 0; i < mesh.num_faces(); ++i) {
    const Vector3 v = dir[FaceIndex(static_cast<std::uint32_t>(i))];
    d.insert(d.end(), {v.x(), v.y(), v.z()});
  }
  j["z_s"] = zs;  // re, im per vertex (doubles round-trip exactly)
  j["z_t"] = zt;
  j["direction"] = d;
  j["scale"] = s;
  j["material"] = m;
  write_file_atomic(path, j.dump() + "\n", overwrite);
}

std::vector<double> state_array(const nlohmann::json& j, const char* key, std::size_t n, const std::string& path) {
  auto it = j.find(key);
  if (it == j.end() || !it->is_array())
    throw InvalidInputError("state '" + path + "': field '" + key + "' missing or not an array");
  if (it->size() != n)
    throw InvalidInputError("state '" + path + "': field '" + key + "' has " + std::to_string(it->size()) +
                            " values, expected " + std::to_string(n) + " (was it written for this mesh?)");
  std::vector<double> v;
  v.reserve(n);
  for (const auto& x : *it) {
    if (!x.is_number()) throw InvalidInputError("state '" + path + "': field '" + key + "' holds a non-number");
    v.push_back(x.get<double>());
  }
  return v;
}

nlohmann::json read_state(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IOError("cannot open state file '" + path + "'");
  std::stringstream buf;
  buf << in.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(buf.str());
  } catch (const nlohmann::json::parse_error& e) {
    throw InvalidInputError("state '" + path + "': malformed JSON at byte " + std::to_string(e.byte));
  }
  if (!j.is_object() || j.value("format", "") != kStateFormat)
    throw InvalidInputError("state '" + path + "': not a material-map state of this version (field 'format' is '" +
                            j.value("format", std::string()) + "', expected '" + kStateFormat +
                            "'; re-run material-map without --update to make one)");
  return j;
}

/// The curl correction the state was solved with (states written before it
/// existed were solved without).
bool state_curl_correction(const nlohmann::json& j) {
  auto it = j.find("curl_correction");
  return it != j.end() && it->is_boolean() && it->get<bool>();
}

/// Whether the state's s and t were swapped across the field's cuts (the
/// coupled form; states written before the option existed were).
bool state_swap_coordinates(const nlohmann::json& j) {
  auto it = j.find("swap_coordinates");
  return it == j.end() || !it->is_boolean() || it->get<bool>();
}

double load_state(const nlohmann::json& j, const std::string& path, Mesh& mesh,
                  PeriodicGlobalParameterization& pgp) {
  const std::size_t nv = mesh.num_vertices(), nf = mesh.num_faces();
  const auto zs = state_array(j, "z_s", 2 * nv, path), zt = state_array(j, "z_t", 2 * nv, path);
  const auto d = state_array(j, "direction", 3 * nf, path);
  const auto s = state_array(j, "scale", nv, path), m = state_array(j, "material", nv, path);
  auto dir = get_or_add(mesh, kFaceDirection, Vector3(1, 0, 0));
  auto sc = get_or_add(mesh, kVertexScale, 1.0);
  auto mat = get_or_add(mesh, kVertexMaterial, 0.0);
  std::vector<Cplx> zsv(nv), ztv(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    zsv[i] = Cplx(zs[2 * i], zs[2 * i + 1]);
    ztv[i] = Cplx(zt[2 * i], zt[2 * i + 1]);
    sc[VertexIndex(static_cast<std::uint32_t>(i))] = s[i];
    mat[VertexIndex(static_cast<std::uint32_t>(i))] = m[i];
  }
  for (std::size_t i = 0; i < nf; ++i)
    dir[FaceIndex(static_cast<std::uint32_t>(i))] = Vector3(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
  pgp.set_state(std::move(zsv), std::move(ztv));
  return j.value("default_scale", 0.0);
}

// ---- pipeline --------------------------------------------------------------

struct Outputs {
  Image plain, fixed, normal;
};

Outputs render_all(const Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile, int size,
                   const std::vector<float>& view, double bump) {
  RenderMesh rm = make_render_mesh(mesh);
  const Camera cam = fit_camera(bounding_box(rm), view[0], view[1]);
  RenderOptions ro;
  ro.width = ro.height = size;
  ro.color_source = RenderOptions::ColorSource::Callback;
  Outputs o;
  MaterialRenderOptions mo;
  mo.lookup = MaterialRenderOptions::Lookup::Plain;
  ro.callback = material_space_fragment(rm, sing, tile, mo);
  o.plain = render(rm, cam, ro).color;
  mo.lookup = MaterialRenderOptions::Lookup::Blended;
  ro.callback = material_space_fragment(rm, sing, tile, mo);
  o.fixed = render(rm, cam, ro).color;
  mo.output = MaterialRenderOptions::Output::NormalMap;
  mo.bump_strength = bump;
  mo.light_world = light_direction_world(cam, ro.light_direction);
  ro.callback = material_space_fragment(rm, sing, tile, mo);
  ro.shade = false;
  o.normal = render(rm, cam, ro).color;
  return o;
}

void write_meshes(Mesh& mesh, const std::string& out, bool force) {
  auto stm = find(mesh, kCornerSTM).first;
  auto uv = get_or_add(mesh, kCornerUV);
  for (HalfedgeIndex h : mesh.halfedges())
    if (!mesh.is_border(h)) uv[h] = {stm[h][0], stm[h][1]};
  auto mat = find(mesh, kVertexMaterial).first;
  auto scalar = mesh.add_property_map<VertexIndex, double>("material", 0.0).first;
  for (VertexIndex v : mesh.vertices()) scalar[v] = mat[v];
  WriteMeshOptions wo;
  wo.overwrite = force;
  write_mesh(out + "/mesh.obj", mesh, wo);
  wo.vertex_scalar_property = "material";
  write_mesh(out + "/mesh.glb", mesh, wo);
  write_mesh(out + "/mesh.ply", mesh, wo);
  mesh.remove_property_map(scalar);
}

int run(const Args& a) {
  auto keep = apply_thread_limit(a.common.threads);
  Timer total;
  nlohmann::json rep, sec;
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
  const std::vector<std::string> inputs{a.mesh, a.constraints, a.update, a.state};
  const char* files[] = {"mesh.obj", "mesh.glb", "mesh.ply", "render_plain.png", "render_fixed.png",
                         "render_normalmap.png", "report.json", "state.json"};
  for (const char* f : files) {
    std::vector<std::string> ins;
    for (const auto& i : inputs)
      if (!i.empty()) ins.push_back(i);
    check_output(a.out + "/" + f, ins, a.common.force, false);
  }

  Timer t;
  const MaterialTile tile = read_material_tile(a.tile);
  sec["read_tile"] = t.seconds();
  t = Timer();
  Mesh mesh;
  rep["input_mesh"] = to_json(load_method_mesh(a.mesh, mesh, a.common));
  require_triangle_mesh(mesh, "material-map");
  sec["read_mesh"] = t.seconds();
  rep["vertices"] = mesh.number_of_vertices();
  rep["faces"] = mesh.number_of_faces();

  // The curl correction of the PGP's target (pgp_curl_correction.h); an
  // update keeps the one its state was solved with.
  nlohmann::json state;
  if (!a.update.empty()) state = read_state(a.state);
  PgpOptions popt;
  popt.curl_correction = a.update.empty() ? a.curl_correction : state_curl_correction(state);
  rep["curl_correction"] = popt.curl_correction;
  // The paper's simplified PGP (no swapping of s and t, section 2.3) or the
  // coupled form; an update keeps the state's (its z are in that form's frames).
  popt.swap_coordinates = a.update.empty() ? !a.no_swap : state_swap_coordinates(state);
  rep["swap_coordinates"] = popt.swap_coordinates;
  PeriodicGlobalParameterization pgp(mesh, popt);
  double default_scale = 0;
  if (a.update.empty()) {
    t = Timer();
    MaterialConstraints c;
    if (!a.constraints.empty()) c = read_material_constraints(a.constraints, mesh);
    sec["read_constraints"] = t.seconds();
    t = Timer();
    std::vector<DirectionConstraint> dirs = c.directions;
    std::string field_source = "strokes";
    DirectionFieldOptions dopt;  // strokes and a constant vector: exact
    // The PGP's connectivity-only work (topology, METIS order) runs beside
    // the curvature and direction field (it reads no property map).
    double prepare_seconds = 0;
    auto field = [&] {
      if (dirs.empty()) {
        field_source = a.field;
        if (a.field == "curvature") {
          // Principal directions are noisy: the constraints are made soft by a
          // smoothing step (over ~8 face rings), which removes field
          // singularities where nearby constraints disagree; armadillo_52k:
          // 313 -> 243 field-singular vertices, singular faces 33.8% -> 28.2%
          // (bench_pgp --field-sweep; 4-ring jets would give 26.7% for ~3x
          // the curvature time).
          compute_principal_curvatures(mesh);
          dirs = constraints_from_principal_directions(mesh, 0.1);
          dopt.smoothing = 64;
        }
        if (dirs.empty()) dirs = constraints_from_constant_vector(mesh, {0.0, 1.0, 0.0});
      }
      interpolate_direction_field(mesh, dirs, dopt);
    };
    tbb::parallel_invoke(field, [&] {
      Timer tp;
      pgp.prepare();
      prepare_seconds = tp.seconds();
    });
    sec["direction_field"] = t.seconds();  // with the PGP preparation alongside
    sec["pgp_prepare"] = prepare_seconds;
    rep["field_source"] = field_source;
    rep["direction_constraints"] = dirs.size();
    t = Timer();
    default_scale = a.scale > 0 ? a.scale : pgp_default_scale(mesh, a.edges_per_period);
    interpolate_scalar_field(mesh, c.scale, scale_field_options(1e-9 * default_scale, default_scale));
    interpolate_scalar_field(mesh, c.material, material_field_options());
    sec["scalar_fields"] = t.seconds();
    t = Timer();
    pgp.initialize();
    sec["pgp"] = t.seconds();
    rep["mode"] = "initialize";
  } else {
    t = Timer();
    default_scale = load_state(state, a.state, mesh, pgp);
    sec["read_state"] = t.seconds();
    t = Timer();
    const MaterialConstraints c = read_material_constraints(a.update, mesh);
    if (c.seed_vertices.empty())
      throw InvalidInputError("--update '" + a.update + "' holds no constraint (strokes, scale or material)");
    EffectAreaOptions eo;
    eo.radius = c.effect_radius;
    const EffectArea area = compute_effect_area(mesh, c.seed_vertices, eo);
    sec["read_constraints_and_effect_area"] = t.seconds();
    rep["effect_area"] = {{"radius", std::isfinite(c.effect_radius) ? nlohmann::json(c.effect_radius) : nlohmann::json()},
                          {"faces", area.free_faces},
                          {"vertices", area.free_vertices}};
    // Orientation and scalar fields are independent (a face map, vertex
    // maps that all exist after load_state), and so is the PGP's order of
    // the area's free vertices (connectivity only): side by side.
    t = Timer();
    double direction_seconds = 0, scalar_seconds = 0;
    tbb::parallel_invoke([&] { pgp.prepare(area); }, [&] {
      Timer td;
      if (!c.directions.empty()) {
        DirectionFieldOptions dopt;
        dopt.area = &area;
        interpolate_direction_field(mesh, c.directions, dopt);
      }
      direction_seconds = td.seconds();
    }, [&] {
      Timer ts;
      if (!c.scale.empty()) {
        ScalarFieldOptions so = scale_field_options(1e-9 * default_scale, default_scale);
        so.area = &area;
        interpolate_scalar_field(mesh, c.scale, so);
      }
      if (!c.material.empty()) {
        ScalarFieldOptions so = material_field_options();
        so.area = &area;
        interpolate_scalar_field(mesh, c.material, so);
      }
      scalar_seconds = ts.seconds();
    });
    sec["direction_field"] = direction_seconds;
    sec["scalar_fields"] = scalar_seconds;
    sec["fields_wall"] = t.seconds();
    t = Timer();
    pgp.write_corners();  // the loaded mesh has no corners yet; those outside the area stay as written now
    pgp.update(area);
    sec["pgp"] = t.seconds();
    rep["mode"] = "update";
  }
  rep["default_scale"] = default_scale;

  t = Timer();
  PgpSingularityOptions sopt;
  sopt.pgp = popt;
  const PgpSingularities sing = detect_pgp_singularities(mesh, sopt);
  sec["singularities"] = t.seconds();
  std::size_t distorted = 0, mismatched = 0, sv = 0;
  for (char x : sing.distorted_face) distorted += x;
  for (char x : sing.mismatched_edge) mismatched += x;
  for (char x : sing.singular_vertex) sv += x;
  rep["singular_fraction"] = sing.singular_fraction;
  rep["singular_faces"] = sing.singular_faces;
  rep["distorted_faces"] = distorted;
  rep["mismatched_edges"] = mismatched;
  rep["singular_vertices"] = sv;
  rep["fidelity"] = material_map_fidelity_report(mesh, sing.corners, tile, a.common.seed);  // issue 18 item 3

  ensure_directory(a.out);
  t = Timer();
  write_meshes(mesh, a.out, a.common.force);
  sec["write_meshes"] = t.seconds();
  t = Timer();
  const Outputs img = render_all(mesh, sing, tile, a.render_size, a.view, a.bump);
  sec["render"] = t.seconds();
  WriteImageOptions io;
  io.overwrite = a.common.force;
  write_image(a.out + "/render_plain.png", img.plain, io);
  write_image(a.out + "/render_fixed.png", img.fixed, io);
  write_image(a.out + "/render_normalmap.png", img.normal, io);
  save_state(a.out + "/state.json", mesh, pgp, default_scale, popt.curl_correction, popt.swap_coordinates,
             a.common.force);
  sec["total"] = total.seconds();
  rep["seconds"] = sec;
  rep["tile"] = {{"dir", a.tile}, {"layers", tile.layers.size()}, {"size", tile.size}};
  rep["mesh"] = a.mesh;
  nlohmann::json full = rep;
  full["command"] = "material-map";
  full["seed"] = a.common.seed;
  write_file_atomic(a.out + "/report.json", full.dump(2) + "\n", a.common.force);
  write_report(a.common, "material-map", rep);
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
                      "geometry/material_constraints.h). Default: none (field from --field, constant scale, m = 0)");
       app.add_option("--update", a->update,
                      "New constraints JSON applied to the state given by --state: only the effect area "
                      "(effect_radius around them) is re-solved; the rest stays bit for bit");
       app.add_option("--state", a->state, "state.json of a previous run (with --update)");
       app.add_option("-o,--output", a->out,
                      "Output folder: mesh.obj (UV = (s,t)), mesh.glb and mesh.ply (material as vertex scalar), "
                      "render_plain.png, render_fixed.png, render_normalmap.png, report.json, state.json")
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
                      "faces, smoothed) or constant (world +Y projected); default curvature")
           ->check(CLI::IsMember({"curvature", "constant"}));
       app.add_option("--render-size", a->render_size, "Side of the renders in pixels (16..4096, default 768)")
           ->check(CLI::Range(16, 4096));
       app.add_option("--view", a->view, "Render view: azimuth elevation in degrees (default 30 20)")->expected(2);
       app.add_option("--bump", a->bump, "Normal-map strength: tilt per unit height slope (0..10, default 0.03)")
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
  Timer timer;
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
  const MaterialTile tile = read_material_tile(tile_dir);

  Mesh mesh;
  make_torus(mesh, 1.0, 0.4, 96, 40);
  // A stroke along the big circle on top, and a material gradient from one side to the other.
  std::vector<DirectionConstraint> dirs;
  for (FaceIndex f : mesh.faces()) {
    Vector3 c(0, 0, 0);
    for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) c = c + (mesh.point(v) - CGAL::ORIGIN) / 3.0;
    if (c.z() > 0.35 && f.idx() % 7 == 0) dirs.push_back({static_cast<std::uint32_t>(f.idx()), {-c.y(), c.x(), 0.0}});
  }
  interpolate_direction_field(mesh, dirs);
  const double S = pgp_default_scale(mesh, 6);
  interpolate_scalar_field(mesh, {}, scale_field_options(1e-9, S));
  std::vector<ScalarConstraint> mat;
  for (VertexIndex v : mesh.vertices()) {
    if (mesh.point(v).x() < -1.2) mat.push_back({static_cast<std::uint32_t>(v.idx()), 0.0});
    if (mesh.point(v).x() > 1.2) mat.push_back({static_cast<std::uint32_t>(v.idx()), 1.0});
  }
  interpolate_scalar_field(mesh, mat, material_field_options());
  periodic_global_parameterization(mesh);
  const PgpSingularities sing = detect_pgp_singularities(mesh);
  write_meshes(mesh, ctx.dir, true);
  fs::rename(ctx.path("mesh.obj"), ctx.path("material_map.obj"));
  fs::rename(ctx.path("mesh.glb"), ctx.path("material_map.glb"));
  fs::rename(ctx.path("mesh.ply"), ctx.path("material_map.ply"));
  std::error_code ec;
  if (fs::exists(ctx.path("mesh.png"), ec)) fs::remove(ctx.path("mesh.png"), ec);
  const Outputs img = render_all(mesh, sing, tile, 384, {20.f, 45.f}, 0.03);
  write_image(ctx.path("material_map_plain.png"), img.plain);
  write_image(ctx.path("material_map_fixed.png"), img.fixed);
  write_image(ctx.path("material_map_normalmap.png"), img.normal);
  return {{"faces", mesh.number_of_faces()},
          {"tile_layers", tile.layers.size()},
          {"singular_fraction", sing.singular_fraction},
          {"seconds", timer.seconds()},
          {"files",
           {"material_tile/", "material_map.obj", "material_map.glb", "material_map.ply", "material_map_plain.png",
            "material_map_fixed.png", "material_map_normalmap.png"}}};
}

DemoStepRegistrar demo_reg{{40, "material-map",
                            "a 4-layer noise-to-cells material tile mapped on a torus with a stroke and a material gradient",
                            demo_material_map}};

}  // namespace
}  // namespace surftex::cli
