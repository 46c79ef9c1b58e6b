// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Multi-chart texture atlas of a base mesh (Zhou et al. 2006, "Mesh Quilting",
// section 3.2: "we build a texture atlas for M_base"; their figure 6 shows a
// low-distortion multi-chart atlas of the bunny). The paper does not say how
// the atlas is made; this is a careful, simple choice:
//
// 1. Segmentation (geometry/disc_chart.h): greedy region growing. Seeds are taken in face-index order
//    (the first face not yet in a chart); a chart grows breadth-first over
//    edges and accepts a face when (a) its normal is within
//    `max_normal_angle_deg` of the seed face's normal, (b) the chart has fewer
//    than `max_chart_faces` faces, and (c) the chart stays a topological disc:
//    the face shares exactly one edge with the chart and its opposite vertex is
//    not yet in the chart, or it shares two edges (fills a notch). Sharing all
//    three edges (closing the chart into a sphere) is refused. After growing,
//    every chart is verified to be a disc (Euler characteristic V-E+F = 1 and
//    exactly one border loop); a chart that fails throws TopologyError (this
//    is an internal invariant and does not happen on manifold input).
// 2. Flattening (geometry/disc_chart.h): each chart is copied into its own Surface_mesh and flattened
//    with CGAL's LSCM (Surface_mesh_parameterization::LSCM_parameterizer_3,
//    two pinned vertices chosen by CGAL). A chart whose flattening comes out
//    with negative total signed area is mirrored. The chart is then scaled so
//    that its uv area equals its 3D area (so every chart has the same
//    uv-per-length scale before packing) and rotated to its minimal-area
//    bounding box among 16 angles. LSCM can fold a chart over itself (its
//    border crosses itself); such a chart is regrown into discs of at most half its faces, each flattened
//    the same way, until every flattening is an embedding.
// 2b. Merging (`merge_charts`; Sander et al. 2001, "Texture mapping progressive
//    meshes", section 4.1: greedy merging of adjacent charts into discs): the
//    chart of smallest 3D area first is merged into the neighbour sharing the
//    longest border with it for which (a) the union has at most
//    `max_chart_faces` faces and is a disc, (b) its LSCM flattening is an
//    embedding, (c) its area distortion is at most max(`max_merge_distortion`,
//    the parts' area-weighted one), and (d) its bounding box with the packing
//    gap (`margin` of the estimated side) around it is smaller than the two
//    parts' together. Many small charts otherwise spend the atlas on gaps.
// 3. Packing: shelf packing of the chart bounding boxes (tallest first) into a
//    square-ish strip, a gap of `margin` (as a fraction of the final atlas
//    side) around every chart, then one uniform scale into [0,1]^2. All
//    charts share one scale: uv_per_length in the result.
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
