// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Final embedding of a surface quilt (Zhou et al. 2006, section 3.2, applied
// to the output of quilt_surface, section 3.1): builds the base mesh's
// multi-chart texture atlas (base_mesh_atlas.h), expresses the quilt in that
// texture space (surface_quilt_to_texture), builds the shell
// (shell_space.h) of thickness shell_height * (swatch height * quilt scale),
// minimises its stretch (shell_map_minimize_stretch, eq. 8-9) and maps every
// vertex through the shell map into 3D (embed_in_shell.h), with the exact
// self-intersection count of the result.
// Reads: the base mesh's points (a copy gets the atlas; `base` is unchanged).
// Writes: `out` (cleared first): the embedded quilt, kFaceElement.
// Throws: InvalidInputError (bad options), and what the stages throw
// (TopologyError, SolverError from the atlas and the shell).
#include <cstddef>

#include "geometry/base_mesh_atlas.h"
#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "shell/embed_in_shell.h"
#include "shell/shell_stretch.h"
#include "shell/surface_quilting.h"

namespace surftex {

struct EmbedSurfaceQuiltOptions {
  /// Shell thickness in units of the scaled swatch height (z_max - z_min) * scale; > 0.
  double shell_height = 1.0;
  BaseMeshAtlasOptions atlas;
  MinimizeStretchOptions stretch;
  /// Run the exact self-intersection count on the embedded mesh.
  bool check_self_intersections = true;
  ProgressCallback progress;
};

struct EmbedSurfaceQuiltResult {
  BaseMeshAtlasResult atlas;
  MinimizeStretchResult stretch;  ///< stretch_before / stretch_after (normalised eq. 9)
  std::size_t tets = 0, clamped_vertices = 0;
  double shell_height = 0;        ///< nominal absolute shell height (mesh units)
  EmbedInShellResult embed;       ///< outside vertices, self-intersecting pairs
  double seconds_atlas = 0, seconds_shell = 0, seconds_stretch = 0, seconds_map = 0, seconds_embed = 0;
};

/// Embeds `quilt` (made by quilt_surface on `base`) into the shell over `base`; see the header comment.
EmbedSurfaceQuiltResult embed_surface_quilt(const Mesh& base, const SurfaceQuilt& quilt, Mesh& out,
                                            const EmbedSurfaceQuiltOptions& opt = {});

}  // namespace surftex
