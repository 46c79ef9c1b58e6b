// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Other maps of the exemplar (height, roughness, tangent-space normal)
// carried through one subdivision synthesis (issue 16 item 2: "one synthesis,
// every channel"; Bangay & Morkel 2006 colour vertices, so every map becomes
// Each map is resampled as the exemplar was, built into the same stack, and
// read at every final vertex where its colour was read (lookup); vertices
// without a lookup take their neighbours' mean. Normal maps ((n + 1) / 2, +x
// right, +y up) become object space x d + y (n x d) + z n, d the vertex's
// field direction, as the synthesis laid the exemplar; tangent_space_bake.h
// turns them into a viewer's tangent space. In full: decision 303.

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "texture/subdivision/subdivision_synthesis.h"

namespace surftex {

struct VertexMapValues {
  int channels = 0;           ///< 3 for maps of >= 3 channels (alpha dropped), else 1
  std::vector<float> values;  ///< channels per vertex, by vertex index
  std::size_t filled = 0;     ///< vertices without a lookup (filled from neighbours)
};

/// `map` has the input exemplar's size (the size the synthesis was given);
/// `mesh` is the synthesis's final mesh. Throws InvalidInputError if the map
/// is empty or the result does not belong to the mesh.
VertexMapValues read_map_at_vertices(const Mesh& mesh, const SubdivisionSynthesisResult& result, const Image& map,
                                     int input_width, int input_height);

/// Object-space unit normals per vertex (by index) from the values of a
/// tangent-space normal map (3 channels), through the synthesis's frames
/// (reads kVertexDirection and the positions: call on the mesh as shown).
/// Throws InvalidInputError for fewer than 3 channels or a missing field.
std::vector<std::array<float, 3>> object_normals_from_map(const Mesh& mesh, const VertexMapValues& normal_map);

/// The exemplar between the vertices (issue 18: the texture at the exemplar's
/// resolution, not the vertices'). A point of a face reads, from each of its
/// three corners, the corner's lookup carried to the point along the corner's
/// frame (u along kVertexDirection, v along n x d: k_region_matching's
/// offsets, in synthesis texels) and blends the three reads by its
/// barycentrics. Where the corners were copied by one transfer the three reads
/// agree, and the point gets the exemplar's own texel rather than a blend of
/// vertex colours; across a transfer's cut it blends the two copies over one
/// triangle. Stack lookups are read at level 0 (the antialiasing level is for
/// the vertices' own colours), pyramid ones at their level. A corner without a
/// lookup gives its `fallback` value (by vertex index).
///
/// `map`: the exemplar as synthesised (result.exemplar) or a map resampled as
/// it was (resample_as_synthesised), or see `read` below; the mesh as synthesised
/// (positions, kVertexDirection; copied: the mesh may change afterwards).
/// Thread-safe. Throws InvalidInputError if the result, the fallback or the
/// map does not fit the mesh.
///
/// With `read` the map may be the input exemplar (or map) at its own
/// resolution where the synthesis reduced it: lookups and offsets are scaled
/// by its pixels per synthesis texel, and a Gaussian stack of `levels` levels
/// is built so that a bake sparser than its pixels can read a prefiltered
/// level (at_level). A stack only: a pyramid synthesis reads the map as
/// synthesised at each lookup's level.
struct ExemplarReadOptions {
  double scale_x = 1, scale_y = 1;  ///< map pixels per synthesis texel (> 0)
  int levels = 1;                   ///< stack levels built, 1..8
};

class SurfaceExemplarSource {
 public:
  SurfaceExemplarSource(const Mesh& mesh, const SubdivisionSynthesisResult& result, const Image& map,
                        std::vector<std::array<float, 3>> fallback, const ExemplarReadOptions& read = {});
  ~SurfaceExemplarSource();
  /// RGB (grey maps repeated) at the point with these corner vertices and barycentrics.
  std::array<float, 3> operator()(const std::array<std::size_t, 3>& vertex, const std::array<double, 3>& bary) const;
  /// The same source reading stack level `level` (clamped to the levels built; 0 = sharp).
  SurfaceExemplarSource at_level(int level) const;
  int level() const { return level_; }
  int levels() const;
  /// Map pixels per synthesis texel along x (ExemplarReadOptions::scale_x).
  double scale() const;

 private:
  struct Data;
  std::shared_ptr<const Data> d_;
  int level_ = 0;
};

/// Rec. 709 luminance of an RGB value, clamped to [0, 1] (as height_from_luminance).
float clamped_luminance(const std::array<float, 3>& rgb);

/// One channel per vertex: the luminance (Rec. 709) of a 3-channel map, else the values.
std::vector<float> vertex_luminance(const VertexMapValues& v);

}  // namespace surftex
