// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark of mesh quilting over curved surfaces (Zhou et al. 2006, section
// 3; issue 17): 3 meshes of ../shared/data (bunny_6k: +Y up; koala: thin ears
// and limbs; knot: genus 1) x 4 swatches (the generated weave, chain mail and
// 16 tilted tori, disjoint elements; the real pebble swatches/rock_1.obj), each
// quilted and embedded by the CLI's driver (quilt_swatch_on_surface) at the
// CLI's defaults (relative size default_surface_quilt_size: 0.25, the weave
// 0.125, the single rock 0.0468; up +Y, shell height 1, 20 stretch sweeps, seed 1; the swatch's
// thin axis detected).
// Prints one JSON line per case:
//   faces, elements (the output's connected components) and quilt_elements
//   (the quilt's own count); intersecting face pairs between / within elements
//   (exact CGAL count on the embedded mesh) and as fractions of the faces;
//   edge_max_over_median (longest output edge / median output edge; goal <= 4;
//   edge_longest: that edge, mesh units)
//   and edge_stretch_max (longest element edge over the same edge where it
//   was placed, SurfaceQuiltResult::edge_stretch_max); stretch_before/after
//   (shell map, eq. 9); bare area overall and in 4 bands of height along +Y
//   (output_bare_area, the report's: base area with no output vertex's foot
//   within half the swatch's element spacing: the median distance from an
//   element's centroid to the nearest other's; the swatch's larger side for a
//   single element; bare_quilt: the quilt's before the embedding); the nearest-gap
//   ratio (per output element the smallest vertex distance to another element,
//   its min and median over the elements divided by the median of the same
//   over the swatch's elements, scaled); seconds (quilt, embed, total) and user
//   CPU seconds.
// Usage: bench_quilt [CASE ...] [--out DIR]
//   CASE = mesh:swatch (e.g. bunny:weave; meshes bunny, koala, knot or a file name of shared/data/meshes such as elephant.off; swatches
//   weave, chainmail, tori, rock or a file name of shared/data/swatches such as wingnut.obj) or bunny5k (the issue 8 benchmark: CGAL's
//   bunny00.off decimated to about 5K faces, weave at relative size 0.12; goals
//   <= 60 s and stretch <= 1.05). No CASE: the 12 cases of the matrix.
//   --out DIR: writes DIR/<case>.glb and DIR/<case>.png (base + quilt).
//   --old-defaults: the CLI's defaults and the method before issue 17 (up +Z,
//   the swatch's z taken as its thin axis, crossings not resolved, no refill,
//   the stretch bound at 12), for before/after tables.
//   Environment overrides for experiments (each sets one option of
//   SurfaceQuiltOptions / QuiltSwatchOnSurfaceOptions; unset = the default):
//   BENCH_SEED, BENCH_RELATIVE_SIZE, BENCH_MAX_EDGE_STRETCH, BENCH_THREAD_STRETCH, BENCH_REFILL_ROUNDS,
//   BENCH_SCATTER (attempts), BENCH_SCATTER_STRETCH, BENCH_SCATTER_CONE,
//   BENCH_SCATTER_ONLY (scatter_swatch_elements; 0: always quilt), BENCH_SCATTER_PASSES, BENCH_SCATTER_CLEARANCE,
//   BENCH_SCATTER_SKIP (scatter_skip_near_failed),
//   BENCH_SHAPE, BENCH_RINGS, BENCH_PIECES, BENCH_LOOP_GAP (blob_loop_gap),
//   BENCH_LIFT_RINGS (lift_crossing_rings), BENCH_RESOLVE, BENCH_TRIM_NEW, BENCH_PUSH, BENCH_CLEARANCE, BENCH_KEEP_CUT,
//   BENCH_RECENTRE (the embedding's recentre_caps), BENCH_EMBED_RESOLVE=0 (no crossing
//   resolution after the shell map), BENCH_EMBED_FILL=0 (no fill of the embedded quilt's bare faces;
//   BENCH_FILL_ATTEMPTS, BENCH_FILL_CONE its tries and normal cone), BENCH_UNTANGLE=0 (folded threads cut, not smoothed out), BENCH_EDGE_MEDIANS (the
//   embedding's max_edge_over_median; 0 = none), BENCH_RELAX=0 (stretched elements cut, not relaxed), BENCH_STRETCH_ITERS (the
//   shell map's sweeps); BENCH_LIFTED=1 also writes DIR/<case>_lifted.glb (the
//   quilt before the shell map: feet on the base, height along face normals)
//   and prints its crossings within elements and its bare area (lifted_bare).
// The history of the old single-case benchmark is docs/decisions/100-quilt-bench-history.md.
#include <CGAL/number_utils.h>  // CGAL 5.5's Bounded_normal_change_placement.h uses is_positive unqualified
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_placement.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/LindstromTurk_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <unordered_map>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/load_input_mesh.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/render_view.h"
#include "geometry/self_intersections.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "geometry/vec3.h"
#include "shell/quilting/foot_grid.h"
#include "shell/quilting/quilt_driver.h"
#include "shell/quilting/quilt_json.h"
#include "shell/swatch.h"
#include "shell/swatch_generators.h"

using namespace surftex;
using json = nlohmann::json;
namespace fs = std::filesystem;
namespace SMS = CGAL::Surface_mesh_simplification;

namespace {

double user_cpu() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec) + 1e-6 * static_cast<double>(u.ru_utime.tv_usec);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Per element of (points, element id per point): the smallest distance to a
// point of another element, capped at `limit`.
std::vector<double> nearest_gaps(const std::vector<P3>& pts, const std::vector<int>& elem, int n, double limit) {
  CellGrid<int> g(limit);
  for (std::size_t i = 0; i < pts.size(); ++i) g.add(pts[i], elem[i]);
  std::vector<double> gap(static_cast<std::size_t>(n), limit);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    double best = gap[static_cast<std::size_t>(elem[i])];
    best *= best;
    g.any_near(pts[i], [&](const P3& q, int tag) {
      if (tag != elem[i]) best = std::min(best, vec3::dot(vec3::sub(pts[i], q), vec3::sub(pts[i], q)));
      return false;
    });
    double& e = gap[static_cast<std::size_t>(elem[i])];
    e = std::min(e, std::sqrt(best));
  }
  return gap;
}

Mesh make_named_swatch(const std::string& kind) {
  Mesh sm;
  if (kind == "weave") make_weave_swatch(sm);
  else if (kind == "chainmail") make_chainmail_swatch(sm);
  else if (kind == "tori") make_tori_swatch(sm);
  else if (kind == "rock") read_mesh(std::string(SURFTEX_SHARED_DATA_DIR) + "/swatches/rock_1.obj", sm);
  else if (kind.find('.') != std::string::npos)  // any other swatch of shared/data/swatches, by file name
    read_mesh(std::string(SURFTEX_SHARED_DATA_DIR) + "/swatches/" + kind, sm);
  else throw InvalidInputError("bench_quilt: unknown swatch '" + kind + "' (weave, chainmail, tori, rock or a file of shared/data/swatches)");
  return sm;
}

std::string mesh_file(const std::string& name) {
  const std::string d = std::string(SURFTEX_SHARED_DATA_DIR) + "/meshes/";
  if (name == "bunny") return d + "bunny_6k.obj";
  if (name == "koala") return d + "koala.obj";
  if (name == "knot") return d + "knot.off";
  if (name.find('.') != std::string::npos) return d + name;  // any other mesh of shared/data/meshes, by file name
  throw InvalidInputError("bench_quilt: unknown mesh '" + name + "' (bunny, koala, knot or a file of " + d + ")");
}

// CGAL's bunny00.off decimated to about 5K faces (the issue 8 benchmark's base).
void bunny5k(Mesh& base) {
  const fs::path dir = fs::temp_directory_path() / ("surftex-bench-quilt-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string cmd = std::string("tar xzf '") + SURFTEX_CGAL_DATA_TARBALL + "' -C '" + dir.string() + "' data/meshes/bunny00.off";
  if (std::system(cmd.c_str()) != 0) throw IOError("cannot extract bunny00.off from " SURFTEX_CGAL_DATA_TARBALL);
  read_mesh((dir / "data" / "meshes" / "bunny00.off").string(), base);
  fs::remove_all(dir);
  SMS::Count_stop_predicate<Mesh> stop(7500);  // edges: E = 1.5 F on a closed mesh
  const SMS::Bounded_normal_change_placement<SMS::LindstromTurk_placement<Mesh>> placement;
  SMS::edge_collapse(base, stop, CGAL::parameters::get_cost(SMS::LindstromTurk_cost<Mesh>()).get_placement(placement));
  base.collect_garbage();
}

// Edge lengths of the embedded mesh: longest over median.
double edge_max_over_median(const Mesh& m, double& longest) {
  std::vector<double> len;
  len.reserve(m.number_of_edges());
  for (EdgeIndex e : m.edges()) len.push_back(std::sqrt(CGAL::squared_distance(m.point(m.source(m.halfedge(e))), m.point(m.target(m.halfedge(e))))));
  longest = len.empty() ? 0 : *std::max_element(len.begin(), len.end());
  const double med = median(len);
  return med > 0 ? longest / med : 0;
}

// The nearest-gap ratio (see the header): {min, median} of the output's
// element gaps over the median of the swatch's (scaled), and the swatch's own.
json gap_ratio(const Mesh& out, const Swatch& s, double scale, double spacing) {
  const double limit = spacing * scale;
  std::vector<double> sg;
  {
    std::vector<P3> pts = s.mesh.points;
    for (P3& p : pts) p = {p[0] * scale, p[1] * scale, p[2] * scale};
    std::vector<int> elem(pts.size(), 0);
    for (std::size_t t = 0; t < s.mesh.tris.size(); ++t)
      for (int v : s.mesh.tris[t]) elem[static_cast<std::size_t>(v)] = s.face_element[t];
    sg = nearest_gaps(pts, elem, static_cast<int>(s.elements.size()), limit);
  }
  Mesh m = out;
  const int n = label_elements(m);
  auto fe = find(m, kFaceElement).first;
  std::vector<P3> pts;
  std::vector<int> elem;
  std::vector<int> vid(m.number_of_vertices(), -1);
  for (FaceIndex f : m.faces())
    for (VertexIndex v : m.vertices_around_face(m.halfedge(f)))
      if (vid[v.idx()] < 0) {
        vid[v.idx()] = static_cast<int>(pts.size());
        const Point3& p = m.point(v);
        pts.push_back({p.x(), p.y(), p.z()});
        elem.push_back(fe[f]);
      }
  const std::vector<double> og = nearest_gaps(pts, elem, n, limit);
  const double smed = median(sg);
  const double smin = sg.empty() ? 0 : *std::min_element(sg.begin(), sg.end());
  const double omin = og.empty() ? 0 : *std::min_element(og.begin(), og.end());
  return {{"min", smed > 0 ? omin / smed : 0.0}, {"median", smed > 0 ? median(og) / smed : 0.0},
          {"swatch_min", smed > 0 ? smin / smed : 0.0}, {"elements", n}};
}

// --old-defaults: the CLI's defaults before issue 17 (up +Z, the swatch's z
// taken as its thin axis), for the "before" table.
bool g_old_defaults = false;

json run_case(const std::string& name, const std::string& outdir) {
  const double cpu0 = user_cpu();
  Timer total;
  Mesh base;
  std::string mesh_name, kind;
  double rel = 0;  // the CLI's default (default_surface_quilt_size)
  if (name == "bunny5k") {
    bunny5k(base);
    mesh_name = "bunny5k", kind = "weave", rel = 0.12;
  } else {
    const auto colon = name.find(':');
    if (colon == std::string::npos) throw InvalidInputError("bench_quilt: a case is mesh:swatch (got '" + name + "')");
    mesh_name = name.substr(0, colon), kind = name.substr(colon + 1);
    load_input_mesh(mesh_file(mesh_name), base);
    base.collect_garbage();
  }
  QuiltSwatchOnSurfaceOptions o;
  o.swatch_up = g_old_defaults ? SwatchAxis::kZ : SwatchAxis::kAuto;
  o.mesh_name = mesh_name;
  SurfaceQuiltOptions& qo = o.quilt;
  qo.relative_size = rel;
  if (g_old_defaults) {
    qo.up = {0, 0, 1};
    qo.step.resolve_crossings = false;
    qo.resolve_crossings = false;
    qo.refill_rounds = 0;
    qo.scatter_attempts = 0;
    qo.max_shape_ratio = 0;
    qo.remove_broken_rings = false;
    qo.min_piece_fraction = 0;
    qo.max_edge_stretch = 12;
  }
  // Experiments (not the benchmark's figures; listed in the header). BENCH_RELATIVE_SIZE 0 = the default size,
  // BENCH_CLEARANCE in swatch units (negative = automatic), BENCH_SEED the run's seed (default 1).
  if (const char* e = std::getenv("BENCH_RELATIVE_SIZE")) qo.relative_size = std::atof(e);
  if (const char* e = std::getenv("BENCH_MAX_EDGE_STRETCH")) qo.max_edge_stretch = std::atof(e);
  if (const char* e = std::getenv("BENCH_THREAD_STRETCH")) qo.max_thread_stretch = std::atof(e);
  if (const char* e = std::getenv("BENCH_REFILL_ROUNDS")) qo.refill_rounds = std::atoi(e);
  if (const char* e = std::getenv("BENCH_SCATTER")) qo.scatter_attempts = std::atoi(e);
  if (const char* e = std::getenv("BENCH_SCATTER_BARE")) qo.scatter_bare_samples = std::atoi(e);
  if (const char* e = std::getenv("BENCH_THREAD_PARTS")) qo.scatter_thread_parts = std::atoi(e);
  if (const char* e = std::getenv("BENCH_SCATTER_STRETCH")) qo.scatter_max_stretch = std::atof(e);
  if (const char* e = std::getenv("BENCH_SCATTER_CONE")) qo.scatter_max_normal_angle_deg = std::atof(e);
  if (const char* e = std::getenv("BENCH_SHAPE")) qo.max_shape_ratio = std::atof(e);
  if (const char* e = std::getenv("BENCH_RINGS")) qo.remove_broken_rings = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_PIECES")) qo.min_piece_fraction = std::atof(e);
  if (const char* e = std::getenv("BENCH_LIFT_RINGS")) qo.lift_crossing_rings = std::atoi(e);
  if (const char* e = std::getenv("BENCH_RESOLVE")) qo.resolve_crossings = qo.step.resolve_crossings = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_TRIM_NEW")) qo.trim_new_to_patch = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_PUSH")) qo.step.push_over_under = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_CLEARANCE")) qo.step.clearance = std::atof(e);
  if (const char* e = std::getenv("BENCH_KEEP_CUT")) qo.step.keep_cut_refused_inputs = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_LOOP_GAP")) qo.blob_loop_gap = std::atof(e);
  if (const char* e = std::getenv("BENCH_SCATTER_ONLY")) qo.scatter_swatch_elements = std::atoi(e);
  if (const char* e = std::getenv("BENCH_SCATTER_PASSES")) qo.scatter_passes = std::atoi(e);
  if (const char* e = std::getenv("BENCH_SCATTER_CLEARANCE")) qo.scatter_clearance = std::atof(e);
  if (const char* e = std::getenv("BENCH_SCATTER_SKIP")) qo.scatter_skip_near_failed = std::atof(e);
  if (const char* e = std::getenv("BENCH_SEED")) o.seed = std::strtoull(e, nullptr, 10);
  o.embed.stretch.iterations = 20;
  if (const char* e = std::getenv("BENCH_RECENTRE")) o.embed.recentre_caps = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_STRETCH_ITERS")) o.embed.stretch.iterations = std::atoi(e);
  if (const char* e = std::getenv("BENCH_EMBED_RESOLVE")) o.embed.resolve_crossings = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_UNTANGLE")) o.embed.untangle_folds = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_EMBED_FILL")) o.fill_embedded = std::atoi(e) != 0;
  if (const char* e = std::getenv("BENCH_FILL_ATTEMPTS")) o.embed.fill.attempts = std::atoi(e);
  if (const char* e = std::getenv("BENCH_FILL_CONE")) o.embed.fill.max_normal_angle_deg = std::atof(e);
  if (const char* e = std::getenv("BENCH_EDGE_MEDIANS")) o.embed.max_edge_over_median = std::atof(e);
  if (const char* e = std::getenv("BENCH_RELAX")) o.embed.relax_stretched = std::atoi(e) != 0;
  Mesh out;
  const QuiltSwatchOnSurfaceResult run = quilt_swatch_on_surface(base, make_named_swatch(kind), out, o);
  const Swatch& s = run.swatch;
  const SurfaceQuilt& q = run.local;
  const SurfaceQuiltResult& r = run.quilt;
  const EmbedSurfaceQuiltResult& er = run.embedding;
  const double faces = static_cast<double>(out.number_of_faces());
  double longest = 0;
  const double emax = edge_max_over_median(out, longest);
  const double spacing = swatch_element_spacing(s);
  json j{{"case", name},
         {"mesh", mesh_name},
         {"swatch", kind},
         {"relative_size", run.relative_size},
         {"base_faces", base.number_of_faces()},
         {"swatch_faces", s.mesh.tris.size()},
         {"swatch_elements", s.elements.size()},
         {"swatch_up", axis_name(s.up_axis)},
         {"faces", out.number_of_faces()},
         {"quilt_elements", r.elements},
         {"pairs_between", er.self_intersections_between},
         {"pairs_within", er.self_intersections_within},
         {"between_fraction", faces > 0 ? static_cast<double>(er.self_intersections_between) / faces : 0.0},
         {"within_fraction", faces > 0 ? static_cast<double>(er.self_intersections_within) / faces : 0.0},
         {"edge_max_over_median", emax},
         {"edge_longest", longest},
         {"edge_max_over_swatch", longest / (q.scale * s.mean_edge_length)},
         {"not_expressible", r.elements_not_expressible},
         {"elements_stretched", r.elements_stretched},
         {"edge_stretch_max", r.edge_stretch_max},
         {"not_expressed", r.elements_not_expressed},
         {"crossing_hits", r.stats.crossing_hits},
         {"crossing_dropped", r.stats.crossing_dropped},
         {"crossing_trimmed", r.stats.crossing_trimmed},
         {"crossing_pushed", r.stats.crossing_pushed},
         {"crossings_resolved", r.crossings_resolved},
         {"crossings_lifted_clear", r.crossings_lifted_clear},
         {"crossing_elements_embedded", er.crossing_elements},
         {"crossing_elements_removed_last", er.crossing_elements_removed_last},
         {"elements_stretched_embedded", er.elements_stretched_embedded},
         {"embedded_edge_bound", er.embedded_edge_bound},
         {"embedded_median_edge", er.embedded_median_edge},
         {"elements_relaxed_embedded", er.elements_relaxed_embedded},
         {"caps_recentred", er.caps_recentred},
         {"elements_untangled", er.elements_untangled},
         {"elements_placed_affine", er.elements_placed_affine},
         {"fill_placed", er.fill.placed},
         {"fill_placed_smaller", er.fill.placed_smaller},
         {"fragments_removed", r.fragments_removed},
         {"dropped_new", r.dropped_new},
         {"new_trimmed", r.new_trimmed},
         {"refill_rounds", r.refill_rounds},
         {"refill_rounds_run", r.refill_rounds_run},
         {"faces_refilled", r.faces_refilled},
         {"scatter_placed", r.scatter_placed},
         {"scatter_lifted", r.scatter_lifted},
         {"elements_misshapen", r.elements_misshapen},
         {"broken_rings_removed", r.broken_rings_removed},
         {"small_pieces_removed", r.small_pieces_removed},
         {"bare_quilt", r.bare_fraction},
         {"steps", r.steps},
         {"stretch_before", er.stretch.stretch_before},
         {"stretch_after", er.stretch.stretch_after},
         {"outside_vertices", er.embed.outside},
         {"bare", {{"overall", run.bare.overall}, {"by_height", run.bare.by_height}}},
         {"gap", gap_ratio(out, s, q.scale, spacing)},
         {"user_cpu", user_cpu() - cpu0}};
  // Per-stage seconds as the CLI's report has them, with the driver's totals and the rotation search.
  j["seconds"] = to_json(r, er)["seconds"];
  j["seconds"]["quilt"] = run.seconds_quilt;
  j["seconds"]["embed"] = run.seconds_embed;
  j["seconds"]["total"] = total.seconds();
  j["seconds"]["turn"] = r.seconds_turn;
  j["elements"] = j["gap"]["elements"];
  if (!outdir.empty()) {
    std::string stem = name;
    std::replace(stem.begin(), stem.end(), ':', '_');
    write_mesh(outdir + "/" + stem + ".glb", out);
    if (std::getenv("BENCH_LIFTED")) {  // the quilt before the shell map: feet on the base, height along the normal
      Mesh lifted;
      surface_quilt_displaced(base, q, (q.z_max - q.z_min) * q.scale, lifted);
      write_mesh(outdir + "/" + stem + "_lifted.glb", lifted);
      // Its crossings within elements: made by quilting (before the shell map).
      auto el = lifted.property_map<FaceIndex, int>(kFaceElement.name).first;
      std::map<int, std::size_t> within;
      for (const FacePair& fp : self_intersecting_faces(lifted))
        if (el[FaceIndex(fp[0])] == el[FaceIndex(fp[1])]) ++within[el[FaceIndex(fp[0])]];
      std::size_t sum = 0;
      for (const auto& [e, n] : within) sum += n;
      j["lifted_pairs_within"] = sum;
      j["lifted_elements_crossing_themselves"] = within.size();
      j["lifted_bare"] = output_bare_area(base, lifted, 0.5 * spacing * q.scale, {0, 1, 0}).overall;
    }
    Mesh scene;
    surface_quilt_scene(base, out, scene);
    ViewOptions vo;  // +Y up, as the meshes and glTF
    vo.size = 900;
    vo.azimuth_deg = 30.f;
    vo.elevation_deg = 20.f;
    write_image(outdir + "/" + stem + ".png", render_view(scene, vo));
    vo.azimuth_deg = 210.f;
    write_image(outdir + "/" + stem + "_back.png", render_view(scene, vo));
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> cases;
  std::string outdir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) outdir = argv[++i];
    else if (a == "--old-defaults") g_old_defaults = true;
    else cases.push_back(a);
  }
  if (!outdir.empty()) std::filesystem::create_directories(outdir);  // before the first case, not after its quilt
  if (cases.empty())
    for (const char* m : {"bunny", "koala", "knot"})
      for (const char* sw : {"weave", "chainmail", "tori", "rock"}) cases.push_back(std::string(m) + ":" + sw);
  int failed = 0;
  for (const std::string& c : cases) {
    try {
      std::cout << run_case(c, outdir).dump() << std::endl;
    } catch (const std::exception& e) {
      std::cout << json{{"case", c}, {"error", e.what()}}.dump() << std::endl;
      ++failed;
    }
  }
  return failed ? 2 : 0;
}
