// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Interpolation of sparse per-vertex scalar constraints by Laplacian smoothing
// (Ray et al. 2009, section 2.2): the texture scale S and the material
// coordinate m. The free vertices solve L x = 0 with the cotangent Laplacian
// (weights (cot a + cot b)/2 clamped to >= 1e-6 times the mean weight, so the
// operator stays an M-matrix on obtuse and skinny triangles and the result
// obeys the maximum principle), constrained vertices and vertices outside the
// effect area locked. The result is then clamped to [min_value, max_value]
// (the paper clamps m to [0,1] and keeps S above an epsilon > 0).
// A connected set of free vertices touching no locked vertex gets
// `default_value`.
//
// Reads/writes the vertex map `value_map` (double, created with default_value
// if absent). With an effect area, non-free vertices keep their value bit for
// bit. Throws InvalidInputError (vertex out of range, non-finite value,
// min > max), SolverError (factorisation failure).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/property_names.h"

namespace surftex {

struct EffectArea;

struct ScalarConstraint {
  std::uint32_t vertex = 0;
  double value = 0;
};

struct ScalarFieldOptions {
  PropertyName<VertexIndex, double> value_map = kVertexMaterial;  ///< or kVertexScale
  double min_value = -std::numeric_limits<double>::infinity();
  double max_value = std::numeric_limits<double>::infinity();
  double default_value = 0;
  const EffectArea* area = nullptr;  ///< nullptr = whole mesh free
};

/// Options for the material coordinate m: map v:material, clamped to [0,1].
ScalarFieldOptions material_field_options();
/// Options for the scale S: map v:scale, >= epsilon, default 1.
ScalarFieldOptions scale_field_options(double epsilon = 1e-6, double default_scale = 1.0);

struct ScalarFieldResult {
  std::size_t solved_vertices = 0;
  std::size_t clamped_vertices = 0;
  std::size_t defaulted_vertices = 0;
};

ScalarFieldResult interpolate_scalar_field(Mesh& mesh, const std::vector<ScalarConstraint>& constraints,
                                           const ScalarFieldOptions& options);

}  // namespace surftex
