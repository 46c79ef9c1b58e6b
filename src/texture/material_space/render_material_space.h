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
// Normal map (the choice we make, the paper only says "normal maps"): the
// tile's luminance is a height field h(s,t,m) in [0,1]; its slopes dh/ds,
// dh/dt (central differences one texel apart, in height per period) tilt the
// interpolated shading normal n along the unit texture-space directions of the
// chart in the triangle (u_s = grad s / |grad s|, u_t likewise):
//   n' = normalize(n - bump_strength (dh/ds u_s + dh/dt u_t)).
// With the fix the three perturbed normals are blended by the barycentrics.
// The fragment is then lit by a two-sided Lambert term, so render it with
// RenderOptions::shade = false (the callback does the shading).
//
// The callback keeps references to `mesh`, `sing` and `tile`: they must
// outlive it. The RenderMesh must come from make_render_mesh of the triangle
// mesh the singularities were computed on (its triangle_face maps triangles
// to faces and its corner k is the PGP corner k: target(halfedge(f)), next,
// next-next). Throws InvalidInputError if triangle_face is absent or names a
// face the singularities do not know, or options are out of range.

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
