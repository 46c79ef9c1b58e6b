// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A mesh swatch M_in for mesh quilting (Zhou et al. 2006, section 2.1): any
// triangle mesh; its geometric elements are its connected components. The
// swatch's 2D domain is its xy bounding rectangle (l_in x w_in) and its height
// h_in the z extent. The paper defines h_in as the smallest bounding-box
// dimension; we require the caller to give swatches with z as the thin axis
// (the shipped generators do) and do not reorient: a swatch whose z extent is
// not the smallest is accepted, it is simply quilted in xy.
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "shell/element_mesh.h"

namespace surftex {

struct SwatchElement {
  P3 bbox_min{0, 0, 0}, bbox_max{0, 0, 0};
  P3 centroid{0, 0, 0};   ///< mean of the element's vertices
  bool closed = false;    ///< no border edge (every edge used by two triangles)
  std::size_t faces = 0;
};

struct Swatch {
  ElementMesh mesh;                   ///< all triangles of the swatch
  std::vector<int> face_element;      ///< element id per triangle (kFaceElement), 0..elements-1
  std::vector<SwatchElement> elements;
  P3 bbox_min{0, 0, 0}, bbox_max{0, 0, 0};
  double mean_edge_length = 0;
  double length() const { return bbox_max[0] - bbox_min[0]; }  ///< l_in (x)
  double width() const { return bbox_max[1] - bbox_min[1]; }   ///< w_in (y)
  double height() const { return bbox_max[2] - bbox_min[2]; }  ///< h_in (z)
};

/// Builds a swatch from a triangle mesh: elements = connected components
/// (numbered in order of their first face). Throws InvalidInputError if the
/// mesh has no face, a non-triangle face, a non-finite coordinate, or a zero
/// xy extent. A zero height (flat swatch, z extent 0) is accepted: planar
/// quilting (section 2) works in xy; embedding on a surface (section 3.2)
/// needs a shell of positive thickness and refuses it there
/// (embed_surface_quilt).
Swatch make_swatch(const Mesh& mesh);
/// read_mesh + make_swatch (any format read_mesh reads). Throws as both.
Swatch load_swatch(const std::string& path);
/// The triangles of element `e` as their own ElementMesh.
ElementMesh swatch_element(const Swatch& swatch, int e);

/// Writes kFaceElement on `mesh` = connected component id (in order of first
/// face) and returns the number of components.
int label_elements(Mesh& mesh);

}  // namespace surftex
