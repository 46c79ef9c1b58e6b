// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark of the material-space mapping steps (Ray et al. 2009, Table 1):
// orientation interpolation, PGP initialisation and a local constraint update
// over ~25% of the triangles, on real meshes of ~11K, ~24K and ~50K triangles.
// Best of 3 runs; one JSON line per mesh and step.
// Usage: bench_pgp [mesh ...]   (default: shared data fandisk, dragon_25k, armadillo_52k)
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "geometry/direction_field.h"
#include "geometry/effect_area.h"
#include "geometry/mesh.h"
#include "geometry/periodic_global_parameterization.h"
#include "geometry/pgp_singularities.h"
#include "geometry/principal_curvatures.h"
#include "geometry/read_mesh.h"
#include "geometry/scalar_field_interpolation.h"
#include "geometry/timer.h"

using namespace surftex;

namespace {

double best_of_3(const std::function<void()>& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    Timer t;
    f();
    best = std::min(best, t.seconds());
  }
  return best;
}

void emit(const std::string& mesh, std::size_t faces, const std::string& step, double s,
          nlohmann::json extra = nlohmann::json::object()) {
  extra["bench"] = "pgp";
  extra["mesh"] = mesh;
  extra["faces"] = faces;
  extra["step"] = step;
  extra["seconds"] = s;
  std::cout << extra.dump() << std::endl;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> meshes;
  for (int i = 1; i < argc; ++i) meshes.push_back(argv[i]);
  if (meshes.empty()) {
    const std::string d = std::string(SURFTEX_SHARED_DATA_DIR) + "/meshes/";
    meshes = {d + "fandisk.off", d + "dragon_25k.off", d + "armadillo_52k.off"};
  }
  for (const std::string& path : meshes) {
    Mesh mesh;
    read_mesh(path, mesh);
    const std::size_t nf = mesh.number_of_faces();
    const std::string name = path.substr(path.find_last_of('/') + 1);

    // Sparse strokes: 20 faces spread over the mesh with a projected direction.
    std::vector<DirectionConstraint> strokes;
    for (std::size_t i = 0; i < 20; ++i)
      strokes.push_back({static_cast<std::uint32_t>(i * nf / 20), {1.0, 0.3, 0.2}});
    emit(name, nf, "principal_curvatures",
         best_of_3([&] { compute_principal_curvatures(mesh); }));
    std::vector<DirectionConstraint> curv = constraints_from_principal_directions(mesh, 0.05);
    emit(name, nf, "interpolate_orientation",
         best_of_3([&] { interpolate_direction_field(mesh, strokes, {}); }),
         {{"constraints", strokes.size()}});
    emit(name, nf, "interpolate_orientation_from_curvature",
         best_of_3([&] { interpolate_direction_field(mesh, curv, {}); }),
         {{"constraints", curv.size()}});
    interpolate_scalar_field(mesh, {{0, 1.0}}, scale_field_options());
    // Scale: 40 periods across the bounding box diagonal.
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (VertexIndex v : mesh.vertices())
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], mesh.point(v)[k]);
        hi[k] = std::max(hi[k], mesh.point(v)[k]);
      }
    const double diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                  (hi[2] - lo[2]) * (hi[2] - lo[2]));
    interpolate_scalar_field(mesh, {{0, diag / 40}}, scale_field_options());
    interpolate_scalar_field(mesh, {{0, 0.0}, {static_cast<std::uint32_t>(mesh.number_of_vertices() / 2), 1.0}},
                             material_field_options());
    PeriodicGlobalParameterization pgp(mesh);
    emit(name, nf, "pgp_initialize", best_of_3([&] { pgp.initialize(); }));
    PgpSingularities sing;
    const double t_sing = best_of_3([&] { sing = detect_pgp_singularities(mesh); });
    emit(name, nf, "detect_singularities", t_sing, {{"singular_fraction", sing.singular_fraction}});

    // Local update: effect area of 25% of the faces around a vertex.
    EffectAreaOptions eo;
    eo.max_faces = nf / 4;
    const std::uint32_t seed = static_cast<std::uint32_t>(mesh.number_of_vertices() / 3);
    EffectArea area;
    const double t_area = best_of_3([&] { area = compute_effect_area(mesh, {seed}, eo); });
    emit(name, nf, "effect_area", t_area, {{"area_faces", area.free_faces}});
    const std::uint32_t cf = static_cast<std::uint32_t>(mesh.face(mesh.halfedge(VertexIndex(seed))).idx());
    DirectionFieldOptions dopt;
    dopt.area = &area;
    ScalarFieldOptions sopt = scale_field_options();
    sopt.area = &area;
    double t_dir = 0, t_scale = 0, t_pgp = 0;
    PgpResult last;
    t_dir = best_of_3([&] { interpolate_direction_field(mesh, {{cf, {0.0, 1.0, 1.0}}}, dopt); });
    t_scale = best_of_3([&] { interpolate_scalar_field(mesh, {{seed, diag / 60}}, sopt); });
    t_pgp = best_of_3([&] { last = pgp.update(area); });
    emit(name, nf, "local_update_orientation", t_dir, {{"area_faces", area.free_faces}});
    emit(name, nf, "local_update_scale", t_scale, {{"area_faces", area.free_faces}});
    emit(name, nf, "local_update_pgp", t_pgp,
         {{"area_faces", area.free_faces}, {"reused_analysis", last.reused_analysis}});
    emit(name, nf, "local_update_total", t_dir + t_scale + t_pgp, {{"area_faces", area.free_faces}});
  }
  return 0;
}
