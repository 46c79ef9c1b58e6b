// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// surftex's up axis is +Y, as in glTF 2.0 (section 3.4: "+Y is up"): the
// renders orbit about +Y, the "up" direction fields of patches and
// material-map point along +Y, and meshes the project builds for its demo are
// written Y-up so that they stand upright in glTF viewers. Meshes a user gives
// are read and written in their own coordinates, never turned.

#include "geometry/mesh_fwd.h"

namespace surftex {

/// Turns a Z-up mesh into a Y-up one: the proper rotation of -90 degrees about
/// +X, (x, y, z) -> (x, z, -y), applied to the positions and to every vector
/// property of properties.h that is present (kVertexNormal, kFaceNormal,
/// kVertexDmax, kVertexDmin, kFaceDirection, kVertexDirection). Orientation,
/// UVs and scalar fields are unchanged.
void z_up_to_y_up(Mesh& mesh);

}  // namespace surftex
