// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The per-face material property, in the manner of properties.h:
//
// | constant      | name       | element | type | meaning                                             |
// |---------------|------------|---------|------|-----------------------------------------------------|
// | kFaceMaterial | f:material | face    | int  | index into the file's MeshMaterial list, -1 = none  |
//
// Written by the mesh readers (read_mesh.h) for files with materials, read by
// write_mesh and `surftex render`. (A row for properties.h's table: it is kept
// in this header until the branches touching properties.h are merged, since an
// edit there recompiles nearly every source file.)

#include "geometry/properties.h"

namespace surftex {

inline constexpr PropertyName<FaceIndex, int> kFaceMaterial{"f:material"};

}  // namespace surftex
