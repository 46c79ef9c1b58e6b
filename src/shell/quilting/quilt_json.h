// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// JSON form of the quilting results (the `quilt` report's figures), beside the
// results they describe, as geometry/repair_mesh_json.h does for repair. Kept
// out of the results' headers so that nlohmann's headers stay out of them.

#include <nlohmann/json_fwd.hpp>

#include "shell/quilting/edit_elements.h"
#include "shell/quilting/embed_surface_quilt.h"
#include "shell/quilting/mesh_quilting.h"
#include "shell/quilting/quilt_driver.h"
#include "shell/quilting/quilt_step.h"
#include "shell/quilting/surface_quilting.h"

namespace surftex {

/// The merge statistics of one quilt (planar or on a surface): stitched and
/// refused seams by reason, inputs and outputs replaced, crossings resolved.
/// Flat keys, the same for both kinds of quilt. The step timings are left to
/// the results that own them.
nlohmann::json to_json(const QuiltStepStats& stats);

/// A planar quilt (Zhou et al. 2006, 2): counts, merge statistics and
/// "seconds" {quilt, match, correspond, deform, merge}.
nlohmann::json to_json(const QuiltResult& result);

/// A surface quilt (3.1) and its embedding through the shell map (3.2):
/// counts, element quality, stretch, what lies outside the shell, the exact
/// self-intersection counts (null when not checked) and "seconds" per stage.
nlohmann::json to_json(const SurfaceQuiltResult& quilt, const EmbedSurfaceQuiltResult& embedding);

/// quilt_swatch_on_plane: the planar quilt's figures, "plane" [W, H],
/// swatch_faces, swatch_elements, element_length_mean / _max.
nlohmann::json to_json(const QuiltSwatchOnPlaneResult& result);

/// quilt_swatch_on_surface: the surface quilt's and embedding's figures,
/// base_faces, swatch_faces, swatch_elements, swatch_up, up, scale, field,
/// faces, vertices, max_turn_deg.
nlohmann::json to_json(const QuiltSwatchOnSurfaceResult& result);

/// edit_elements: elements, faces_removed.
nlohmann::json to_json(const EditElementsResult& result);

}  // namespace surftex
