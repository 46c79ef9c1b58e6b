// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// L2 stretch of a shell map and its minimisation (Zhou et al. 2006, section 3.2,
// "Stretch Metric on Tetrahedra", equations 8-9, and "Minimization Algorithm";
// after Sander et al. 2001).
//
// Per tet (eq. 8): L2 = sqrt((a + b + c) / 3) = sqrt(trace(J^T J) / 3), J the
// constant Jacobian of the piecewise-linear map between the tet in texture
// space (metric units (u, v, w * w_scale), see shell_space.h) and in shell
// space. Total (eq. 9): L2(M) = sqrt(sum_i L2_i^2 |T_s^i| / sum_j |T_s^j|).
//
// Two departures from the letter of the paper (reasons: decision 104): J is
// the Jacobian of texture -> shell (Sander et al.'s direction), and the
// normalisation is (sum|T_t| / sum|T_s|)^(1/3), so that normalised L2 >= 1
// with equality iff the map is a similarity. The normalised value is the one
// reported and minimised.

#include <cstddef>
#include <cstdint>

#include "shell/shell_space.h"

namespace surftex {

/// Eq. 8 for one tet: L2 stretch of the linear map taking texture tet `t` to
/// shell tet `s` (vertex i to vertex i). Infinite if the texture tet is flat.
double tet_l2_stretch(const std::array<Vec3, 4>& s, const std::array<Vec3, 4>& t);

struct ShellStretch {
  double l2 = 0;             ///< eq. 9 (unnormalised; in mesh units per uv unit)
  double l2_normalized = 0;  ///< eq. 9 times (sum|T_t| / sum|T_s|)^(1/3); >= 1
  double max_tet = 0;        ///< largest normalised per-tet L2
  double shell_volume = 0;   ///< sum |T_s| (mesh units^3)
  double texture_volume = 0; ///< sum |T_t| (uv units^3, w in metric units)
};

/// Stretch of the shell map given by `shell` (eq. 8-9, normalised as above).
ShellStretch shell_stretch(const ShellSpace& shell);

struct MinimizeStretchOptions {
  /// Sweeps over all free vertices (each vertex gets one random line search per sweep); >= 0.
  int iterations = 40;
  /// Seed of the random search directions.
  std::uint64_t seed = 1;
  /// Samples on each side of the vertex along the search line, at distances
  /// radius, radius/2, radius/4, ... (multi-scale: the best step in a thin
  /// shell is often far below the neighbour distance); >= 1.
  int line_samples = 10;
  /// Golden-section refinements around the best sample; >= 0.
  int refine_steps = 8;
  /// Search radius as a fraction of the shortest uv distance from the vertex to
  /// its neighbouring offset-surface vertices; in (0, 1].
  double step_fraction = 0.5;
  /// Stop early when a sweep lowers the normalised stretch by less than this (relative); >= 0.
  double tolerance = 1e-6;
};

struct MinimizeStretchResult {
  double stretch_before = 0;  ///< normalised L2 before
  double stretch_after = 0;   ///< normalised L2 after (<= before)
  int sweeps = 0;
  std::size_t free_vertices = 0;   ///< offset-surface vertices not on a lateral boundary
  std::size_t moves_tried = 0, moves_accepted = 0;
  int colors = 0;  ///< independent sets processed in parallel
};

/// Random line search on the (u, v) of the offset-surface shell vertices
/// (layer 1) that are not on a lateral boundary (section 3.2: the bottom layer
/// and the lateral boundaries stay fixed to keep continuity across charts).
/// A move is accepted only if it lowers the local energy sum L2_t^2 |T_s^t|
/// over the vertex's tets (equivalent to lowering the global value, since the
/// texture volume of a chart is fixed by its boundary) and every texture tet
/// of the vertex stays positively oriented (exact CGAL::orientation).
/// Vertices are coloured so that no two of a colour share a tet, each colour
/// run with tbb::parallel_for, directions seeded by (seed, sweep, vertex):
/// independent of the thread count. Modifies shell.texture_points. The bottom
/// layer, every w and the lateral vertices stay; every texture tet stays
/// positive, so the chart's tets still tile its slab (locate points in the
/// chart, not the prism: ShellMap::locate_texture_from).
/// Throws InvalidInputError for bad options or an empty shell.
MinimizeStretchResult shell_map_minimize_stretch(ShellSpace& shell, const MinimizeStretchOptions& opt = {});

}  // namespace surftex
