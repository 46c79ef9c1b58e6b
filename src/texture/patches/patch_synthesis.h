// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Patch-based oriented surface texture synthesis (Gorla, Interrante & Sapiro
// 2003): the whole pipeline of sections 3 and 4, with multi-texturing (5).
//
//  1. partition the mesh into near-planar patches (3.1, geometry/
//     partition_near_planar.h), then split patches whose projection overlaps
//     itself (3.2, texture/patches/flatten_patch.h);
//  2. a direction field over the faces (4, "texture orientation options"):
//       - Constant: a constant vector projected onto the tangent planes
//         (3.3.2.1; default "up" = +y), a 1-symmetric (signed) field;
//       - Kmax / Kmin: the direction of greatest / least SIGNED normal
//         curvature (kmax >= kmin of principal_curvatures.h, sign w.r.t. the
//         outward normal: kmax is the "most convex" direction);
//       - KmaxAbs / KminAbs: the direction of greatest / least UNSIGNED
//         normal curvature, i.e. of max(|kmax|, |kmin|) / min(...): on a
//         saddle or concave region these swap with respect to the signed
//         choice. Principal directions are line fields (d and -d are the same
//         direction), so "signed/unsigned" refers to the curvature, never to
//         the direction vector;
//       - None: isotropic (no orientation; each patch uses its own frame).
//     Principal directions are smoothed first: the faces with the largest
//     anisotropy (|kmax - kmin|, or ||kmax| - |kmin|| for the unsigned
//     choices; the top `constraint_fraction`) constrain a smooth 2-symmetric
//     field (geometry/direction_field.h) that fills the rest;
//  3. flatten each patch onto its seed plane with rotated neighbour
//     triangles as boundary and rasterise at a fixed resolution (3.2);
//  4. visit the patches in order (4): Random = a random start (seeded), then
//     a random unsynthesised patch adjacent to the synthesised ones (a new
//     random start when none is adjacent, "filling in any holes at the end");
//     Curvature = start at and proceed to the adjacent patch with the greatest
//     mean principal curvature difference;
//  5. synthesise each patch with two-pass Efros-Leung (3.3,
//     texture/efros_leung.h): Inside pixels are Fill; Boundary pixels whose
//     neighbour patch is already synthesised are Known, their colour looked
//     up through the rotated neighbour triangle (face + barycentrics ->
//     the neighbour patch's plane -> its image, bilinear over its Inside
//     pixels); other pixels are Outside. The per-pixel angle is the field
//     interpolated at the pixel (vertex directions = sign-aligned averages of
//     face directions, blended by barycentrics) and expressed in the patch
//     plane (3.3.2: per-pixel re-orientation with pre-rotated exemplars).
//     Within a patch the fill order is el.order: OnionPeel (most constrained
//     side first, the paper's default) or Direction (swept along the patch's
//     mean field direction, "following the direction of the vector field");
//  6. re-synthesise the patches listed in `resynthesize` (4.1: the paper's
//     interactive fix-up), keeping all others as boundary conditions;
//  7. finally, fill every Boundary pixel of every patch image from its
//     neighbour (so bilinear lookups at patch edges read the neighbour's
//     texture, not garbage).
// Multi-texturing (5): with two or more exemplars, the exemplar used at a
// pixel is floor(t * E) (clamped) for t in [0,1] from Illumination (Lambert
// n.l of the interpolated normal with `light`), Curvature (mean curvature,
// normalised over the 5th..95th percentile of vertices), Height (position
// along `height_axis`, normalised over the mesh) or VertexScalar (the given
// per-vertex values, normalised over their range).
//
// Deterministic: the patch order and every Efros-Leung run are seeded from
// `seed` (per patch and pass), so the same input gives the same bytes.
// Parallel: a patch reads only the neighbours that precede it in the order,
// so it starts as soon as those are done; independent patches run as TBB
// tasks side by side, with the same result for any thread count. The
// exemplar rotations are prepared once per run (el_prepare_exemplars).
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
  std::uint64_t seed = 1;
  ProgressCallback progress;  ///< stages "partition", "field", "flatten", "synthesis"
};

struct PatchSynthesisResult {
  PartitionResult partition;
  FlattenResult flat;            ///< rasters per patch (pixel states, faces, barycentrics)
  std::vector<Image> images;     ///< per patch, res x res, exemplar channels
  /// Per patch and pixel: where an Inside pixel's value came from
  /// (efros_leung.h ElSource; exemplar -1 elsewhere), to resample other maps
  /// of the exemplar through the same synthesis (texture/patches/patch_exemplar_maps.h).
  std::vector<std::vector<ElSource>> sources;
  std::vector<int> order;        ///< patch ids in synthesis order (main pass)
  int split_patches = 0;         ///< patches split because their projection overlapped
  std::size_t texels = 0;        ///< pixels synthesised (main pass + resynthesis)
  std::size_t seeded = 0;        ///< of which seeded by random patches
  std::size_t known_boundary = 0;  ///< Known boundary pixels given to the synthesis
  double seconds_partition = 0, seconds_field = 0, seconds_flatten = 0,
         seconds_synthesis = 0, seconds_total = 0;
};

PatchSynthesisResult synthesize_patches(Mesh& mesh, const std::vector<Image>& exemplars,
                                        const PatchSynthesisOptions& options = {});

}  // namespace surftex
