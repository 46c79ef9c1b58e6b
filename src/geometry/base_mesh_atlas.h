// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Multi-chart texture atlas of a base mesh (Zhou et al. 2006, "Mesh Quilting",
// section 3.2: "we build a texture atlas for M_base"; their figure 6 shows a
// low-distortion multi-chart atlas of the bunny). The paper does not say how
// the atlas is made; this is a careful, simple choice:
//
// 1. Segmentation (disc_chart.h): greedy region growing from the first free
//    face, within max_normal_angle_deg and max_chart_faces, keeping discs
//    (verified; TopologyError otherwise).
// 2. Flattening: LSCM per chart (disc_chart.h, LscmSolver::kDirect), mirrored
//    if negative, scaled to its 3D area, rotated to its smallest bounding box;
//    folded charts regrown smaller. Charts flattened in parallel.
// 2b. Merging (merge_charts; Sander et al. 2001, 4.1): smallest charts merged
//    into neighbours while the union is a disc, embeds, stays within
//    max_merge_distortion and packs smaller. Serial greedy order; the unions
//    the next merges try are flattened ahead in parallel.
// Same bytes on any number of threads (decision 210).
// 3. Packing: shelf packing with `margin` gaps, one uniform scale into [0,1]^2.
// In full: docs/decisions/104-shell-space.md.
//
// Works on closed (genus 0, genus g) and open manifold triangle meshes.
// Writes: kCornerUV (halfedge h: uv of the corner of face(h) at target(h)),
//         kFacePatch (chart id per face, 0..num_charts-1).
// Throws: InvalidInputError (bad options, non-triangle faces, empty mesh),
//         TopologyError (non-manifold input that breaks the disc invariant),
//         SolverError (LSCM failure on a chart).

#include <cstddef>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct BaseMeshAtlasOptions {
  /// Half-angle (degrees) of the normal cone around a chart's seed normal; in (0, 180].
  double max_normal_angle_deg = 50.0;
  /// Largest number of faces in a chart (>= 1). Smaller charts flatten with less distortion.
  std::size_t max_chart_faces = 4000;
  /// Gap between charts and around the atlas, as a fraction of the atlas side; in [0, 0.1).
  /// Also the gap that merging (step 2b) weighs. Default: 0.005.
  double margin = 0.005;
  /// Merge adjacent charts after flattening (step 2b). Default: off.
  bool merge_charts = false;
  /// Largest area distortion of a merged chart (mean_area_distortion's measure, >= 1), unless its
  /// parts already had more. Default: 1.5.
  double max_merge_distortion = 1.5;
};

struct BaseMeshAtlasResult {
  int num_charts = 0;
  std::vector<std::size_t> chart_faces;  ///< faces per chart
  /// uv units per unit of 3D length (the one uniform scale of every chart).
  double uv_per_length = 0;
  /// Area-weighted mean over faces of max(a3d/auv, auv/a3d) after normalisation (1 = none).
  double mean_area_distortion = 0;
  /// Faces whose uv triangle has non-positive signed area (flipped by LSCM).
  std::size_t flipped_faces = 0;
  /// Fraction of [0,1]^2 covered by charts.
  double packing_efficiency = 0;
};

/// Segments `mesh` into disc charts, flattens and packs them; see the header comment.
BaseMeshAtlasResult compute_base_mesh_atlas(Mesh& mesh, const BaseMeshAtlasOptions& opt = {});

}  // namespace surftex
