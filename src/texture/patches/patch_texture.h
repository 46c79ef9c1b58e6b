// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A surface textured by patch-based oriented synthesis (Gorla, Interrante &
// Sapiro 2003), ready to export: the paper's pipeline, then its atlas and
// maps. Steps:
//  1. synthesis (sections 3-5, texture/patches/patch_synthesis.h): partition
//     into near-planar patches, direction field, flattening, two-pass
//     Efros-Leung per patch in order, resynthesis, boundary fill;
//  2. atlas: the patch images packed into one texture with mip gutters
//     (texture/patches/patch_atlas.h); exemplar maps (height, tangent-space
//     normal, roughness) resampled through the same synthesis coordinates
//     (texture/patches/patch_exemplar_maps.h) and packed alike;
//  3. PBR maps (texture/pbr_maps.h): height = the exemplar height, else the
//     atlas luminance; normal = the exemplar normal, else from the height's
//     slopes (`bump` = tilt per unit height slope, height per exemplar texel:
//     one atlas texel is one exemplar texel); roughness as metallicRoughness;
//  4. seam figure: colour jumps across patch seams on the surface against
//     those within patches (texture/patches/patch_seam_ratio.h);
//  5. fidelity against the exemplar (texture/surface_fidelity.h, issue 18
//     item 3).
// Writes what synthesize_patches and pack_patch_atlas write (kFacePatch,
// kFaceDirection, kCornerUV, ...). Throws what the stages throw.

#include <vector>

#include <nlohmann/json.hpp>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "texture/patches/patch_atlas.h"
#include "texture/patches/patch_seam_ratio.h"
#include "texture/patches/patch_synthesis.h"

namespace surftex {

/// Maps of exemplar 0, each its size, empty when not given.
struct PatchExemplarMaps {
  Image normal, height, roughness;
};

struct PatchTextureOptions {
  PatchSynthesisOptions synthesis;  ///< its seed also seeds the seam figure and the fidelity
  double bump = 2;                  ///< normal-map strength from the height, >= 0 (default 2)
  bool pbr_maps = true;             ///< step 3 (false: colour atlas only)
  bool fidelity = true;             ///< step 5
};

struct PatchTextureResult {
  PatchSynthesisResult synthesis;
  PatchAtlas atlas;                 ///< the colour atlas
  Image height, normal, metallic_roughness;  ///< empty without pbr_maps; metallic_roughness without a roughness map
  bool height_from_exemplar = false, normal_from_exemplar = false;
  double bump = 0;
  int patch_resolution = 0;         ///< texels per patch side used
  int requested_resolution = 0;     ///< the options', or raised for the texture-scale floor (larger when lowered to fit one atlas)
  int synthesis_options_resolution = 0;  ///< the options' flatten.resolution
  SeamRatioResult seam;
  double seam_step_texels = 0;
  nlohmann::json fidelity;          ///< atlas_fidelity_report (null without `fidelity`)
  double cpu_seconds_synthesis = 0; ///< process CPU time of step 1 (all threads)
  double seconds_atlas = 0, seconds_seam = 0, seconds_total = 0;
};

PatchTextureResult synthesize_patch_texture(Mesh& mesh, const std::vector<Image>& exemplars,
                                            const PatchExemplarMaps& maps, const PatchTextureOptions& options = {});

/// The report's figures: patch counts, texel counts and rate, "seconds"
/// {partition, field, flatten, synthesis, atlas, seam_metric, total},
/// synthesis_share, "seam", "atlas" (size, gutter, map sources) and "fidelity".
nlohmann::json to_json(const PatchTextureResult& result);

}  // namespace surftex
