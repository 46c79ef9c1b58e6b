// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// ElementMesh: a plain indexed triangle mesh (points + triangles) used as the
// working representation of geometric-texture elements during mesh quilting
// (Zhou et al. 2006, section 2: every connected component of M_in / M_out is a
// "geometric element"). Quilting cuts, deletes and zips triangles of single
// elements many times; index arrays make these edits cheap and local, and the
// result is turned into the one mesh type (surftex::Mesh) at the end.
//
// Also here: the small topological helpers quilting needs (connected
// components, border edges, boundary loops, vertex normals, 1-rings) and the
// conversions Mesh <-> ElementMesh (writing/reading kFaceElement).
// Throws: InvalidInputError (non-triangle faces, indices out of range),
//         TopologyError (mesh_from_elements: a face Surface_mesh refuses).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

using P3 = std::array<double, 3>;
using Tri = std::array<int, 3>;

struct ElementMesh {
  std::vector<P3> points;
  std::vector<Tri> tris;
};

/// Connected components over shared vertices: component id per triangle,
/// numbered 0.. in order of first triangle. Returns the number of components.
int triangle_components(const ElementMesh& m, std::vector<int>& tri_component);
/// Undirected edges used by exactly one triangle (border edges of the element).
std::size_t count_border_edges(const ElementMesh& m);
/// Handles of an edge-manifold element given by its triangles (a ring or
/// torus 1, a pebble or a ring cut open 0), summed over its components:
/// (2 c - chi - b) / 2 with chi = V - E + F over the vertices the triangles
/// use, c components, b border loops (components of the border-edge graph).
int element_genus(const std::vector<Tri>& tris);
/// True if every undirected edge is used exactly twice, once in each direction
/// (closed, consistently oriented, edge-manifold).
bool is_closed_oriented(const ElementMesh& m);
/// Boundary loops: each a vertex sequence following the direction the border
/// edges have in their triangles (a -> b for triangle (a, b, c) with border edge
/// ab). Returns false if the border is not a set of simple loops (a vertex with
/// more than one outgoing border edge).
bool boundary_loops(const ElementMesh& m, std::vector<std::vector<int>>& loops);
/// Closes the border loop `loop` of `m` (a boundary_loops loop) with new
/// triangles, oriented as the loop's own. Concentric rings of new vertices,
/// each the loop shrunk towards its centroid, keep the cap's edges near the
/// loop's mean edge (a fan from the centroid alone has spokes as long as the
/// loop's radius: a 48-vertex cut gets edges 7.6 times its mean edge); loops
/// no wider than their mean edge get that fan. Needs >= 3 vertices (else
/// nothing is added).
void cap_loop(ElementMesh& m, const std::vector<int>& loop);
/// Cap centres put back in the middle of their cap: every vertex of at least
/// `min_valence` neighbours whose one-ring is one closed fan is moved by the
/// part of (mean of its ring - its position) that lies in the ring's plane
/// (Newell normal), when that part is over `min_offset` times its mean spoke.
/// A cap fanned from its loop's centroid and then deformed with its loop (a
/// quilting step's Laplacian deformation) can end with its centre at one end
/// of the loop: a spike of spokes. A sphere's pole or any vertex already in
/// the middle of its ring stays. Returns how many vertices moved.
std::size_t recentre_fans(ElementMesh& m, int min_valence = 9, double min_offset = 0.25);
/// Length of the longest edge; 0 if none.
double longest_edge_length(const ElementMesh& m);
/// The longest over several elements; 0 if none.
double longest_edge_length(const std::vector<ElementMesh>& els);
/// Median length over the triangles' sides (an edge of two triangles counted
/// twice, as every edge of a closed element is); 0 if none. Over several
/// elements: of all their sides together.
double median_edge_length(const ElementMesh& m);
double median_edge_length(const std::vector<ElementMesh>& els);
/// The pairs of `m`'s triangles that intersect (exact, the rules of
/// self_intersecting_faces: geometry/self_intersections.h), as triangle
/// indices, first < second; on one thread unless `parallel` (callers that
/// check many elements side by side leave it off). Throws TopologyError for
/// a non-manifold element (as mesh_from_elements).
std::vector<std::array<std::uint32_t, 2>> element_self_crossings(const ElementMesh& m, bool parallel = false);
/// A fold of an element untangled (a thread crumpled by the shell map,
/// decision 102): the vertices of the triangles flagged in `faces` and one
/// ring of vertices around them are smoothed, every other vertex held
/// (umbrella steps: each to the mean of its neighbours, all at once), 4, then
/// 16, then 64 steps from the start, until `m` crosses itself in at most
/// `own` pairs of triangles. Returns whether it then does; `m` is changed
/// only if so. Throws InvalidInputError if `faces` is not one flag per triangle.
bool smooth_out_crossings(ElementMesh& m, const std::vector<char>& faces, std::size_t own);
/// Unit area-weighted vertex normals (zero for isolated vertices).
std::vector<P3> vertex_normals(const ElementMesh& m);
/// Unit face normals (zero for degenerate triangles).
std::vector<P3> face_normals(const ElementMesh& m);
/// Sorted, unique 1-ring neighbours of every vertex.
std::vector<std::vector<int>> vertex_neighbours(const ElementMesh& m);
/// Copies the triangles `tris` of `m` (indices into m.tris) into a compact ElementMesh.
ElementMesh extract_triangles(const ElementMesh& m, const std::vector<int>& tris);
/// Appends `b` to `a` (indices of b shifted).
void append(ElementMesh& a, const ElementMesh& b);

/// Mesh -> ElementMesh (vertices renumbered densely in iteration order).
/// Throws InvalidInputError for a non-triangle face.
ElementMesh element_mesh_from(const Mesh& mesh);
/// Builds `out` (cleared first) from the elements, one after the other, and
/// writes kFaceElement = the index of the element in `elements`.
/// Throws TopologyError naming the element if Surface_mesh refuses a face
/// (non-manifold vertex or edge).
void mesh_from_elements(const std::vector<ElementMesh>& elements, Mesh& out);
/// The faces (indices in mesh_from_elements's order) of the elements marked
/// in `changed` and of every element whose bounding box meets a marked one's:
/// all a crossing check must test again when only the marked ones changed
/// since a check that found no pair among the others.
std::vector<std::uint32_t> faces_near_changed_elements(const std::vector<ElementMesh>& elements,
                                                       const std::vector<char>& changed);

}  // namespace surftex
