// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Partition of a triangle mesh into connected, nearly planar patches of
// similar size (Gorla, Interrante & Sapiro 2003, section 3.1).
//
// Greedy stage (the paper's pseudo code): the lowest unassigned triangle
// seeds a patch grown breadth-first within max_angle_deg of its normal,
// max_distance of its farthest vertex and (ours) max_faces; the seed defines
// the reference plane. Refinement until stable (max_iterations): merge small
// patches, reassign better-aligned triangles, regrow disconnected parts
// (ours). Every triangle stays within max_angle_deg; every patch is
// edge-connected. In full: docs/decisions/505-efros-leung-details.md.
//
// Writes kFacePatch (f:patch, int, 0..patches-1; created if absent). Patch
// ids are renumbered in order of their seed face index. Throws
// InvalidInputError for non-triangle meshes, an empty mesh or options out of
// range.

#include <array>
#include <cstddef>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct PartitionOptions {
  /// Largest angle between a triangle's normal and its patch's reference
  /// (seed) normal, degrees, in (0, 89]. Default 30 (the paper's Figure 3
  /// colours 18 and 25 degrees as 5% and 10% projection error).
  double max_angle_deg = 30.0;
  /// Largest patch size: the paper's max_dist (world units, > 0); 0 = derived
  /// from max_faces: sqrt(max_faces * mean triangle area / pi), the radius of
  /// a disc holding max_faces average triangles.
  double max_distance = 0.0;
  /// Most triangles in one patch, >= 1. Default 200.
  int max_faces = 200;
  /// Patches with fewer triangles are merged into a neighbour if possible;
  /// 0 = max(2, max_faces / 10).
  int small_faces = 0;
  /// Refinement passes at most, >= 0. Default 20.
  int max_iterations = 20;
};

struct PartitionResult {
  int patches = 0;
  std::vector<int> seed_face;                       ///< per patch: face index of its seed
  std::vector<std::array<double, 3>> normal;        ///< per patch: unit reference normal
  std::vector<int> faces;                           ///< per patch: triangle count
  int greedy_patches = 0;                           ///< count after the greedy stage
  int iterations = 0;                               ///< refinement passes run
  std::size_t merged_patches = 0, reassigned_faces = 0;
  double max_distance = 0.0;                        ///< the distance limit used (world units)
  double max_deviation_deg = 0.0;                   ///< largest triangle-to-reference angle
};

PartitionResult partition_near_planar(Mesh& mesh, const PartitionOptions& options = {});

}  // namespace surftex
