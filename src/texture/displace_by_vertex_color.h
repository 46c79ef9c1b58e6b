// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Displacement synthesis output (Bangay & Morkel 2006, section 1 and figure
// 10c/f: the synthesised attribute used as a surface displacement): every
// vertex moves along its unit normal by height * g, where g is the grey level
// of its colour (Rec. 709 luminance 0.2126 R + 0.7152 G + 0.0722 B of the
// linear kVertexColor; for a grey colour R = G = B = g that is g itself).
//
// Inputs: mesh with kVertexColor (linear RGB, reads); height in mesh units
// (any finite value; negative moves inwards). Normals: area-weighted polygon
// normals (geometry/polygon_util.h) of the mesh before displacement, so the
// result does not depend on the vertex order. Writes the positions.
// Throws InvalidInputError if kVertexColor is absent or height is not finite.

#include "geometry/mesh_fwd.h"

namespace surftex {

struct DisplaceResult {
  double min_offset = 0, max_offset = 0;  ///< signed offsets applied, mesh units
};

DisplaceResult displace_by_vertex_color(Mesh& mesh, double height);

}  // namespace surftex
