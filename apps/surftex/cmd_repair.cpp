// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex repair`: load any OFF/OBJ/PLY/STL mesh, repair it
// (geometry/repair_mesh.h) and write it, or refuse with the reason.
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "geometry/repair_mesh.h"
#include "geometry/repair_mesh_json.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "surftex/command.h"

namespace surftex::cli {
namespace {
namespace repair_command {  // named: the unity build joins these files

struct RepairArgs {
  std::string input, output;
  bool fill_holes = false;
  bool largest = false;
  std::size_t max_hole_edges = RepairOptions{}.max_hole_edges;
  double needle = RepairOptions{}.needle_threshold;
  double cap = RepairOptions{}.cap_threshold;
  CommonOptions common;
};

int run_repair(const RepairArgs& a) {
  require_input_file(a.input, "input mesh");
  check_output(a.output, {a.input}, a.common.force);
  auto limit = apply_thread_limit(a.common.threads);

  Timer t;
  PolygonSoup soup = read_polygon_soup(a.input);
  SoupRepairCounts counts;
  Mesh mesh;
  SoupToMeshOptions so;
  so.triangulate = false;  // repair_mesh triangulates, dropping (and counting) what it cannot
  soup_to_mesh(std::move(soup), mesh, so, &counts);
  const double load_s = t.seconds();

  RepairOptions opt;
  opt.fill_holes = a.fill_holes;
  opt.keep_largest_component = a.largest;
  opt.max_hole_edges = a.max_hole_edges;
  opt.needle_threshold = a.needle;
  opt.cap_threshold = a.cap;
  opt.progress = terminal_progress(a.common.quiet);
  t.reset();
  RepairReport r = repair_mesh(mesh, opt);
  const double repair_s = t.seconds();

  nlohmann::json report = to_json(r);
  report["input"] = a.input;
  report["output"] = a.output;
  report["load"] = to_json(counts);
  report["seconds"]["load"] = load_s;
  report["seconds"]["repair"] = repair_s;
  report["options"] = {{"fill_holes", a.fill_holes},
                       {"largest_component", a.largest},
                       {"max_hole_edges", a.max_hole_edges},
                       {"needle_threshold", a.needle},
                       {"cap_threshold", a.cap}};
  if (!r.valid)  // refuse: nothing is written (neither mesh nor report)
    throw TopologyError("cannot repair '" + a.input + "': " + r.refusal);
  t.reset();
  WriteMeshOptions wo;
  wo.overwrite = a.common.force;
  write_mesh(a.output, mesh, wo);
  report["seconds"]["write"] = t.seconds();
  write_report(a.common, "repair", report, {{a.input}, {a.output}});

  if (!a.common.quiet) {
    const RepairFound& f = r.found;
    const RepairDone& d = r.done;
    std::fprintf(stderr,
                 "loaded %zu points, %zu polygons (%zu duplicate points merged, %zu degenerate and "
                 "%zu duplicate polygons removed, %zu faces with < 3 vertices dropped, %zu fan-triangulated)\n",
                 counts.input_points, counts.input_polygons, counts.duplicate_points_merged,
                 counts.degenerate_polygons_removed, counts.duplicate_polygons_removed,
                 counts.short_polygons_dropped, counts.faces_fan_triangulated);
    std::fprintf(stderr,
                 "found: %zu zero-area, %zu needle, %zu cap faces; %zu non-manifold vertices; %zu "
                 "boundary loops; %zu components; %zu inward components\n",
                 f.zero_area_faces, f.needle_faces, f.cap_faces, f.non_manifold_vertices,
                 f.boundary_loops, f.components, f.inward_components);
    std::fprintf(stderr,
                 "done: %zu edges stitched, %zu degenerate faces removed, %zu needles collapsed, "
                 "%zu caps flipped, %zu vertices split, %zu holes filled (%zu skipped), %zu "
                 "components reoriented, %zu removed\n",
                 d.stitched_edges, d.degenerate_faces_removed + d.degenerate_faces_deleted,
                 d.needles_collapsed, d.caps_flipped, d.non_manifold_vertices_split,
                 d.holes_filled, d.holes_skipped, d.components_reoriented, d.components_removed);
    std::fprintf(stderr,
                 "result: %zu vertices, %zu faces, %zu components, %s, %zu self-intersecting face "
                 "pairs (reported, not removed); written to %s (%.2f s load, %.2f s repair)\n",
                 r.vertices, r.faces, r.components,
                 r.closed ? "closed" : (std::to_string(r.boundary_loops) + " boundary loops").c_str(),
                 r.self_intersecting_pairs, a.output.c_str(), load_s, repair_s);
  }
  return 0;
}

SubcommandRegistrar reg{
    {"repair",
     "Repair a mesh (weld, remove degenerate faces, split non-manifold vertices, orient, "
     "optionally fill holes) and write it, or refuse with the reason",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<RepairArgs>();
       app.add_option("input", a->input, "Input mesh (.off, .obj, .ply, .stl)")->required();
       app.add_option("-o,--output", a->output,
                      "Output mesh (.obj, .ply, .off or .glb, chosen by the extension); not "
                      "written if the mesh cannot be repaired")
           ->required();
       app.add_flag("--fill-holes", a->fill_holes,
                    "Fill boundary loops with triangles (default: off, open surfaces are kept)");
       app.add_option("--max-hole-edges", a->max_hole_edges,
                      "With --fill-holes, leave holes with more boundary edges than this open "
                      "(3..100000, default 200)")
           ->check(CLI::Range(std::size_t(3), std::size_t(100000)));
       app.add_flag("--largest-component", a->largest,
                    "Keep only the connected component with most faces (default: keep all)");
       app.add_option("--needle-threshold", a->needle,
                      "A triangle whose longest/shortest edge ratio exceeds this is a needle and "
                      "its shortest edge is collapsed (>= 1, default 1000)")
           ->check(CLI::Range(1.0, 1e300));
       app.add_option("--cap-threshold", a->cap,
                      "A triangle whose largest angle has a cosine below this is a cap and its "
                      "longest edge is flipped (-1..0, default -0.9998, about 178.9 degrees)")
           ->check(CLI::Range(-1.0, 0.0));
       add_common_options(app, a->common);
       return [a] { return run_repair(*a); };
     }}};

}  // namespace repair_command
}  // namespace
}  // namespace surftex::cli
