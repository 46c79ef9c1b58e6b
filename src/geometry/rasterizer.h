// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A small software rasterizer for previews and validation renders (docs/DESIGN.md:
// "a software rasterizer renders results to images, no GPU needed").
//
// Clip-space clipping, 1/256-sample fixed point, exact integer edge functions
// with a top-left rule (shared edges covered exactly once), a visibility
// z-buffer shaded once per sample, N x N supersampling; perspective-correct
// attributes. Tiles rendered in parallel: same bytes for any thread count.
// In full: docs/decisions/607-rasterizer.md.
//
// This header and its .cpp use no CGAL: image code may include it freely.
// Build a RenderMesh from a surftex::Mesh with geometry/render_mesh.h.

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

#include "geometry/image.h"

namespace surftex {

using Vec3f = std::array<float, 3>;
using Vec2f = std::array<float, 2>;

/// Triangles ready to draw. Every optional array is either empty or has the
/// stated size; render() checks this.
struct RenderMesh {
  std::vector<Vec3f> positions;                ///< world coordinates
  std::vector<std::array<int, 3>> triangles;   ///< indices into positions
  std::vector<Vec3f> vertex_colors;            ///< optional, one per position, linear RGB
  std::vector<Vec2f> corner_uvs;               ///< optional, 3 per triangle (corner k of t at 3t+k); v up
  std::vector<Vec3f> vertex_normals;           ///< optional, one per position (need not be unit)
  std::vector<int> triangle_face;              ///< optional, source face id per triangle
};

/// Axis-aligned box.
struct BBox3f {
  Vec3f min{0.f, 0.f, 0.f};
  Vec3f max{0.f, 0.f, 0.f};
};

/// Box around all positions referenced or not (throws InvalidInputError if
/// `mesh` has no positions or a non-finite one).
BBox3f bounding_box(const RenderMesh& mesh);

/// A pinhole (perspective) or orthographic camera looking from `eye` at
/// `target`; `up` fixes the roll (it need not be orthogonal to the view
/// direction, only not parallel to it). The image aspect ratio comes from the
/// render size.
struct Camera {
  enum class Projection { Perspective, Orthographic };
  Projection projection = Projection::Perspective;
  Vec3f eye{0.f, 0.f, 3.f};
  Vec3f target{0.f, 0.f, 0.f};
  Vec3f up{0.f, 1.f, 0.f};
  float fov_y_deg = 35.f;          ///< perspective: vertical field of view, (0, 180) degrees
  float ortho_half_height = 1.f;   ///< orthographic: half the view height, world units, > 0
  /// Distance along the view direction below which geometry is clipped away,
  /// world units. Perspective needs > 0; orthographic allows any finite value.
  float near_plane = 0.01f;
};

/// A camera on the sphere around `box`: azimuth about world +Y (0 = from +Z),
/// elevation towards +Y (-90..90 deg); the nearest view (perspective, 35 deg
/// vertical) keeping the box inside with a 5% margin. Throws InvalidInputError
/// on non-finite angles or aspect <= 0.
Camera fit_camera(const BBox3f& box, float azimuth_deg, float elevation_deg,
                  Camera::Projection projection = Camera::Projection::Perspective,
                  float aspect = 1.f);

/// Per-fragment colour: triangle index (into RenderMesh::triangles) and
/// perspective-correct barycentrics of the sample w.r.t. that triangle's three
/// corners (non-negative up to rounding, summing to 1). Returns linear RGB.
/// Called concurrently from several threads: it must be thread-safe.
using FragmentCallback = std::function<Vec3f(int triangle, const Vec3f& barycentric)>;

struct RenderOptions {
  int width = 1024;   ///< output pixels, 1..16384
  int height = 1024;  ///< output pixels, 1..16384
  int supersample = 2;  ///< N: N x N samples per pixel, box-averaged; 1..4
  Vec3f background{1.f, 1.f, 1.f};  ///< colour of uncovered samples

  enum class ColorSource { Constant, VertexColors, Texture, Callback };
  ColorSource color_source = ColorSource::Constant;
  Vec3f constant_color{0.8f, 0.78f, 0.74f};  ///< ColorSource::Constant
  /// ColorSource::Texture: sampled bilinearly at the corner UVs (u right, v up:
  /// v = 0 is the bottom row). 1 channel = grey, >= 3 channels = the first 3.
  const Image* texture = nullptr;
  /// Texture coordinates outside [0,1]: Repeat, Clamp (to the edge texel) or
  /// Mirror (there and back: glTF MIRRORED_REPEAT).
  enum class Wrap { Repeat, Clamp, Mirror };
  Wrap wrap = Wrap::Repeat;
  FragmentCallback callback;  ///< ColorSource::Callback

  /// Lambert + ambient shading; off = the base colour as is.
  bool shade = true;
  float ambient = 0.25f;  ///< [0,1]: colour = base * (ambient + (1 - ambient) * max(0, n.l))
  /// Direction towards the light in the camera frame (right, up, towards the
  /// viewer); need not be unit. Default: from the camera, slightly above-left.
  Vec3f light_direction{-0.35f, 0.45f, 1.f};
};

struct RenderResult {
  Image color;     ///< width x height x 3, linear RGB
  Image depth;     ///< width x height x 1: nearest view depth (world units along the view direction), +inf where empty
  Image coverage;  ///< width x height x 1: fraction of the pixel's samples covered, in [0,1]
  /// Samples that passed the edge test before the depth test (a crack check).
  std::size_t fragments = 0;
  std::size_t triangles_drawn = 0;    ///< screen triangles after clipping and culling
  std::size_t triangles_clipped = 0;  ///< input triangles that needed clipping
};

/// Renders `mesh` seen by `camera`. Throws InvalidInputError (naming the
/// field and value) on out-of-range options, a bad camera, indices out of
/// range, non-finite positions, or attribute arrays of the wrong size for the
/// chosen colour source.
RenderResult render(const RenderMesh& mesh, const Camera& camera, const RenderOptions& options);

/// Bilinear texture lookup at (u, v) with v up, as render() does: texel
/// centres at ((i + 0.5) / width, 1 - (j + 0.5) / height). Returns RGB.
Vec3f sample_texture(const Image& texture, float u, float v, RenderOptions::Wrap wrap);
/// The same with a wrap per axis (glTF wrapS / wrapT).
Vec3f sample_texture(const Image& texture, float u, float v, RenderOptions::Wrap wrap_u, RenderOptions::Wrap wrap_v);

}  // namespace surftex
