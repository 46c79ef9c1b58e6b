// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// One look at a surftex Mesh: the rasterizer (geometry/rasterizer.h) with the
// camera fitted to the mesh (fit_camera) and the colours the mesh carries.
// The common case of the commands and benchmarks that write a render.png
// next to their outputs ("look at what you produce").
//
// Properties read: kCornerUV (h:uv) when a texture is given, kVertexColor
// (v:color) when Colors::VertexColors (or Auto and the mesh has it).

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "geometry/rasterizer.h"

namespace surftex {

struct ViewOptions {
  int size = 768;               ///< square image side, pixels (1..16384)
  float azimuth_deg = 30.f;     ///< fit_camera's azimuth about +Y
  float elevation_deg = 20.f;   ///< fit_camera's elevation, -90..90
  enum class Colors {
    Auto,          ///< Texture if `texture` is set, else VertexColors if present, else Constant
    Constant,      ///< RenderOptions::constant_color, shaded
    VertexColors,  ///< kVertexColor (throws InvalidInputError if absent)
    Texture        ///< `texture` at the corner UVs (throws if either is missing)
  };
  Colors colors = Colors::Auto;
  const Image* texture = nullptr;  ///< not owned; must outlive the call
  /// Texture lookups past [0,1]: Clamp suits atlases (charts next to empty
  /// texels), Repeat suits periodic tiles.
  RenderOptions::Wrap wrap = RenderOptions::Wrap::Clamp;
  /// The mesh's up axis. fit_camera orbits about +Y; a Z-up scene (the
  /// quilting outputs: swatch height along z) is turned (x, y, z) -> (x, z, -y)
  /// for the render, so the camera looks at it from above-front.
  enum class Up { Y, Z };
  Up up = Up::Y;
};

/// The rendered colour image (size x size x 3, linear RGB, white background).
/// Throws InvalidInputError as make_render_mesh() and render() do.
Image render_view(const Mesh& mesh, const ViewOptions& options = {});

}  // namespace surftex
