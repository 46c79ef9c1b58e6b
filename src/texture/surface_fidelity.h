// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Surface fidelity: how close the texture a method put on a surface is to its
// exemplar, measured on the surface, one figure for every image-texture
// method (patches, subdiv, material-map; issue 18 item 3).
//
// 1. Charts: chart_texels-square windows at texel size h, centred on seeded
//    area-weighted surface points; the edge-connected faces within the normal
//    cone, projected on the seed's plane in its texture frame; a pixel is
//    valid when its centre lies in exactly one chart triangle.
// 2. Resampling: each valid pixel takes the surface colour at its centre.
// 3. Similarity: the charts side by side, bidirectional similarity with the
//    exemplar (bds); the reference bds_2d is graph-cut 2D synthesis resampled
//    and masked the same way; ratio = bds / bds_2d (1 = as good as 2D).
// 4. Seams: colour jumps across chart/patch boundaries over the mean jump
//    within, same direction (about 1 when boundaries are invisible).
// 5. Verbatim copies: the share of valid pixels on straight runs of
//    consecutive exemplar texels longer than half the exemplar.
// Every rule in full: docs/decisions/201-surface-fidelity.md.
//
// Deterministic: every random choice from `seed`; the same inputs give the
// same figures for any thread count. Throws InvalidInputError (empty mesh or
// exemplar, texel size not > 0, frames or seam flags of the wrong size, no
// valid chart at all, options out of range).

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "texture/bidirectional_similarity.h"

namespace surftex {

/// A point of the surface: its face, the three corners of the fan triangle of
/// that face holding it (halfedge indices h: the corner of face(h) at
/// target(h), kCornerUV's convention; and the corner vertices) and its
/// barycentrics over those three corners.
struct SurfacePoint {
  std::size_t face = 0;
  std::array<std::size_t, 3> corner{};  ///< halfedge indices
  std::array<std::size_t, 3> vertex{};  ///< target vertices of the corners
  std::array<double, 3> bary{};
};

/// The surface colour at a point, RGB in the exemplar's value range. Must be
/// safe to call from several threads at once.
using SurfaceColorFn = std::function<std::array<float, 3>(const SurfacePoint&)>;

/// kVertexColor interpolated over the fan triangle (a vertex-coloured mesh as
/// a PLY/GLB viewer shows it). Throws InvalidInputError if the map is absent.
/// Keeps a copy of the colours: the mesh may change afterwards.
SurfaceColorFn vertex_color_source(const Mesh& mesh);
/// An atlas image looked up bilinearly (wrapping) at the corner UVs
/// (kCornerUV, u right, v up: the rasterizer's and write_mesh's convention).
/// Keeps copies of the UVs and the image. Throws InvalidInputError if the
/// map is absent or the image empty.
SurfaceColorFn atlas_color_source(const Mesh& mesh, const Image& atlas);

/// Per-vertex exemplar sources (texel x, y; x < 0 = none) as a source
/// function for SurfaceFidelityOptions::source: interpolated over the fan
/// triangle, known only where all three corners have a source.
SurfaceColorFn vertex_source_coordinates(const std::vector<std::array<int, 2>>& per_vertex);

struct MaterialTile;
/// A material-space tile (Ray et al. 2009) looked up at each face's corner
/// (s,t,m) (`corners`: PgpSingularities::corners order). Triangles only.
SurfaceColorFn material_tile_source(const std::vector<std::array<std::array<double, 3>, 3>>& corners,
                                    const MaterialTile& tile);

/// Per face: the exemplar's +x and +y axes (image rows downwards) on the
/// surface, 3D vectors in the face's tangent plane (need not be unit; zero =
/// no orientation, such a face seeds no chart).
struct TextureFrames {
  std::vector<std::array<double, 3>> x_axis, y_axis;
};
/// From kVertexDirection (subdivision synthesis): x = mean vertex direction,
/// y = x cross n. Throws InvalidInputError if absent.
TextureFrames frames_from_vertex_directions(const Mesh& mesh);
/// From kFaceDirection (patch synthesis: the exemplar's +x drawn along the
/// field, y = x cross n). Throws InvalidInputError if absent.
TextureFrames frames_from_face_directions(const Mesh& mesh);
/// From per-corner texture coordinates in exemplar texels, (x right, y down)
/// (an atlas or a material-space parameterization): the 3D gradients of x
/// and y over each face's first fan triangle.
TextureFrames frames_from_corner_coordinates(const Mesh& mesh,
                                             const std::function<std::array<double, 2>(std::size_t halfedge)>& xy);
/// frames_from_corner_coordinates of an atlas of width x height texels read
/// through kCornerUV (u right, v up). Throws InvalidInputError without corner UVs.
TextureFrames frames_from_atlas_uv(const Mesh& mesh, int width, int height);

/// The texel size (mesh units per texel) a mapping's frames imply: the
/// area-weighted median over faces of sqrt(|x_axis| |y_axis|) (for frames
/// from corner coordinates in texels). 0 when no face has a frame.
double texel_size_of_frames(const Mesh& mesh, const TextureFrames& frames);

/// Per edge index: 1 where the two faces' corner coordinates differ at either
/// end of the edge (a chart boundary of an atlas or of a parameterization).
/// Border edges are 0.
std::vector<char> seam_edges_from_corners(const Mesh& mesh,
                                          const std::function<std::array<double, 2>(std::size_t halfedge)>& uv,
                                          double tolerance = 1e-9);
/// seam_edges_from_corners over kCornerUV (throws InvalidInputError if absent).
std::vector<char> seam_edges_from_corner_uv(const Mesh& mesh);
/// Per edge index: 1 where the two faces have different ids (patches).
std::vector<char> seam_edges_from_face_ids(const Mesh& mesh, const std::vector<int>& face_id);

struct SeamRatioSurfaceOptions {
  int chart_texels = 64;  ///< chart side, texels, 16..1024 (halved down to 16 when none fits)
  int max_charts = 48;    ///< 1..256
  std::uint64_t seed = 1;
};

struct SurfaceSeamRatio {
  double ratio = 0;  ///< orientation-matched across / within (step 4); 0 when either class is empty
  double mean_across = 0, mean_within = 0;
  std::size_t pairs_across = 0, pairs_within = 0;
  std::size_t seam_edges = 0;  ///< edges flagged in `seam_edges` (with two faces)
};

/// The seam jump ratio (file comment, step 4). `texel_size` in mesh units.
SurfaceSeamRatio surface_seam_ratio(const Mesh& mesh, const SurfaceColorFn& color, const std::vector<char>& seam_edges,
                                    double texel_size, const SeamRatioSurfaceOptions& options = {});

struct SurfaceFidelityOptions {
  /// Synthesis texel size: mesh units per exemplar texel, > 0 (required).
  double texel_size = 0;
  /// Chart side in texels, 16..1024, halved down to 16 when none fits. Default 64.
  int chart_texels = 64;
  /// Most charts, 1..256. Default 24 (about 100K texels at the default side).
  int max_charts = 24;
  /// Normal cone of a chart around its seed face's normal, degrees, (0, 89]. Default 35.
  double max_normal_angle_deg = 35.0;
  /// A chart with fewer valid pixels than this share of its window is dropped, [0, 1). Default 0.25.
  double min_valid_share = 0.25;
  /// Bidirectional similarity: patch side (default 7), output stride (default 2),
  /// the exemplar taken as periodic (default off), exact search.
  int patch = 7;
  int stride = 2;
  bool periodic_exemplar = false;
  /// Nearest-neighbour search: at most this many full distances per query
  /// (0 = unbounded), kd-tree nodes skipped unless within a factor 1 +
  /// search_eps of the best (0 = exact pruning). Defaults 256 and 3: near
  /// the exact figure for about a quarter of the work of 64 / 0
  /// (BidirectionalOptions; decision 201). Both 0 = exact.
  int max_candidates = kReportMaxCandidates;
  float search_eps = kReportSearchEps;
  /// Every exemplar_stride-th exemplar patch queries the charts for
  /// completeness (BidirectionalOptions::exemplar_stride), >= 0; 0 (default)
  /// = the smallest step >= 2 that keeps the queries at most 20000.
  int exemplar_stride = 0;
  /// Compute the graph-cut 2D reference (bds_2d, ratio). Default on.
  bool reference_2d = true;
  /// Optional: the exemplar texel of each point as (x, y, known > 0.5); when
  /// set, long_run_fraction is measured (step 5).
  SurfaceColorFn source;
  std::uint64_t seed = 1;
};

struct SurfaceFidelityResult {
  double bds = 0;      ///< coherence + completeness of the surface charts
  double bds_2d = 0;   ///< the same for graph-cut 2D synthesis under the same mask (0 if not computed)
  double ratio = 0;    ///< bds / bds_2d (0 if not computed)
  /// Share of valid texels on a verbatim run (step 5); -1 without a source.
  double long_run_fraction = -1;
  BidirectionalResult surface, reference;
  int charts = 0;                 ///< charts kept
  std::size_t valid_texels = 0;   ///< valid pixels over all charts
  double texel_size = 0;
  int chart_texels = 0;
  Image mosaic;                   ///< the charts side by side (invalid pixels 0)
  std::vector<char> mosaic_valid; ///< per mosaic pixel
  Image reference_image;          ///< the graph-cut image (masked the same way), if computed
  double seconds_charts = 0, seconds_bds = 0, seconds_reference = 0;
};

/// Steps 1-3 of the file comment. `exemplar`: 3 channels or more (the first
/// three are compared) or grey (replicated).
SurfaceFidelityResult surface_fidelity(const Mesh& mesh, const Image& exemplar, const SurfaceColorFn& color,
                                       const TextureFrames& frames, const SurfaceFidelityOptions& options);

/// The bidirectional-similarity settings surface_fidelity compares its
/// charts and the reference with (patch, stride, periodic, search; the
/// exemplar stride from the exemplar's size when 0), output_valid left empty.
BidirectionalOptions fidelity_similarity_options(const SurfaceFidelityOptions& options, const Image& exemplar);

/// The CLI's report block: to_json(surface_fidelity) plus "seam" (when
/// seam_edges is non-empty); {"error": reason} when no chart fits.
nlohmann::json fidelity_report(const Mesh& mesh, const Image& exemplar, const SurfaceColorFn& color,
                               const TextureFrames& frames, const std::vector<char>& seam_edges,
                               const SurfaceFidelityOptions& options);

/// fidelity_report of an atlas-textured mesh (kCornerUV; +x along
/// kFaceDirection or the atlas's u; seams at kFacePatch or UV cuts). `patches`.
nlohmann::json atlas_fidelity_report(const Mesh& mesh, const Image& exemplar, const Image& atlas, double texel_size,
                                     bool face_directions, std::uint64_t seed);
/// fidelity_report of a material-space mapping (tile at the corner (s,t,m),
/// exemplar = the layer at the mean material). The `material-map` report.
nlohmann::json material_map_fidelity_report(const Mesh& mesh,
                                            const std::vector<std::array<std::array<double, 3>, 3>>& corners,
                                            const MaterialTile& tile, std::uint64_t seed);

/// {"bds", "bds_2d", "ratio", "coherence", "completeness", "coherence_2d",
///  "completeness_2d", "long_run_fraction" (when measured), "charts",
///  "valid_texels", "texel_size", "chart_texels", "seconds"}.
nlohmann::json to_json(const SurfaceFidelityResult& r);
/// {"ratio", "mean_jump_across", "mean_jump_within", "pairs_across", "pairs_within", "seam_edges"}.
nlohmann::json to_json(const SurfaceSeamRatio& r);

}  // namespace surftex
