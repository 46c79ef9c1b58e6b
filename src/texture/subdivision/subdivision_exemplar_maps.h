// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Other maps of the exemplar (height, roughness, tangent-space normal)
// carried through one subdivision synthesis (issue 16 item 2: "one synthesis,
// every channel"; Bangay & Morkel 2006 colour vertices, so every map becomes
// a per-vertex value). The map is resampled as the exemplar was
// (resample_as_synthesised), built into the same stack or pyramid
// (make_exemplar_levels, same bounded levels), and read at every final
// vertex exactly where its colour was read (SubdivisionSynthesisResult::
// lookup: level and bilinear position), in float. A vertex without a lookup
// (a face point whose colour is its face's average and was never matched,
// rare) takes the mean of its neighbours' values, spread ring by ring; with no
// lookup at all, the map's mean.
//
// Normal maps: channels 0-2 = (n + 1) / 2 in the exemplar's frame, x along
// its columns (+u, right), y up the image (+v, "+Y up"). The synthesis lays
// the exemplar at vertex P with +x along P's field direction d (kVertexDirection
// projected into P's tangent plane, k_region_matching.h) and the image's up
// along n x d (a region vertex at local v > 0 reads a row above the centre's),
// so the object-space normal is x d + y (n x d) + z n, n = the vertex normal
// the synthesis uses (polygon_vertex_normals). Tilts and flat normals thus
// keep their meaning on the surface; texture/tangent_space_bake.h turns them
// into a viewer's tangent space.

#include <array>
#include <cstddef>
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

/// One channel per vertex: the luminance (Rec. 709) of a 3-channel map, else the values.
std::vector<float> vertex_luminance(const VertexMapValues& v);

}  // namespace surftex
