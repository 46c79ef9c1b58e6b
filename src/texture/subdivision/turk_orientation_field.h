// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Orientation field and sweep field by diffusion (Turk 2001, "Texture
// synthesis on surfaces", section 3; used by Bangay & Morkel 2006, section
// 3.1.1). Works on any polygon mesh (normals are Newell area-weighted).
//
// turk_orientation_field: Jacobi passes setting each non-key vertex to the
// projected, normalised mean of its neighbours' vectors, `fill` passes until
// every vertex has one, then `smoothing_passes`; keyless components get the
// world x (or y) axis, counted in `unreached`. from_existing starts from the
// current kVertexDirection (coarse to fine, 3.1.1).
// turk_sweep_field: s(anchor) = 0, every other vertex the mean over its
// neighbours of s(n) + (p_v - p_n) . (d_v + d_n)/|d_v + d_n| (Gauss-Seidel in
// vertex order); breadth-first start, then `passes`. In full: decision 206.
//
// Reads kVertexDirection (sweep). Writes kVertexDirection / kVertexSweep.
// Throws InvalidInputError (empty mesh, key or anchor vertex out of range,
// zero or non-finite key direction, negative passes).

#include <array>
#include <cstddef>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct OrientationKey {
  std::size_t vertex = 0;             ///< vertex index
  std::array<double, 3> direction{};  ///< any non-zero vector; projected to the tangent plane
};

struct TurkFieldOptions {
  /// Passes after every vertex has a value (>= 0). Default 10.
  int smoothing_passes = 10;
  /// Start from the existing kVertexDirection values (coarse-to-fine step).
  bool from_existing = false;
};

struct TurkFieldResult {
  int fill_passes = 0;
  int smoothing_passes = 0;
  std::size_t unreached = 0;  ///< vertices in components without a key (given a default)
};

TurkFieldResult turk_orientation_field(Mesh& mesh, const std::vector<OrientationKey>& keys,
                                       const TurkFieldOptions& opt = {});

struct SweepFieldOptions {
  /// Relaxation passes after the breadth-first initialisation (>= 0). Default 30.
  int passes = 30;
  /// Start from the existing kVertexSweep values (coarse-to-fine step).
  bool from_existing = false;
};

struct SweepFieldResult {
  double min_value = 0, max_value = 0;
};

SweepFieldResult turk_sweep_field(Mesh& mesh, std::size_t anchor, const SweepFieldOptions& opt = {});

}  // namespace surftex
