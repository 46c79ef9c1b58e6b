// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Index of an N-symmetry direction field around each interior vertex (the
// singularities that "emerge from the geometry", Ray et al. 2009, section 2.2).
//
// Around vertex v (faces f_0..f_{k-1} in counter-clockwise order) the field
// angle jump from f_i to f_{i+1}, after transport across their shared edge, is
// reduced to (-pi/N, pi/N]; the index is (sum of jumps + angle defect) / 2 pi,
// a multiple of 1/N. We return it times N (an integer). Sum over a closed mesh
// = N * Euler characteristic (Poincare-Hopf): 2N on a sphere, 0 on a torus.
// Border vertices and isolated vertices get 0.
//
// Reads the face map `direction_map` (Vector3, default kFaceDirection).
// Throws InvalidInputError if the map is absent or symmetry not in {1,2,4}.

#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/property_names.h"

namespace surftex {

struct FieldIndexOptions {
  int symmetry = 4;
  PropertyName<FaceIndex, Vector3> direction_map = kFaceDirection;
};

/// Per vertex index (by `.idx()`): N times the field index.
std::vector<int> direction_field_indices(const Mesh& mesh, const FieldIndexOptions& options = {});

}  // namespace surftex
