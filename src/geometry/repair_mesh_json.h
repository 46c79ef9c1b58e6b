// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// JSON form of a RepairReport (for `surftex repair --report`), kept apart
// from repair_mesh.h so that nlohmann's headers stay out of widely included
// headers (only the forward declaration is pulled in here).

#include <nlohmann/json_fwd.hpp>

#include "geometry/read_mesh.h"
#include "geometry/repair_mesh.h"

namespace surftex {

/// {"found": {...}, "done": {...}, "result": {...}, "valid": b, "refusal": s,
///  "seconds": {step: s, ...}}; every count of the structs under its own name.
nlohmann::json to_json(const RepairReport& report);

/// Every count of what reading a file repaired in its polygon soup, under its
/// own name.
nlohmann::json to_json(const SoupRepairCounts& counts);

}  // namespace surftex
