// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Flattening of near-planar patches into fixed-resolution rasters with
// boundary conditions (Gorla, Interrante & Sapiro 2003, section 3.2).
//
// Per patch (kFacePatch): the seed triangle's plane (Figure 4); patch
// triangles projected onto it; neighbouring triangles ROTATED about their
// shared edge into it (the paper), ring by ring up to boundary_rings (ours:
// ring 1 alone leaves gaps); boundary triangles overlapping (exact test) are
// dropped; a patch overlapping itself is split (split_overlapping_patches).
// Raster: res x res per patch at one texel size for all, rows along the
// texture's +x at the seed (kFaceDirection when present), pixel centres on
// one world lattice (patches on a plane share one grid); pixels Inside,
// Boundary or Outside, each with its face and barycentrics. In full:
// docs/decisions/505-efros-leung-details.md.
//
// Reads kFacePatch, kFaceDirection (optional). split_overlapping_patches writes kFacePatch. Throws
// InvalidInputError (missing kFacePatch, a face without patch, bad options,
// non-triangle faces).

#include <array>
#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

enum class PatchPixel : std::uint8_t { Inside = 0, Boundary = 1, Outside = 2 };

struct FlattenOptions {
  int resolution = 128;     ///< raster side, pixels, 8..4096
  int margin = 4;           ///< pixels kept around the largest patch, 0..resolution/4
  int boundary_rings = 2;   ///< rings of neighbour triangles unfolded, 0..4
};

using Uv2 = std::array<double, 2>;

struct FlatTriangle {
  int face = -1;                  ///< mesh face index
  std::array<Uv2, 3> corner{};    ///< plane coordinates of face_vertices order (world units)
  int ring = 0;                   ///< 0 = patch triangle, >= 1 = boundary ring
};

struct FlatPatch {
  int id = -1;
  int seed_face = -1;
  std::array<double, 3> origin{}, e1{}, e2{}, normal{};  ///< plane frame
  std::vector<FlatTriangle> triangles;  ///< patch triangles (ring 0)
  std::vector<FlatTriangle> boundary;   ///< kept rotated neighbour triangles
  std::size_t dropped_boundary = 0;     ///< neighbour triangles dropped for overlap
  // Raster: pixel (x, y) centre is at (u0 + (x + 0.5) * texel, v0 - (y + 0.5) * texel).
  int res = 0;
  double texel = 0, u0 = 0, v0 = 0;
  // Stored window of the res x res raster: the bounding box of its Inside and
  // Boundary pixels (1 x 1 at the origin when there are none; 0 x 0 before
  // flatten_patches rasterises); every pixel outside it is Outside. The
  // arrays below, and every image laid over the patch, hold the window only
  // (bw * bh, row-major): a small patch's raster is mostly Outside, and
  // thousands of full rasters cost gigabytes.
  int bx = 0, by = 0, bw = 0, bh = 0;
  std::vector<PatchPixel> pixel;                  ///< bw*bh, row-major
  std::vector<int> pixel_face;                    ///< mesh face, -1 for Outside
  std::vector<std::array<float, 3>> pixel_bary;   ///< barycentrics in that face
  bool in_window(int x, int y) const { return x >= bx && y >= by && x < bx + bw && y < by + bh; }
  /// Window index of raster pixel (x, y), which must be in the window.
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y - by) * bw + static_cast<std::size_t>(x - bx);
  }
  /// State of raster pixel (x, y) (Outside beyond the window).
  PatchPixel state(int x, int y) const { return in_window(x, y) ? pixel[index(x, y)] : PatchPixel::Outside; }
  /// Raster position of window index i.
  int raster_x(std::size_t i) const { return bx + static_cast<int>(i % static_cast<std::size_t>(bw)); }
  int raster_y(std::size_t i) const { return by + static_cast<int>(i / static_cast<std::size_t>(bw)); }
  /// Image position (pixel units, continuous: texel centres at +0.5) of plane point (u, v).
  std::array<double, 2> to_pixel(double u, double v) const {
    return {(u - u0) / texel, (v0 - v) / texel};
  }
};

struct FlattenResult {
  std::vector<FlatPatch> patches;  ///< indexed by patch id
  double texel = 0;                ///< common texel size, world units
  std::size_t inside_pixels = 0, boundary_pixels = 0;
  std::size_t dropped_boundary = 0;
};

/// Exact test: do the interiors of 2D triangles a and b intersect? (Touching
/// along edges or at vertices is not an overlap; degenerate triangles never
/// overlap.) Uses CGAL's exact orientation predicate.
bool triangles_overlap_2d(const std::array<Uv2, 3>& a, const std::array<Uv2, 3>& b);

/// Pairs (face a, face b) of patch triangles whose projections overlap.
std::vector<std::array<int, 2>> patch_overlaps(const FlatPatch& patch);

/// Flattens one patch (plane, triangles, boundary rings) without raster.
/// `seed_face` is the patch's reference triangle.
FlatPatch flatten_patch_geometry(const Mesh& mesh, int patch, int seed_face, int boundary_rings);

/// Splits patches whose projection overlaps itself: new patches grow from their
/// lowest face over the leaving triangles (within max_angle_deg); updates
/// `seed_faces`; returns the number split. Writes kFacePatch.
int split_overlapping_patches(Mesh& mesh, std::vector<int>& seed_faces, double max_angle_deg,
                              int max_rounds = 8);

/// Flattens and rasterises every patch of kFacePatch. seed_faces[p] is the
/// reference triangle of patch p (partition_near_planar's seed_face); it must
/// belong to patch p.
FlattenResult flatten_patches(const Mesh& mesh, const std::vector<int>& seed_faces,
                              const FlattenOptions& options = {});

struct Image;

/// Bilinear lookup at raster position (px, py) of an image laid over patch
/// `fp` (window-sized, see FlatPatch), restricted to its Inside pixels (weights renormalised); writes
/// img.channels values to `out`; false if none of the four texels is Inside.
bool sample_inside(const FlatPatch& fp, const Image& img, double px, double py, float* out);

}  // namespace surftex
