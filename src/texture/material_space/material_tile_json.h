// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// JSON form of a material tile (the `material-tile` report's figures), beside
// the result it describes, as geometry/repair_mesh_json.h does for repair.
// Kept out of material_tile.h so that nlohmann's headers stay out of it.

#include <nlohmann/json_fwd.hpp>

#include "texture/material_space/material_tile.h"

namespace surftex {

/// A material tile (Ray et al. 2009, section 1): "layers" (count),
/// "sign_changes" (per layer, texels whose mask side changed since the
/// previous layer), "mask_agreement" (per layer, in [0, 1]) and "seconds"
/// {keys, morph, synthesis} (wall seconds). The images are left to
/// write_material_tile.
nlohmann::json to_json(const MaterialTileResult& result);

}  // namespace surftex
