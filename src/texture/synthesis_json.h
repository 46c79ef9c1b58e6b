// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// JSON form of the 2D synthesis results (the `synth` report's figures), beside
// the results they describe, as geometry/repair_mesh_json.h does for repair.
// Kept out of the results' headers so that nlohmann's headers stay out of them.

#include <nlohmann/json_fwd.hpp>

#include "texture/bidirectional_similarity.h"
#include "texture/efros_leung.h"

namespace surftex {

/// A two-pass Efros-Leung run (Gorla et al. 2003, 3.3): "window" and
/// "first_pass_window" (effective diameters, px), "orientations_searched"
/// (distinct exemplar orientations), "search_images" (the rotated exemplars
/// those needed built) and "seeded_pixels" (pixels filled by
/// random seed patches). The image, the sources and the timing are left to
/// the caller.
nlohmann::json to_json(const ElResult& result);

/// Bidirectional similarity (Simakov et al. 2008) with the settings that
/// measured it: "patch", "stride", "exemplar_stride",
/// "approximate_max_candidates" (0 = exact), "approximate_search_eps" (0 = exact) and the distances "coherence",
/// "completeness", "total" (mean squared difference per value, squared image
/// units).
nlohmann::json to_json(const BidirectionalResult& result, const BidirectionalOptions& opt);

}  // namespace surftex
