// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Patch-based oriented surface texture synthesis (Gorla, Interrante & Sapiro
// 2003): the whole pipeline of sections 3 and 4, with multi-texturing (5).
//
// 1. near-planar patches (3.1), split where their projection overlaps (3.2);
// 2. a direction field (4): Constant (projected "up"), Kmax / Kmin (signed
//    curvature), KmaxAbs / KminAbs (unsigned) or None; principal directions
//    smoothed from the top `constraint_fraction` anisotropic faces;
// 3. each patch flattened with rotated neighbour triangles, rasterised (3.2)
//    at one texel for all: the resolution's, raised (ours) when it would show
//    fewer than min_exemplar_widths exemplar widths across the mesh
//    (decision 211), lowered if one atlas cannot hold the rasters;
// 4. patches visited in Random or Curvature order (4);
// 5. each synthesised by two-pass Efros-Leung (3.3), already synthesised
//    neighbours as Known pixels, oriented per pixel (3.3.2);
// 6. `resynthesize` patches redone (4.1); 7. Boundary pixels filled from
//    their neighbours. Multi-texturing (5): exemplar floor(t E) from
//    Illumination, Curvature, Height or VertexScalar.
// Seeded per patch and pass; patches run as TBB tasks once their preceding
// neighbours are done, same bytes for any thread count. In full:
// docs/decisions/505-efros-leung-details.md.
//
// Writes kFacePatch, kFaceDirection (unless field None), kVertexKmax/Kmin/
// Dmax/Dmin when curvature is needed, kVertexNormal. Throws InvalidInputError
// (bad options, no exemplar, exemplars with different channel counts,
// vertex scalar of the wrong size, resynthesize id out of range), plus what
// the stages throw.

#include <array>
#include <cstdint>
#include <vector>

#include "texture/patches/flatten_patch.h"
#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "texture/patches/partition_near_planar.h"
#include "texture/patches/patch_atlas.h"
#include "geometry/progress.h"
#include "texture/efros_leung.h"

namespace surftex {

enum class PatchField { None, Constant, Kmax, Kmin, KmaxAbs, KminAbs };
enum class PatchOrder { Random, Curvature };
enum class MultiTexture { None, Illumination, Curvature, Height, VertexScalar };

struct PatchSynthesisOptions {
  PartitionOptions partition;
  FlattenOptions flatten;        ///< resolution = texels per patch side (default 128)
  /// Efros-Leung settings (window, preselect, rotations, order, ...). `seed`
  /// and `progress` inside are ignored (set per patch from the fields below).
  ElOptions el;
  PatchField field = PatchField::Constant;
  std::array<double, 3> constant_vector{0.0, 1.0, 0.0};  ///< PatchField::Constant, non-zero
  /// Share of faces (0, 1] whose principal directions constrain the smooth
  /// field for the principal choices. Default 0.2.
  double constraint_fraction = 0.2;
  PatchOrder order = PatchOrder::Random;
  MultiTexture multi = MultiTexture::None;
  std::array<double, 3> light{0.3, 0.8, 0.5};        ///< towards the light (Illumination)
  std::array<double, 3> height_axis{0.0, 1.0, 0.0};  ///< Height
  std::vector<double> vertex_scalar;                 ///< VertexScalar: one per vertex index
  /// Patch ids to re-synthesise after the main pass (each 0..patches-1).
  std::vector<int> resynthesize;
  /// The rasters must pack into one atlas of these options (pack_patch_atlas)
  /// before any synthesis: when they do not, fit_resolution lowers
  /// flatten.resolution by eighths (down to 16) until they do; otherwise, or
  /// below 16, InvalidInputError. check_atlas = false skips the check.
  PatchAtlasOptions atlas;
  bool check_atlas = true;
  bool fit_resolution = true;
  /// Texture scale floor (ours): with fit_resolution, when the patches'
  /// common texel would show fewer than this many widths of exemplar 0
  /// across the mesh's longest bounding-box side, flatten.resolution (and the
  /// margin with it) is raised so that it shows them (then lowered again only
  /// if one atlas cannot hold the rasters). subdiv's --texel-size Nx counts
  /// in the same terms. >= 0, 0 = off. Default 1.
  double min_exemplar_widths = 1.0;
  std::uint64_t seed = 1;
  ProgressCallback progress;  ///< stages "partition", "field", "flatten", "synthesis"
};

struct PatchSynthesisResult {
  PartitionResult partition;
  FlattenResult flat;            ///< rasters per patch (pixel states, faces, barycentrics)
  std::vector<Image> images;     ///< per patch, its raster window (FlatPatch::bw x bh), exemplar channels
  /// Per patch and pixel: where an Inside pixel's value came from
  /// (efros_leung.h ElSource; exemplar -1 elsewhere), to resample other maps
  /// of the exemplar through the same synthesis (texture/patches/patch_exemplar_maps.h).
  std::vector<std::vector<ElSource>> sources;
  std::vector<int> order;        ///< patch ids in synthesis order (main pass)
  int split_patches = 0;         ///< patches split because their projection overlapped
  int resolution = 0;            ///< texels per patch side used (flatten.resolution unless raised or lowered)
  /// flatten.resolution, or the resolution min_exemplar_widths raised it to
  /// (before any lowering to fit the atlas).
  int resolution_wanted = 0;
  /// Widths of exemplar 0 across the mesh's longest bounding-box side at
  /// flatten.resolution's texel, and at the texel used.
  double exemplar_widths_partition = 0, exemplar_widths = 0;
  std::size_t texels = 0;        ///< pixels synthesised (main pass + resynthesis)
  std::size_t seeded = 0;        ///< of which seeded by random patches
  std::size_t known_boundary = 0;  ///< Known boundary pixels given to the synthesis
  /// First-pass candidates ranked, and pixels whose approximate short list was
  /// widened for ties (ElResult::pass1_candidates, pass1_widened), summed.
  std::size_t pass1_candidates = 0, pass1_widened = 0;
  double seconds_partition = 0, seconds_field = 0, seconds_flatten = 0,
         seconds_synthesis = 0, seconds_total = 0;
};

PatchSynthesisResult synthesize_patches(Mesh& mesh, const std::vector<Image>& exemplars,
                                        const PatchSynthesisOptions& options = {});

}  // namespace surftex
