// SPDX-License-Identifier: AGPL-3.0-or-later
// The material-space mapping driver (Ray et al. 2009, sections 2-3; see material_mapping.h).
#include "texture/material_space/material_mapping.h"

#include <tbb/parallel_invoke.h>

#include <cmath>
#include <complex>
#include <fstream>
#include <sstream>

#include "geometry/direction_field.h"
#include "geometry/effect_area.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "texture/material_space/periodic_global_parameterization.h"
#include "geometry/principal_curvatures.h"
#include "geometry/properties.h"
#include "geometry/scalar_field_interpolation.h"
#include "geometry/timer.h"

namespace surftex {

namespace {

using Cplx = std::complex<double>;

// Version 2: z_s, z_t are stored in per-vertex frames (s/t coupled across
// field cuts); version-1 states (independent s and t) are refused.
// "swap_coordinates": false when solved with the paper's simplified PGP (no
// frames, every corner turn 0); absent = true.
const char* const kStateFormat = "surftex material-map state v2";

void check_options(const MaterialMappingOptions& o) {
  if (!(o.scale >= 0) || !std::isfinite(o.scale))
    throw InvalidInputError("material mapping: scale must be >= 0 (0 = automatic), got " + std::to_string(o.scale));
  if (!(o.edges_per_period >= 1 && o.edges_per_period <= 1000))
    throw InvalidInputError("material mapping: edges_per_period must be in [1, 1000], got " +
                            std::to_string(o.edges_per_period));
  if (!(o.curvature_fraction > 0 && o.curvature_fraction <= 1))
    throw InvalidInputError("material mapping: curvature_fraction must be in (0, 1], got " +
                            std::to_string(o.curvature_fraction));
  if (!(o.curvature_smoothing >= 0) || !std::isfinite(o.curvature_smoothing))
    throw InvalidInputError("material mapping: curvature_smoothing must be >= 0, got " +
                            std::to_string(o.curvature_smoothing));
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

nlohmann::json read_state_json(const std::string& path) {
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

bool json_bool(const nlohmann::json& j, const char* key, bool absent) {
  auto it = j.find(key);
  return it == j.end() || !it->is_boolean() ? absent : it->get<bool>();
}

}  // namespace

nlohmann::json to_json(const MaterialMappingResult& r) {
  nlohmann::json j;
  j["mode"] = r.mode;
  if (r.mode == "initialize") {
    j["field_source"] = r.field_source;
    j["direction_constraints"] = r.direction_constraints;
  } else {
    j["effect_area"] = {{"radius", std::isfinite(r.effect_radius) ? nlohmann::json(r.effect_radius) : nlohmann::json()},
                        {"faces", r.effect_faces},
                        {"vertices", r.effect_vertices}};
  }
  j["default_scale"] = r.default_scale;
  j["curl_correction"] = r.curl_correction;
  j["swap_coordinates"] = r.swap_coordinates;
  const PgpSingularities& s = r.singularities;
  std::size_t distorted = 0, mismatched = 0, sv = 0;
  for (char x : s.distorted_face) distorted += x;
  for (char x : s.mismatched_edge) mismatched += x;
  for (char x : s.singular_vertex) sv += x;
  j["singular_fraction"] = s.singular_fraction;
  j["singular_faces"] = s.singular_faces;
  j["distorted_faces"] = distorted;
  j["mismatched_edges"] = mismatched;
  j["singular_vertices"] = sv;
  j["seconds"] = r.seconds;
  return j;
}

MaterialMapping::MaterialMapping(Mesh& mesh, const MaterialMappingOptions& options)
    : mesh_(mesh), options_(options) {
  check_options(options_);
  for (FaceIndex f : mesh_.faces())
    if (mesh_.degree(f) != 3)
      throw InvalidInputError("material mapping: face " + std::to_string(f.idx()) + " is not a triangle");
}

MaterialMapping::~MaterialMapping() = default;

void MaterialMapping::make_solver() {
  PgpOptions popt;
  popt.curl_correction = options_.curl_correction;
  popt.swap_coordinates = options_.swap_coordinates;
  pgp_ = std::make_unique<PeriodicGlobalParameterization>(mesh_, popt);
  result_.curl_correction = popt.curl_correction;
  result_.swap_coordinates = popt.swap_coordinates;
}

void MaterialMapping::detect_singularities() {
  Timer t;
  PgpSingularityOptions sopt;
  sopt.pgp.curl_correction = options_.curl_correction;
  sopt.pgp.swap_coordinates = options_.swap_coordinates;
  result_.singularities = detect_pgp_singularities(mesh_, sopt);
  result_.seconds["singularities"] = t.seconds();
}

// Section 2.2 then 2.3 over the whole mesh.
const MaterialMappingResult& MaterialMapping::map(const MaterialConstraints& c) {
  result_ = MaterialMappingResult();
  make_solver();
  result_.mode = "initialize";
  Timer t;
  std::vector<DirectionConstraint> dirs = c.directions;
  result_.field_source = "strokes";
  DirectionFieldOptions dopt;  // strokes and a constant vector: exact
  double prepare_seconds = 0;
  auto field = [&] {
    if (dirs.empty()) {
      const bool curvature = options_.field == MaterialMappingOptions::Field::Curvature;
      result_.field_source = curvature ? "curvature" : "constant";
      if (curvature) {
        // Principal directions are noisy: the constraints are made soft by a
        // smoothing step, which removes field singularities where nearby
        // constraints disagree (docs/decisions: bench_pgp --field-sweep).
        compute_principal_curvatures(mesh_);
        dirs = constraints_from_principal_directions(mesh_, options_.curvature_fraction);
        dopt.smoothing = options_.curvature_smoothing;
      }
      if (dirs.empty()) dirs = constraints_from_constant_vector(mesh_, {0.0, 1.0, 0.0});
    }
    interpolate_direction_field(mesh_, dirs, dopt);
  };
  // The PGP's connectivity-only work (topology, METIS order) runs beside the
  // curvature and direction field (it reads no property map).
  tbb::parallel_invoke(field, [&] {
    Timer tp;
    pgp_->prepare();
    prepare_seconds = tp.seconds();
  });
  result_.seconds["direction_field"] = t.seconds();  // with the PGP preparation alongside
  result_.seconds["pgp_prepare"] = prepare_seconds;
  result_.direction_constraints = dirs.size();
  t.reset();
  result_.default_scale =
      options_.scale > 0 ? options_.scale : pgp_default_scale(mesh_, options_.edges_per_period);
  interpolate_scalar_field(mesh_, c.scale, scale_field_options(1e-9 * result_.default_scale, result_.default_scale));
  interpolate_scalar_field(mesh_, c.material, material_field_options());
  result_.seconds["scalar_fields"] = t.seconds();
  t.reset();
  pgp_->initialize();
  result_.seconds["pgp"] = t.seconds();
  solved_ = true;
  detect_singularities();
  return result_;
}

// Section 2.1: the effect area, then 2.2 and 2.3 restricted to it.
const MaterialMappingResult& MaterialMapping::update(const MaterialConstraints& c) {
  if (!solved_) throw InvalidInputError("material mapping: update() needs map() or load_state() first");
  if (c.seed_vertices.empty())
    throw InvalidInputError("material mapping: the update holds no constraint (strokes, scale or material)");
  result_.mode = "update";
  result_.seconds.clear();
  Timer t;
  EffectAreaOptions eo;
  eo.radius = c.effect_radius;
  const EffectArea area = compute_effect_area(mesh_, c.seed_vertices, eo);
  result_.seconds["effect_area"] = t.seconds();
  result_.effect_radius = c.effect_radius;
  result_.effect_faces = area.free_faces;
  result_.effect_vertices = area.free_vertices;
  // Orientation and scalar fields are independent (a face map, vertex maps),
  // and so is the PGP's order of the area's free vertices: side by side.
  t.reset();
  double direction_seconds = 0, scalar_seconds = 0;
  const double S = result_.default_scale;
  tbb::parallel_invoke([&] { pgp_->prepare(area); }, [&] {
    Timer td;
    if (!c.directions.empty()) {
      DirectionFieldOptions dopt;
      dopt.area = &area;
      interpolate_direction_field(mesh_, c.directions, dopt);
    }
    direction_seconds = td.seconds();
  }, [&] {
    Timer ts;
    if (!c.scale.empty()) {
      ScalarFieldOptions so = scale_field_options(1e-9 * S, S);
      so.area = &area;
      interpolate_scalar_field(mesh_, c.scale, so);
    }
    if (!c.material.empty()) {
      ScalarFieldOptions so = material_field_options();
      so.area = &area;
      interpolate_scalar_field(mesh_, c.material, so);
    }
    scalar_seconds = ts.seconds();
  });
  result_.seconds["direction_field"] = direction_seconds;
  result_.seconds["scalar_fields"] = scalar_seconds;
  result_.seconds["fields_wall"] = t.seconds();
  t.reset();
  pgp_->update(area);
  result_.seconds["pgp"] = t.seconds();
  detect_singularities();
  return result_;
}

void MaterialMapping::save_state(const std::string& path, bool overwrite) const {
  if (!solved_) throw InvalidInputError("material mapping: save_state() needs map() or load_state() first");
  nlohmann::json j;
  j["format"] = kStateFormat;
  j["curl_correction"] = options_.curl_correction;
  j["swap_coordinates"] = options_.swap_coordinates;
  j["vertices"] = mesh_.num_vertices();
  j["faces"] = mesh_.num_faces();
  j["default_scale"] = result_.default_scale;
  auto dir = find(mesh_, kFaceDirection).first;
  auto sc = find(mesh_, kVertexScale).first;
  auto mat = find(mesh_, kVertexMaterial).first;
  std::vector<double> zs, zt, d, s, m;
  for (std::size_t i = 0; i < mesh_.num_vertices(); ++i) {
    zs.push_back(pgp_->z_s()[i].real());
    zs.push_back(pgp_->z_s()[i].imag());
    zt.push_back(pgp_->z_t()[i].real());
    zt.push_back(pgp_->z_t()[i].imag());
    s.push_back(sc[VertexIndex(static_cast<std::uint32_t>(i))]);
    m.push_back(mat[VertexIndex(static_cast<std::uint32_t>(i))]);
  }
  for (std::size_t i = 0; i < mesh_.num_faces(); ++i) {
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

void MaterialMapping::load_state(const std::string& path) {
  Timer t;
  const nlohmann::json j = read_state_json(path);
  // The state's PGP variant: its z are in that variant's frames. States
  // written before the options existed were solved without the curl
  // correction and with s and t coupled.
  options_.curl_correction = json_bool(j, "curl_correction", false);
  options_.swap_coordinates = json_bool(j, "swap_coordinates", true);
  const std::size_t nv = mesh_.num_vertices(), nf = mesh_.num_faces();
  const auto zs = state_array(j, "z_s", 2 * nv, path), zt = state_array(j, "z_t", 2 * nv, path);
  const auto d = state_array(j, "direction", 3 * nf, path);
  const auto s = state_array(j, "scale", nv, path), m = state_array(j, "material", nv, path);
  result_ = MaterialMappingResult();
  make_solver();
  auto dir = get_or_add(mesh_, kFaceDirection, Vector3(1, 0, 0));
  auto sc = get_or_add(mesh_, kVertexScale, 1.0);
  auto mat = get_or_add(mesh_, kVertexMaterial, 0.0);
  std::vector<Cplx> zsv(nv), ztv(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    zsv[i] = Cplx(zs[2 * i], zs[2 * i + 1]);
    ztv[i] = Cplx(zt[2 * i], zt[2 * i + 1]);
    sc[VertexIndex(static_cast<std::uint32_t>(i))] = s[i];
    mat[VertexIndex(static_cast<std::uint32_t>(i))] = m[i];
  }
  for (std::size_t i = 0; i < nf; ++i)
    dir[FaceIndex(static_cast<std::uint32_t>(i))] = Vector3(d[3 * i], d[3 * i + 1], d[3 * i + 2]);
  pgp_->set_state(std::move(zsv), std::move(ztv));
  pgp_->write_corners();  // the loaded mesh has no corners yet
  result_.default_scale = j.value("default_scale", 0.0);
  result_.mode = "loaded";
  result_.seconds["read_state"] = t.seconds();
  solved_ = true;
}

}  // namespace surftex
