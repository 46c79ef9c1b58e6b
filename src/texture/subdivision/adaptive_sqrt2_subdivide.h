// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Adaptive sqrt(2)-subdivision for an even vertex distribution (Bangay &
// Morkel 2006, section 3.2.2): at every step the faces whose area exceeds
// `factor` times the mean face area (a_i > f * mean(a)) are refined with the
// selective sqrt(2) split (sqrt2_subdivide_selected; like the paper, no
// one-level rule between neighbours); reports the spread of face area (std as
// a percentage of the mean, the paper's figure) before and after each step;
// Newell areas.
//
// Stops early when no face is above the threshold. Old vertices do not move.
// Properties carried as in sqrt2_subdivide.h.
// Throws InvalidInputError (factor <= 0 or not finite, steps < 0, empty mesh),
// TopologyError (see sqrt2_subdivide_selected).

#include <cstddef>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "texture/subdivision/sqrt2_subdivide.h"

namespace surftex {

struct AdaptiveSubdivideOptions {
  /// Threshold factor f: faces with area > f * mean area are refined; > 0. The
  /// paper finds f ~ 1.5 good for most models. Default 1.5.
  double factor = 1.5;
  /// Number of adaptive steps (>= 0). Default 4.
  int steps = 4;
  /// Carry flags for the split (colour, sweep, direction).
  Sqrt2SubdivideOptions split;
};

struct AdaptiveSubdivideResult {
  /// Face-area standard deviation as % of the mean: entry 0 before any step,
  /// entry i after step i (steps_done + 1 entries).
  std::vector<double> area_std_percent;
  std::vector<std::size_t> faces_refined;  ///< per step
  int steps_done = 0;
};

/// Face-area standard deviation as a percentage of the mean area (population std).
double face_area_std_percent(const Mesh& mesh);

AdaptiveSubdivideResult adaptive_sqrt2_subdivide(Mesh& mesh, const AdaptiveSubdivideOptions& opt = {});

}  // namespace surftex
