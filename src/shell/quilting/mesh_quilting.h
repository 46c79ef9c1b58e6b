// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Planar mesh quilting (Zhou et al. 2006, sections 2.2-2.7): grows an output
// mesh M_out over the rectangle [0, width] x [0, height] (z as in the swatch)
// by repeatedly placing the swatch M_in near the most constrained unprocessed
// grid cell and stitching its elements to the existing ones.
//
// Seed (2.3): the unprocessed cell of the rectangle (extended one swatch on
// each side) with the most processed 8-neighbours (ties: lowest row, column);
// P_out: cells within subpatch_radius. Steps 2.4-2.7: quilt_step.h. Elements
// whose centroid ends outside are dropped (never clipped); kFaceElement written.
#include <cstdint>

#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "shell/quilting/quilt_step.h"
#include "shell/swatch.h"

namespace surftex {

struct PlanarQuiltOptions {
  /// Grid cell side (mesh units); 0 = automatic: max(l_in, w_in) / 10. >= 0.
  double cell_size = 0;
  /// P_out half-size in cells; 0 = automatic: a quarter of the swatch's smaller side in cells (>= 1).
  int subpatch_radius = 0;
  QuiltStepOptions step;
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

struct QuiltResult {
  int steps = 0;
  int elements = 0;
  std::size_t faces = 0, vertices = 0;
  QuiltStepStats stats;
  double seconds = 0;
};

/// Quilts `swatch` over [0,width] x [0,height]; writes `out` (cleared first)
/// with kFaceElement. Throws InvalidInputError (non-positive or non-finite
/// sizes, a swatch smaller than 3 cells or than P_out).
QuiltResult quilt_plane(const Swatch& swatch, double width, double height, Mesh& out,
                        const PlanarQuiltOptions& opt = {});

}  // namespace surftex
