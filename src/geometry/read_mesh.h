// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh input: OFF, OBJ, PLY (ascii and binary), STL (ascii and binary).
// Files are parsed by surftex's own defensive readers into a polygon soup
// (every count and index validated against the file size before allocating,
// NaN/inf refused), which is then repaired and oriented (CGAL PMP
// repair_polygon_soup / orient_polygon_soup) before becoming a Surface_mesh.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

/// What a file holds, before any repair. Indices are 0-based into `points`.
struct PolygonSoup {
  std::vector<std::array<double, 3>> points;
  std::vector<std::vector<std::size_t>> polygons;
  /// Optional per-corner texture coordinates (OBJ `vt`), parallel to `polygons`
  /// (same shape) when non-empty.
  std::vector<std::array<double, 2>> uvs;
  std::vector<std::vector<std::size_t>> polygon_uvs;
  /// Optional per-point colours in [0,1] (PLY red/green/blue, OFF COFF).
  std::vector<std::array<float, 3>> colors;
};

/// Reads any supported format (chosen by extension, then by content). Throws
/// IOError (unreadable, truncated, malformed: the message names file, line or
/// element) or InvalidInputError (NaN/inf coordinates, bad indices, no faces).
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
  bool oriented = true;  ///< orient_polygon_soup succeeded without splitting
};

/// Repairs and orients a soup and builds the mesh. Colours, if present, go to
/// the kVertexColor property. Throws TopologyError if nothing valid is left.
void soup_to_mesh(PolygonSoup soup, Mesh& mesh, const SoupToMeshOptions& opt = {},
                  SoupRepairCounts* counts = nullptr);

/// read_polygon_soup + soup_to_mesh.
void read_mesh(const std::string& path, Mesh& mesh, const SoupToMeshOptions& opt = {},
               SoupRepairCounts* counts = nullptr);

}  // namespace surftex
