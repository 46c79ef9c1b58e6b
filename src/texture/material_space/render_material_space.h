// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Rendering a material-space mapping (Ray et al. 2009, section 3): the
// rasterizer's per-fragment callback that looks the 3D tile up at the
// fragment's (s,t,m), either plainly (the face's own corner coordinates
// interpolated: shows the PGP's singular zones as seams and poles) or with the
// section-3 fix (three lookups in the charts of the face's three vertices,
// blended by the barycentrics; texture/material_space/pgp_singularities.h), and a
// normal-map variant of both.
//
// Normal map (our choice): the tile's luminance as height, its slopes tilting
// the shading normal along the chart's unit s and t directions,
// n' = normalize(n - bump_strength (dh/ds u_s + dh/dt u_t)), blended with the
// fix; lit two-sided by the callback (render with shade = false). The
// callback references `mesh`, `sing`, `tile` (must outlive it); the
// RenderMesh must come from make_render_mesh of the same triangle mesh.
// Throws InvalidInputError (triangle_face absent or unknown, bad options).

#include "texture/material_space/pgp_singularities.h"
#include "geometry/rasterizer.h"
#include "texture/material_space/material_tile_io.h"

namespace surftex {

struct MaterialRenderOptions {
  enum class Lookup { Plain, Blended };
  Lookup lookup = Lookup::Blended;  ///< Plain = no singularity fix
  enum class Output { Color, NormalMap };
  Output output = Output::Color;
  /// NormalMap: tilt per unit slope (height per period), >= 0. Default 0.03
  /// (a one-texel step of a 64-texel tile tilts by about 1 radian).
  double bump_strength = 0.03;
  Vec3f base_color{0.8f, 0.78f, 0.74f};  ///< NormalMap: albedo
  Vec3f light_world{0.3f, 0.5f, 1.f};    ///< NormalMap: direction towards the light, world frame
  float ambient = 0.25f;                 ///< NormalMap: [0,1]
};

FragmentCallback material_space_fragment(const RenderMesh& mesh, const PgpSingularities& sing,
                                         const MaterialTile& tile, const MaterialRenderOptions& options = {});

/// A camera-frame light direction (RenderOptions::light_direction: right, up,
/// towards the viewer) expressed in world coordinates for `camera`.
Vec3f light_direction_world(const Camera& camera, const Vec3f& light_camera);

/// The three views `material-map` renders (size x size, camera fitted at the
/// azimuth and elevation): plain lookups (the singularities show), blended
/// lookups (section 3's fix), and the blended normal map lit (`bump` as
/// MaterialRenderOptions::bump_strength).
struct MaterialViews {
  Image plain, fixed, normal;
};
MaterialViews render_material_views(const Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile,
                                    int size, float azimuth_deg, float elevation_deg, double bump);

}  // namespace surftex
