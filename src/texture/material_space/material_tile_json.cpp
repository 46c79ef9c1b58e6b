// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/material_tile_json.h"

#include <nlohmann/json.hpp>

namespace surftex {

nlohmann::json to_json(const MaterialTileResult& r) {
  return {{"layers", r.layers.size()},
          {"sign_changes", r.sign_changes},
          {"mask_agreement", r.mask_agreement},
          {"seconds", {{"keys", r.seconds_keys}, {"morph", r.seconds_morph}, {"synthesis", r.seconds_synthesis}}}};
}

}  // namespace surftex
