// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Final mesh embedding (Zhou et al. 2006, section 3.2): an output mesh whose
// vertex coordinates are texture-space coordinates (u, v, w) (u, v in the base
// mesh atlas, w in [0,1] the height in the shell) is mapped vertex by vertex
// Faces stay straight between mapped vertices (elements must be small against
// the tets); self-intersections counted exactly (PMP). Vertices outside the
// texture space are refused or extrapolated from the nearest tet
// (outside_policy), and counted.
// Reads/writes: the mesh's vertex points only (overwritten in place).
// Throws: InvalidInputError (outside vertex with kRefuse, non-triangle faces
// when checking).

#include <cstddef>

#include "geometry/mesh_fwd.h"
#include "shell/shell_map.h"

namespace surftex {

struct EmbedInShellOptions {
  enum class Outside { kRefuse, kExtrapolate };
  /// What to do with a vertex outside the texture space.
  Outside outside_policy = Outside::kExtrapolate;
  /// Run the exact self-intersection check on the result.
  bool check_self_intersections = true;
};

struct EmbedInShellResult {
  std::size_t vertices = 0;               ///< vertices mapped
  std::size_t outside = 0;                ///< of which outside the texture space (extrapolated)
  bool checked = false;                   ///< the self-intersection check ran
  std::size_t self_intersecting_pairs = 0;
};

/// Maps every vertex of `mesh` from texture space (u,v,w) to shell space in place.
EmbedInShellResult embed_in_shell(Mesh& mesh, const ShellMap& map, const EmbedInShellOptions& opt = {});

}  // namespace surftex
