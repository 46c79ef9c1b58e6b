// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh input: OFF, OBJ (+ its .mtl materials), PLY (ascii and binary), STL
// (ascii and binary), glTF 2.0 (.glb binary and .gltf JSON).
// Files are parsed by surftex's own defensive readers into a polygon soup
// (every count and index validated against the file size before allocating,
// NaN/inf refused), which is then repaired and oriented (CGAL PMP
// repair_polygon_soup / orient_polygon_soup) before becoming a Surface_mesh.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/mesh_material.h"

namespace surftex {

/// What a file holds, before any repair. Indices are 0-based into `points`.
struct PolygonSoup {
  std::vector<std::array<double, 3>> points;
  std::vector<std::vector<std::size_t>> polygons;
  /// Optional per-corner texture coordinates (OBJ `vt`): `polygon_uvs` is
  /// either empty or parallel to `polygons`; polygon_uvs[i] is then either
  /// empty (that polygon has no UVs) or has polygons[i].size() indices into `uvs`.
  std::vector<std::array<double, 2>> uvs;
  std::vector<std::vector<std::size_t>> polygon_uvs;
  /// Optional per-point colours in [0,1] (PLY red/green/blue, OFF COFF, OBJ
  /// `v x y z r g b`): either empty or parallel to `points`.
  std::vector<std::array<float, 3>> colors;
  /// Where the soup came from (the file path), used in error messages.
  std::string source;
  /// Faces with fewer than 3 vertices in the file (e.g. OBJ `f 1 2`): their
  /// indices are validated like any other, then the face is left out of
  /// `polygons` (it bounds no area) and counted here; `first_short_polygon`
  /// names where the first one was (file line or face number).
  std::size_t short_polygons_dropped = 0;
  std::string first_short_polygon;
  /// Optional materials (OBJ usemtl + .mtl, glTF materials) and, parallel to
  /// `polygons` when non-empty, each polygon's index into them (-1 = none).
  std::vector<MeshMaterial> materials;
  std::vector<int> polygon_material;
  /// OBJ `mtllib` names as written (resolved by read_polygon_soup).
  std::vector<std::string> material_libraries;
  /// Files read besides `source` (.mtl files; external glTF buffers and images).
  std::vector<std::string> files_read;
  /// What was in the file but is not used, one line each (a missing .mtl, a
  /// material no .mtl defines, glTF points and lines skipped, ...).
  std::vector<std::string> warnings;
};

/// Reads any supported format (by extension, case-insensitive; else by
/// content, a GLB by its magic). OBJ reads its `mtllib` files (a missing one is
/// a warning); glTF: the default scene's triangles with node transforms
/// (read_gltf.cpp). Every header count is checked against the file size before
/// allocating. The accepted variants of each format:
/// docs/decisions/404-mesh-readers.md. Throws IOError (missing, unreadable,
/// truncated, malformed, unknown; names file and line or element) or
/// InvalidInputError (NaN/inf, bad indices, no faces).
PolygonSoup read_polygon_soup(const std::string& path);

struct SoupToMeshOptions {
  bool triangulate = true;  ///< triangulate non-triangular faces
};

/// Counts of what soup-to-mesh conversion found and did (also in repair reports).
struct SoupRepairCounts {
  std::size_t input_points = 0, input_polygons = 0;
  std::size_t duplicate_points_merged = 0;
  std::size_t degenerate_polygons_removed = 0;  ///< repeated vertices, < 3 distinct
  std::size_t duplicate_polygons_removed = 0;
  std::size_t isolated_points_removed = 0;
  std::size_t points_duplicated_to_orient = 0;  ///< non-manifold splits by orient_polygon_soup
  std::size_t polygons_simplified = 0;  ///< lost consecutive repeated vertices (those left with < 3 are also in degenerate_polygons_removed)
  std::size_t pinched_polygons_split = 0;  ///< extra polygons from splitting pinched ones
  bool oriented = true;  ///< orient_polygon_soup succeeded without splitting
  std::size_t output_vertices = 0, output_faces = 0;  ///< after conversion (and triangulation)
  std::size_t faces_triangulated = 0;  ///< non-triangular faces split into triangles
  std::size_t short_polygons_dropped = 0;  ///< faces with < 3 vertices in the file, left out (PolygonSoup)
  /// Faces PMP::triangulate_faces could not triangulate (its constrained
  /// triangulation fails on polygons whose projection is degenerate): split
  /// as a fan from their first corner instead, which keeps the topology.
  std::size_t faces_fan_triangulated = 0;
  std::size_t uv_corners = 0;          ///< corners that received a kCornerUV value
  std::size_t uv_corners_dropped = 0;  ///< corners whose UV could not be mapped (or had none)
};

/// Repairs and orients a soup and builds the mesh (cleared first): CGAL PMP
/// repair_polygon_soup's steps one by one (each counted), orient_polygon_soup,
/// polygon_soup_to_polygon_mesh, triangulate_faces when opt.triangulate
/// (fan-triangulating, and counting, what it cannot split). Writes kVertexColor
/// and kCornerUV when the soup has them (mapped by position; corners without a
/// UV get (0,0), counted). Throws InvalidInputError (index out of range),
/// TopologyError (no face left, not a mesh; names soup.source).
void soup_to_mesh(PolygonSoup soup, Mesh& mesh, const SoupToMeshOptions& opt = {},
                  SoupRepairCounts* counts = nullptr);

/// read_polygon_soup + soup_to_mesh.
void read_mesh(const std::string& path, Mesh& mesh, const SoupToMeshOptions& opt = {},
               SoupRepairCounts* counts = nullptr);

/// What read_mesh_file found besides the mesh.
struct MeshFileContents {
  SoupRepairCounts counts;
  std::vector<MeshMaterial> materials;  ///< kFaceMaterial indexes these (textures not decoded)
  std::vector<std::string> files_read;  ///< the mesh file, then .mtl / buffer / image files
  std::vector<std::string> warnings;
};

/// read_mesh keeping the materials: kFaceMaterial is written when the file
/// has any (through repair and triangulation, by the face's positions, as
/// kCornerUV).
MeshFileContents read_mesh_file(const std::string& path, Mesh& mesh, const SoupToMeshOptions& opt = {});

}  // namespace surftex
