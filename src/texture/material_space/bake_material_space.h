// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Bakes a material-space mapping (Ray et al. 2009, sections 2-3) into a
// standard UV atlas, so that any viewer shows what surftex's own
// singularity-fixed render shows: every atlas texel covered by a face holds
// the (s,t,m) lookup of the 3D tile at that point, with section 3's fix (a
// point of a singular face is looked up three times, in the 1-ring charts of
// the face's three vertices, and the three colours are blended by its
// barycentrics) and the material blend of the tile (linear between the two
// layers nearest to m, texture/material_space/material_tile_io.h).
//
// Steps: atlas (base_mesh_atlas.h), texel rasterisation in uv (uv_raster.h),
// the lookups, and a mip gutter (atlas_gutter.h). The tile's maps go through
// the same lookups (height, roughness, normal); a tile normal becomes the
// object-space x S + y U + z N (S, U: directions of increasing s and
// decreasing t, orthogonalised). In full: docs/decisions/301.
//
// Reads the singularities' charts (computed on this mesh), writes kCornerUV
// (atlas uv) and kFacePatch (chart id). Throws InvalidInputError (size not in
// 64..8192, min_mip_size < 1, singularities of another mesh, non-triangle
// face), plus what the atlas throws.

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "texture/material_space/pgp_singularities.h"
#include "texture/material_space/material_tile_io.h"

namespace surftex {

struct MaterialBakeOptions {
  int size = 2048;          ///< atlas width = height, texels, 64..8192 (default 2048)
  int min_mip_size = 64;    ///< smallest mip level kept free of bleeding, >= 1 (default 64)
  bool fix_singularities = true;  ///< section 3's three lookups (false = plain lookups)
};

struct MaterialBakeResult {
  Image color;               ///< size x size x 3, linear RGB
  Image height;              ///< size x size x 1, [0,1]: the tile's height layers, else its luminance
  bool height_from_tile = false;  ///< height from the tile's height layers
  Image roughness;           ///< size x size x 1, [0,1], from the tile's roughness layers (else empty)
  /// size x size x 3, the unit object-space normal (not encoded) on the
  /// rasterised texels (raster triangle >= 0), 0 elsewhere (not dilated),
  /// from the tile's normal layers (else empty).
  Image object_normal;
  std::vector<int> chart;    ///< per texel before dilation: chart id, -1 = gutter/background
  std::vector<int> owner;    ///< per texel after dilation: the chart it belongs to
  int charts = 0;
  int gutter = 0;            ///< texels: 2^K, or less for many small charts (geometry/gutter_atlas.h)
  int protected_mip_size = 0;  ///< smallest mip side kept free of bleeding
  double margin = 0;         ///< atlas chart spacing used (fraction of the side)
  std::size_t gutter_violations = 0;  ///< texels within `gutter` of a chart not owned by it (0 wanted)
  double coverage = 0;       ///< fraction of texels covered by charts
  double texels_per_length = 0;  ///< atlas texels per mesh unit
  double seconds_atlas = 0, seconds_lookup = 0, seconds_gutter = 0;
};

MaterialBakeResult bake_material_space(Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile,
                                       const MaterialBakeOptions& options = {});

/// The tangent-space normal map ((n + 1) / 2) a glTF viewer needs to show
/// `bake.object_normal` on the GLB of the baked `mesh` (frame of
/// tangent_space_bake.h); gutters dilated. Throws InvalidInputError without
/// object normals.
Image material_space_tangent_normals(const Mesh& mesh, const MaterialBakeResult& bake);

/// The PBR set of the baked atlas (height, roughness, tangent-space normal;
/// normals from the height's slopes when the tile has none, tilt `bump` per
/// unit of height per `period`).
struct MaterialAsset {
  MaterialBakeResult bake;
  Image normal, metallic_roughness;
  std::string normal_source;  ///< "exemplar_normal" or "height"
};
MaterialAsset bake_material_asset(Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile, int atlas_size,
                                  double bump, double period);

/// The atlas figures of the report: size, charts, gutter, coverage, texel
/// density, map sources and "seconds" {atlas, lookup, gutter}.
nlohmann::json to_json(const MaterialAsset& asset);

/// The colour of the mapping at barycentrics `bary` of `face` (what the
/// fixed render shows): one lookup, or three blended on a singular face.
Vec3f material_space_color(const PgpSingularities& sing, const MaterialTile& tile, std::uint32_t face,
                           const std::array<double, 3>& bary, bool fix_singularities = true);

}  // namespace surftex
