// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The exported asset of a subdivision synthesis (Bangay & Morkel 2006 colour
// vertices; viewers want textures): the vertex colours baked into a gutter
// atlas of a triangle copy of the mesh, with the PBR set of texture/pbr_maps.h.
//
// Steps: triangle copy (geometry/triangulated_copy.h), gutter atlas
// (geometry/gutter_atlas.h), colour bake (geometry/bake_vertex_colors.h): the
// exemplar read between the vertices through their lookups where the sources
// are given (SurfaceExemplarSource), else the vertex colours blended; then the
// maps: height = the exemplar height baked like the colour, else the
// luminance of the colour atlas; normal = the exemplar
// normal's object-space vertex normals in the atlas's tangent frames
// (texture/tangent_space_bake.h), else from the height's slopes; roughness
// (metallicRoughness) only from the exemplar roughness. With a texel size, the
// colour jumps across the atlas's chart seams are measured
// (texture/surface_fidelity.h, issue 18 item 3).
//
// Also here: the exemplar maps read at the final vertices, and the fidelity
// block of the report. Throws what the stages throw.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "geometry/bake_vertex_colors.h"
#include "geometry/gutter_atlas.h"
#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "texture/subdivision/subdivision_exemplar_maps.h"
#include "texture/subdivision/subdivision_synthesis.h"
#include "texture/surface_fidelity.h"

namespace surftex {

/// Maps given beside the colour exemplar, each the exemplar's size, empty
/// when not given: tangent-space normal (RGB), height and roughness.
struct SubdivisionExemplarMaps {
  Image normal, height, roughness;
};

/// The colour and the exemplar's height and roughness read between the
/// vertices (SurfaceExemplarSource); empty = the vertex values blended.
struct SubdivisionSurfaceSources {
  std::optional<SurfaceExemplarSource> color, height, roughness;
};

/// Per-vertex values of the exemplar maps, by vertex index of the
/// synthesised mesh; empty = not given.
struct SubdivisionVertexMaps {
  std::vector<float> height, roughness;        ///< luminance of the map
  std::vector<std::array<float, 3>> normal;    ///< object-space unit normals
  std::size_t filled = 0;  ///< vertices without a lookup (of the last map read)
  SubdivisionSurfaceSources between;  ///< what the atlas bakes where set
};

/// The sources of the mesh as synthesised (before any displacement): the
/// colour (fallback kVertexColor) and each given height and roughness map,
/// `width` x `height` = the exemplar as given. Where the synthesis reduced the
/// exemplar for the vertex budget (a stack), they read the maps as given and
/// `input_exemplar` (when given; else the exemplar as synthesised) at their
/// own resolution, through the lookups scaled to it; the bake then reads the
/// stack level its atlas's density asks (SubdivisionAsset::color_stack_level).
/// Throws InvalidInputError if input_exemplar is not width x height.
SubdivisionSurfaceSources subdivision_surface_sources(const Mesh& mesh, const SubdivisionSynthesisResult& result,
                                                      const SubdivisionExemplarMaps& maps, int width, int height,
                                                      const Image* input_exemplar = nullptr);

/// The maps read where each final vertex's colour was read
/// (texture/subdivision/subdivision_exemplar_maps.h); `width` x `height` is
/// the exemplar's size as given to the synthesis.
SubdivisionVertexMaps exemplar_maps_at_vertices(const Mesh& mesh, const SubdivisionSynthesisResult& result,
                                                const SubdivisionExemplarMaps& maps, int width, int height);

/// The report's "fidelity" block: the colour between the vertices (what the
/// atlas bakes, subdivision_surface_sources) resampled in charts at the
/// synthesis texel against the exemplar as synthesised; {"error": reason}
/// when no chart fits (tiny or very thin meshes).
nlohmann::json subdivision_fidelity_report(const Mesh& mesh, const SubdivisionSynthesisResult& result,
                                           std::uint64_t seed);

struct SubdivisionAssetOptions {
  int atlas_size = 1024;           ///< atlas width = height, texels (gutter_atlas range)
  double bump = 2;                 ///< normal tilt per unit height slope, height per exemplar texel, >= 0
  double texels_per_length = 1;    ///< exemplar texels per mesh unit, > 0 (scales `bump` to atlas texels)
  double texel_size = 0;           ///< synthesis texel, mesh units; > 0 measures the atlas seams
  /// Largest atlas chart, triangles, >= 1. Default 8000: the 4000 of other
  /// atlases cut a 300K-vertex hierarchy into ~320 charts whose gutters took
  /// half the atlas; 16000 kept 7-10% more texels for twice the chart
  /// merging time (decision 208).
  std::size_t max_chart_faces = 8000;
};

struct SubdivisionAsset {
  /// The triangle copy: kVertexColor, kCornerUV (atlas), kFacePatch (chart).
  std::unique_ptr<Mesh> mesh;
  GutterAtlas atlas;
  BakeResult color;                ///< the baked vertex colours (image = base colour)
  Image height, normal, metallic_roughness;  ///< metallic_roughness empty without a roughness map
  SubdivisionAssetOptions options;
  double atlas_texels_per_exemplar_texel = 0;
  bool normal_from_exemplar = false, height_from_exemplar = false;
  bool color_between_vertices = false;  ///< the colour from SubdivisionSurfaceSources, not the vertex colours
  int color_stack_level = 0;            ///< the source's stack level the colour bake read (prefilter)
  double color_map_scale = 1;           ///< the source's pixels per synthesis texel (> 1: the exemplar as given)
  bool seam_measured = false;      ///< options.texel_size > 0
  SurfaceSeamRatio seam;           ///< colour jumps across the atlas's chart seams
  double seconds = 0;              ///< the whole bake

  SubdivisionAsset();
  ~SubdivisionAsset();
  SubdivisionAsset(SubdivisionAsset&&) noexcept;
  SubdivisionAsset& operator=(SubdivisionAsset&&) noexcept;
};

/// The atlas side the CLI defaults to for a synthesised mesh of `vertices`
/// vertices: the smallest power of two from 1024 to 4096 whose charts, at
/// the ~15% coverage measured with the mip-safe gutters (decision 209), hold
/// a texel per vertex (a synthesis texel); 1024 up to 157K vertices, 2048
/// up to 629K.
int default_subdivision_atlas_size(std::size_t vertices);

SubdivisionAsset bake_subdivision_asset(const Mesh& mesh, const SubdivisionVertexMaps& maps,
                                        const SubdivisionAssetOptions& options = {});

/// The report's "atlas" block: charts, size, coverage, gutter, gutter
/// violations, margin, protected mip size, area distortion, flipped faces,
/// bump, atlas texels per exemplar texel, map sources, roughness, "seam"
/// (with a texel size) and "seconds" {"bake"}.
nlohmann::json to_json(const SubdivisionAsset& asset);

}  // namespace surftex
