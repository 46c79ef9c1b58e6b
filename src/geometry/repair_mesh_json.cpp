// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/repair_mesh_json.h"

#include <nlohmann/json.hpp>

namespace surftex {

nlohmann::json to_json(const RepairReport& r) {
  const RepairFound& f = r.found;
  const RepairDone& d = r.done;
  nlohmann::json j;
  j["found"] = {{"vertices", f.vertices},
                {"faces", f.faces},
                {"non_triangle_faces", f.non_triangle_faces},
                {"duplicate_vertices", f.duplicate_vertices},
                {"zero_area_faces", f.zero_area_faces},
                {"needle_faces", f.needle_faces},
                {"cap_faces", f.cap_faces},
                {"non_manifold_vertices", f.non_manifold_vertices},
                {"border_edges", f.border_edges},
                {"boundary_loops", f.boundary_loops},
                {"components", f.components},
                {"isolated_vertices", f.isolated_vertices},
                {"inward_components", f.inward_components}};
  j["done"] = {{"faces_triangulated", d.faces_triangulated},
               {"untriangulable_faces_removed", d.untriangulable_faces_removed},
               {"stitched_edges", d.stitched_edges},
               {"degenerate_faces_removed", d.degenerate_faces_removed},
               {"needles_collapsed", d.needles_collapsed},
               {"caps_flipped", d.caps_flipped},
               {"degenerate_faces_deleted", d.degenerate_faces_deleted},
               {"non_manifold_vertices_split", d.non_manifold_vertices_split},
               {"isolated_vertices_removed", d.isolated_vertices_removed},
               {"holes_filled", d.holes_filled},
               {"holes_skipped", d.holes_skipped},
               {"faces_added_by_filling", d.faces_added_by_filling},
               {"components_reoriented", d.components_reoriented},
               {"components_removed", d.components_removed},
               {"rounds", d.rounds},
               {"step_errors", d.step_errors}};
  j["result"] = {{"vertices", r.vertices},
                 {"faces", r.faces},
                 {"components", r.components},
                 {"boundary_loops", r.boundary_loops},
                 {"closed", r.closed},
                 {"self_intersections_checked", r.self_intersections_checked},
                 {"self_intersecting_pairs", r.self_intersecting_pairs}};
  j["valid"] = r.valid;
  j["refusal"] = r.refusal;
  nlohmann::json s = nlohmann::json::object();
  for (const auto& [name, sec] : r.seconds) s[name] = sec;
  j["seconds"] = s;
  return j;
}

nlohmann::json to_json(const SoupRepairCounts& c) {
  return nlohmann::json{{"input_points", c.input_points},
                        {"input_polygons", c.input_polygons},
                        {"duplicate_points_merged", c.duplicate_points_merged},
                        {"degenerate_polygons_removed", c.degenerate_polygons_removed},
                        {"duplicate_polygons_removed", c.duplicate_polygons_removed},
                        {"isolated_points_removed", c.isolated_points_removed},
                        {"polygons_simplified", c.polygons_simplified},
                        {"pinched_polygons_split", c.pinched_polygons_split},
                        {"points_duplicated_to_orient", c.points_duplicated_to_orient},
                        {"oriented", c.oriented},
                        {"faces_triangulated", c.faces_triangulated},
                        {"faces_fan_triangulated", c.faces_fan_triangulated},
                        {"short_polygons_dropped", c.short_polygons_dropped},
                        {"uv_corners", c.uv_corners},
                        {"uv_corners_dropped", c.uv_corners_dropped},
                        {"output_vertices", c.output_vertices},
                        {"output_faces", c.output_faces}};
}

}  // namespace surftex
