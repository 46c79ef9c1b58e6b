// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/synthesis_json.h"

#include <nlohmann/json.hpp>

namespace surftex {

nlohmann::json to_json(const ElResult& r) {
  return {{"window", r.window},
          {"first_pass_window", r.first_pass_window},
          {"orientations_searched", r.rotations_used},
          {"search_images", r.search_images},
          {"seeded_pixels", r.seeded}};
}

nlohmann::json to_json(const BidirectionalResult& r, const BidirectionalOptions& opt) {
  return {{"patch", opt.patch},
          {"stride", opt.stride},
          {"exemplar_stride", opt.exemplar_stride},
          {"approximate_max_candidates", opt.max_candidates},
          {"approximate_search_eps", opt.search_eps},
          {"coherence", r.coherence},
          {"completeness", r.completeness},
          {"total", r.total}};
}

}  // namespace surftex
