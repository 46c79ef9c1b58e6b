// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Editing the elements of a geometric texture by id (Zhou et al. 2006,
// section 4: the synthesized elements recoloured or removed one by one), the
// work of the `elements` command.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct EditElementsOptions {
  /// Recolourings "ID=r,g,b" (0 <= ID < elements, components in [0, 1]), applied in order.
  std::vector<std::string> recolor;
  /// Element ids to remove (0 <= id < elements).
  std::vector<int> remove;
  /// Seed of the element colours given first to a mesh without kVertexColor.
  std::uint64_t seed = 1;
};

struct EditElementsResult {
  int elements = 0;             ///< elements before the edit
  std::size_t faces_removed = 0;
};

/// Labels the elements of `mesh` (kFaceElement = connected components in
/// order of their first face, as quilt writes them), colours them by element
/// if the mesh has no kVertexColor, applies the recolourings to their
/// vertices and removes the faces of the removed elements (garbage
/// collected). Throws InvalidInputError naming --recolor or --remove and the
/// value.
EditElementsResult edit_elements(Mesh& mesh, const EditElementsOptions& opt);

}  // namespace surftex
