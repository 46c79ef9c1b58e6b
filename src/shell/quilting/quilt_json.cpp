// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/quilt_json.h"

#include <nlohmann/json.hpp>

namespace surftex {

nlohmann::json to_json(const QuiltStepStats& st) {
  return {{"stitched", st.stitched},
          {"stitch_refused", st.stitch_refused},
          {"coincident", st.coincident},
          {"coincident_cut_added", st.coincident_cut_added},
          {"stitched_trimmed", st.stitched_trimmed},
          {"related", st.related},
          {"stitch_refused_loops", st.refused_loops},
          {"stitch_refused_border", st.refused_border},
          {"stitch_refused_geometry", st.refused_geometry},
          {"stitch_refused_infeasible", st.refused_infeasible},
          {"stitch_refused_reasons", st.refused_reasons},
          {"outputs_replaced", st.out_replaced},
          {"inputs_added", st.in_added},
          {"inputs_dropped", st.in_dropped},
          {"inputs_kept_cut", st.in_cut_added},
          {"crossing_hits", st.crossing_hits},  // new elements that would have passed through placed ones
          {"crossing_dropped", st.crossing_dropped},
          {"crossing_trimmed", st.crossing_trimmed},
          {"crossing_pushed", st.crossing_pushed}};
}

nlohmann::json to_json(const QuiltResult& r) {
  nlohmann::json j = to_json(r.stats);
  j["elements"] = r.elements;
  j["faces"] = r.faces;
  j["vertices"] = r.vertices;
  j["steps"] = r.steps;
  j["seconds"] = {{"quilt", r.seconds},
                  {"match", r.stats.seconds_match},
                  {"correspond", r.stats.seconds_correspond},
                  {"deform", r.stats.seconds_deform},
                  {"merge", r.stats.seconds_merge}};
  return j;
}

namespace {

// Placement and element quality of the surface quilt (3.1).
void add_placement(const SurfaceQuiltResult& r, nlohmann::json& j) {
  j["elements"] = r.elements;
  j["steps"] = r.steps;
  j["patches_shrunk"] = r.patches_shrunk;
  j["patches_transported"] = r.patches_transported;
  j["patches_aligned"] = r.patches_aligned;
  j["overlap_jump_deg"] = r.overlap_area > 0 ? r.overlap_turn_sum / r.overlap_area : 0.0;
  j["patches_turned"] = r.patches_turned;
  j["elements_past_border"] = r.elements_past_border;
  j["elements_stretched"] = r.elements_stretched;
  j["elements_misshapen"] = r.elements_misshapen;
  j["broken_rings_removed"] = r.broken_rings_removed;
  j["small_pieces_removed"] = r.small_pieces_removed;
  j["edge_stretch_max"] = r.edge_stretch_max;
  j["crossings_resolved"] = r.crossings_resolved;
  j["crossings_lifted_clear"] = r.crossings_lifted_clear;
  j["lift_crossing_rings"] = r.lift_crossing_rings;
  j["finish_elements_checked"] = r.finish_elements_checked;
  j["fragments_removed"] = r.fragments_removed;
  j["refill_rounds"] = r.refill_rounds;
  j["refill_rounds_run"] = r.refill_rounds_run;
  j["faces_refilled"] = r.faces_refilled;
  j["scatter_placed"] = r.scatter_placed;
  j["scatter_faces_tried"] = r.scatter_faces_tried;
  j["scatter_faces_skipped"] = r.scatter_faces_skipped;
  j["scatter_lifted"] = r.scatter_lifted;
  j["scatter_only"] = r.scatter_only;
  j["bare_fraction"] = r.bare_fraction;
  j["elements_not_expressible"] = r.elements_not_expressible;
  j["elements_not_expressed"] = r.elements_not_expressed;
  j["elements_partial"] = r.elements_partial;
  j["seams_broken"] = r.seams_broken;
  j["z_fitted_elements"] = r.z_fitted_elements;
}

// The embedding through the shell map (3.2): the shell, its stretch and what
// ended outside it.
void add_embedding(const EmbedSurfaceQuiltResult& er, nlohmann::json& j) {
  j["crossing_elements_embedded"] = er.crossing_elements;  // cut or removed after the embedding
  j["crossing_elements_removed_last"] = er.crossing_elements_removed_last;  // still crossing after the trims: removed
  j["elements_stretched_embedded"] = er.elements_stretched_embedded;  // over the shard bound after the shell map
  j["embedded_edge_bound"] = er.embedded_edge_bound;    // that bound, mesh units (decision 102, session 41)
  j["embedded_median_edge"] = er.embedded_median_edge;
  j["elements_relaxed_embedded"] = er.elements_relaxed_embedded;  // brought within it by moving, not cut
  j["caps_recentred"] = er.caps_recentred;
  j["elements_untangled"] = er.elements_untangled;
  j["elements_placed_affine"] = er.elements_placed_affine;
  j["fill_faces_tried"] = er.fill.faces_tried;  // bare faces after the embedding (decision 102, session 44)
  j["fill_placed"] = er.fill.placed;            // thread pieces or whole copies placed there
  j["fill_placed_smaller"] = er.fill.placed_smaller;  // of which copies smaller than the full size
  j["charts"] = er.atlas.num_charts;
  j["tets"] = er.tets;
  j["shell_height"] = er.shell_height;
  j["clamped_vertices"] = er.clamped_vertices;
  if (er.unfolded_vertices > 0) j["unfolded_vertices"] = er.unfolded_vertices;  // only when a fold was undone
  j["elements_embedded"] = er.elements;  // in the output (elements: the quilt's)
  j["stretch_before"] = er.stretch.stretch_before;
  j["stretch_after"] = er.stretch.stretch_after;
  j["outside_vertices"] = er.embed.outside;
  j["outside_below"] = er.outside_below;
  j["outside_above"] = er.outside_above;
  j["outside_uv"] = er.outside_uv;
  j["locations_clamped"] = er.locations_clamped;  // quilt vertices clamped onto their base face
  if (er.outside_shell_measured) {
    // Vertices outside the union of the shell's 3D tets (distance > 1e-6 shell heights).
    j["outside_shell"] = er.outside_shell.outside;
    j["outside_shell_below"] = er.outside_shell.below;
    j["outside_shell_above"] = er.outside_shell.above;
    j["outside_shell_side"] = er.outside_shell.side;
    j["outside_shell_max_distance"] = er.outside_shell.max_distance;
    // The whole copies placed affinely: below the shell = into the base.
    j["affine_vertices_below_shell"] = er.affine_outside_shell.below;
    j["affine_vertices_above_shell"] = er.affine_outside_shell.above;
  }
  if (er.embed.checked) {
    j["self_intersections"] = er.embed.self_intersecting_pairs;
    j["self_intersections_within_elements"] = er.self_intersections_within;
    j["self_intersections_between_elements"] = er.self_intersections_between;
    // Elements keeping the swatch element's own crossings (within-element pairs).
    j["elements_self_crossing_kept"] = er.elements_self_crossing_kept;
  } else {
    j["self_intersections"] = nullptr;
  }
}

}  // namespace

nlohmann::json to_json(const SurfaceQuiltResult& r, const EmbedSurfaceQuiltResult& er) {
  nlohmann::json j = to_json(r.stats);
  add_placement(r, j);
  add_embedding(er, j);
  j["seconds"] = {{"quilt", r.seconds},
                  {"patches", r.seconds_patch},
                  {"match", r.stats.seconds_match},
                  {"correspond", r.stats.seconds_correspond},
                  {"deform", r.stats.seconds_deform},
                  {"merge", r.stats.seconds_merge},
                  {"resolve", r.stats.seconds_resolve},
                  {"finish", r.seconds_finish},
                  {"atlas", er.seconds_atlas},
                  {"shell", er.seconds_shell},
                  {"stretch", er.seconds_stretch},
                  {"shell_map", er.seconds_map},
                  {"embed", er.seconds_embed}};
  return j;
}

nlohmann::json to_json(const QuiltSwatchOnPlaneResult& r) {
  nlohmann::json j = to_json(r.quilt);
  j["plane"] = {r.width, r.height};
  j["swatch_faces"] = r.swatch.mesh.tris.size();
  j["swatch_elements"] = r.swatch.elements.size();
  j["swatch_components"] = r.swatch.components;  // more than elements: crossing components joined
  j["element_length_mean"] = r.element_length_mean;
  j["element_length_max"] = r.element_length_max;
  return j;
}

nlohmann::json to_json(const QuiltSwatchOnSurfaceResult& r) {
  nlohmann::json j = to_json(r.quilt, r.embedding);
  j["base_faces"] = r.base_faces;
  j["swatch_faces"] = r.swatch.mesh.tris.size();
  j["swatch_elements"] = r.swatch.elements.size();
  j["swatch_components"] = r.swatch.components;  // more than elements: crossing components joined
  j["swatch_up"] = axis_name(r.swatch.up_axis);
  j["swatch_vertices_split"] = r.swatch_vertices_split;
  j["base_vertices_split"] = r.base_vertices_split;
  j["up"] = r.up;
  j["scale"] = r.relative_size;
  j["field"] = r.field == SurfaceQuiltOptions::Field::kUp ? "up" : "none";
  j["faces"] = r.faces;
  j["vertices"] = r.vertices;
  j["max_turn_deg"] = r.rotation_max_deg;
  j["bare_fraction_quilt"] = r.quilt.bare_fraction;  // before the embedding
  j["bare_fraction"] = r.bare.overall;               // of the output
  j["bare_by_height"] = r.bare.by_height;
  return j;
}

nlohmann::json to_json(const EditElementsResult& r) {
  return {{"elements", r.elements}, {"faces_removed", r.faces_removed}};
}

}  // namespace surftex
