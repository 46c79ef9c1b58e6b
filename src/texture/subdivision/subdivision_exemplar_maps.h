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
