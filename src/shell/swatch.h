// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// A mesh swatch M_in for mesh quilting (Zhou et al. 2006, section 2.1): any
// triangle mesh; its geometric elements are its connected components. The
// swatch's 2D domain is its xy bounding rectangle (l_in x w_in) and its height
// h_in the z extent. The paper defines h_in as the smallest bounding-box
// dimension: make_swatch(mesh, SwatchAxis::kAuto) finds that thin axis and
// turns the swatch so that it becomes z (swatch_thin_axis, orient_swatch_up);
// make_swatch(mesh) takes z as given (the shipped generators make z thin).
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

/// The swatch axis that is its thickness (h_in) and becomes the height over
/// the surface: detected (kAuto) or given (x, y, z).
enum class SwatchAxis { kAuto, kX, kY, kZ };

struct Swatch {
  ElementMesh mesh;                   ///< all triangles of the swatch
  std::vector<int> face_element;      ///< element id per triangle (kFaceElement), 0..elements-1
  std::vector<SwatchElement> elements;
  /// Connected components of the mesh; more than elements when components
  /// that pass through each other were joined into one element (make_swatch).
  int components = 0;
  /// The most self-intersecting face pairs (exact) within one element: 0 for
  /// a clean swatch; a scanned object may have a few (wingnut.obj 3), a group
  /// of crossing components many (apples_bowl.obj 887), which every copy of
  /// the element carries into a quilt. From the same exact pass as the grouping.
  std::size_t element_self_crossings = 0;
  P3 bbox_min{0, 0, 0}, bbox_max{0, 0, 0};
  double mean_edge_length = 0;
  /// The smallest distance between two elements (vertex to triangle; 0 for
  /// a single element or elements that touch), at most max(l_in, w_in): the
  /// clearance quilting keeps between elements (QuiltStepOptions::clearance).
  double min_gap = 0;
  /// The input's axis that became z (0 = x, 1 = y, 2 = z; see make_swatch).
  int up_axis = 2;
  double length() const { return bbox_max[0] - bbox_min[0]; }  ///< l_in (x)
  double width() const { return bbox_max[1] - bbox_min[1]; }   ///< w_in (y)
  double height() const { return bbox_max[2] - bbox_min[2]; }  ///< h_in (z)
};

/// Builds a swatch: elements = connected components (by first face), those
/// that pass through each other (an exact crossing) joined into one. Throws
/// InvalidInputError for no face, a non-triangle, a non-finite coordinate or a
/// zero xy extent; a flat swatch is accepted here (a plane quilts it;
/// quilt_swatch_on_surface refuses it on a mesh).
Swatch make_swatch(const Mesh& mesh);
/// As above with the thin axis `up` turned onto z first (a cyclic permutation,
/// handedness kept; kAuto: swatch_thin_axis); Swatch::up_axis records it.
Swatch make_swatch(const Mesh& mesh, SwatchAxis up);
/// The axis (0, 1, 2) of the smallest bounding-box extent of `mesh` (the
/// paper's h_in, section 2.1); z unless another extent is smaller by more than
/// 1%, then y before x. Throws InvalidInputError for an empty mesh.
int swatch_thin_axis(const Mesh& mesh);
/// Permutes the coordinates of every vertex cyclically so that `axis` (0, 1,
/// 2) becomes z; axis 2 leaves the mesh unchanged.
void orient_swatch_up(Mesh& mesh, int axis);
/// The section 2.3 grid for cells of side `cell`: sx x sy. Throws
/// InvalidInputError (led by `who`, naming the axes, cell and --cell /
/// --swatch-up) if either is below 3.
void swatch_cells(const Swatch& swatch, double cell, const std::string& who, int& sx, int& sy);
/// The swatch's element spacing (swatch units): the median, over its
/// elements, of the xy distance from an element's vertex centroid to the
/// nearest other's; for a single element its larger xy side.
double swatch_element_spacing(const Swatch& swatch);
/// "x", "y" or "z".
const char* axis_name(int axis);
/// read_mesh + make_swatch (any format read_mesh reads). Throws as both.
Swatch load_swatch(const std::string& path);
/// Every element's triangles as its own ElementMesh, in element order (one
/// pass over the triangles; element e of face_element is entry e).
std::vector<ElementMesh> swatch_element_meshes(const Swatch& swatch);
/// The triangles of element `e` as their own ElementMesh.
ElementMesh swatch_element(const Swatch& swatch, int e);

/// Writes kFaceElement on `mesh` = connected component id (in order of first
/// face) and returns the number of components.
int label_elements(Mesh& mesh);

}  // namespace surftex
