// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Orientation field and sweep field by diffusion (Turk 2001, "Texture
// synthesis on surfaces", section 3; used by Bangay & Morkel 2006, section
// 3.1.1). Works on any polygon mesh (normals are Newell area-weighted).
//
// turk_orientation_field: the user gives orientations at key vertices. Passes
// are made over the mesh; in each pass (Jacobi: every vertex reads the values
// of the previous pass) the vector at every non-key vertex is set to the
// average of its neighbours' defined vectors, projected onto the tangent plane
// at the vertex and normalised. Key vertices keep their (projected,
// normalised) vector. First `fill` passes run until every vertex has a value
// (the diffusion front), then `smoothing_passes` more. A vertex whose
// component has no key gets the world x axis (or y) projected to its tangent
// plane and is counted in `unreached`.
// Coarse to fine (section 3.1.1, "performed in a hierarchical manner"): with
// from_existing, the current kVertexDirection values (e.g. carried by
// sqrt2_subdivide, which averages them onto face points) are the start; they
// are re-projected and normalised, zero vectors count as undefined, and only
// `smoothing_passes` passes follow.
//
// turk_sweep_field: a scalar that increases along the field, to order
// vertices (Turk's sweep). s(anchor) = 0; every other vertex repeatedly takes
// the mean over its neighbours n of s(n) + (p_v - p_n) . (d_v + d_n)/|d_v + d_n|
// (Gauss-Seidel in vertex order, which is deterministic). The first passes
// spread values out from the anchor breadth first; `passes` relaxation passes
// follow. Components without the anchor get their first vertex as anchor.
// With from_existing, the current kVertexSweep values are the start.
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
