// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A triangle copy of a polygon mesh that stays a valid manifold mesh, for code
// that wants triangles (atlases, bakes) while the polygons are kept elsewhere.
// Faces are fanned with the vertex indices kept (quads split along the shorter
// diagonal). A fan diagonal that already exists as an edge (of the mesh, or of
// another face's fan) would make the result non-manifold; that happens on
// messy input, e.g. around valence-2 vertices. The other fan starts are tried,
// and if every start has such a diagonal, the face's fan is built on copies of
// its vertices (same positions): a separate small component.
//
// Copies kVertexColor when present. Throws TopologyError if a triangle cannot
// be added.

#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

/// Replaces `out` by the triangle copy of `mesh`; returns the source vertex
/// index (in `mesh`) of every vertex of `out`, by vertex index: the first
/// mesh.number_of_vertices() are the vertices themselves, then the copies.
std::vector<std::uint32_t> triangulated_copy(const Mesh& mesh, Mesh& out);

}  // namespace surftex
