// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Shell space over a base mesh and its texture space (Zhou et al. 2006, section
// 3.2 "Final Mesh Embedding"; the shell map of Porumbescu et al. 2005).
//
// The thin volume between the base (w = 0) and its offset along the vertex
// normals (w = 1), built per atlas chart (shell vertices duplicated on chart
// borders). Each prism is split into 3 tets by base vertex index, so
// neighbours agree; prisms rather than TetGen because every tet corner needs
// texture coordinates and every tet must be positive in both spaces (the
// decision: docs/decisions/104-shell-space.md). Texture space (u, v, w): w is
// measured as w * w_scale (uv units), so a flat shell maps by a similarity.
// Height h (relative to the mean edge if relative_height); heights of bad
// prisms (a non-positive tet or a turned-over top) shrink by shrink_factor
// until none is left; where shrinking cannot help (a face turned over against
// its neighbours), the bottom layer is unfolded there (the vertices move to
// their neighbours' mean) and shrinking resumes. Tets are stored positive in
// texture space and checked positive in shell space (SolverError otherwise).
//
// Reads: kCornerUV and kFacePatch (e.g. from compute_base_mesh_atlas); every
// corner of one base vertex inside one chart must carry the same uv. Vertex
// normals are computed here (CGAL PMP compute_vertex_normals); no other
// property is read.
// Throws: InvalidInputError (missing uv/patch maps, non-triangle faces, bad
// options, inconsistent uvs), SolverError (a uv triangle with non-positive
// area, or clamping could not make every tet positive).

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

using Vec3 = std::array<double, 3>;
using Tet = std::array<int, 4>;

struct ShellSpaceOptions {
  /// Shell thickness: relative to the mean edge length if relative_height, else absolute; > 0.
  double height = 0.5;
  bool relative_height = true;
  /// Factor applied to a vertex height when its prism is bad; in (0,1).
  double shrink_factor = 0.7;
  /// Rounds of shrinking before giving up (SolverError); >= 0.
  int max_shrink_steps = 40;
};

/// The tetrahedralized shell and its texture space. Indices are shell-vertex indices.
struct ShellSpace {
  std::vector<Vec3> shell_points;    ///< 3D position of each shell vertex (mesh units)
  std::vector<Vec3> texture_points;  ///< (u, v, w): atlas uv, w in {0, 1}
  std::vector<Tet> tets;             ///< positively oriented in both spaces
  std::vector<int> tet_face;         ///< base face index of each tet's prism
  std::vector<int> base_vertex;      ///< base vertex index of each shell vertex
  std::vector<int> chart;            ///< chart id (kFacePatch) of each shell vertex
  std::vector<std::uint8_t> layer;   ///< 0 = base surface, 1 = offset surface
  std::vector<std::uint8_t> lateral; ///< 1 = on a chart border (lateral boundary of the shell patch)
  std::vector<int> partner;          ///< the other layer's shell vertex of the same (chart, base vertex)
  double height = 0;                 ///< nominal absolute height h (mesh units)
  double uv_per_length = 0;          ///< atlas scale: sqrt(sum uv area / sum 3D area)
  double w_scale = 0;                ///< texture length of w = 1, in uv units (height * uv_per_length)
  std::vector<double> vertex_height; ///< per base vertex, after clamping (mesh units)
  std::size_t clamped_vertices = 0;  ///< base vertices whose height was shrunk
  int shrink_rounds = 0;             ///< rounds of clamping used
  std::size_t unfolded_vertices = 0; ///< base vertices moved in the bottom layer to undo a fold (0 on most meshes)

  /// Texture-space point in metric units: (u, v, w * w_scale).
  Vec3 texture_metric(int i) const {
    const Vec3& t = texture_points[static_cast<std::size_t>(i)];
    return {t[0], t[1], t[2] * w_scale};
  }
};

/// Builds the shell over `base` (see header comment).
ShellSpace build_shell_space(const Mesh& base, const ShellSpaceOptions& opt = {});

/// Signs of every tet in both spaces with the exact predicate CGAL::orientation
/// (Epick points). Counts tets that are not POSITIVE.
struct ShellOrientationCheck {
  std::size_t shell_not_positive = 0;
  std::size_t texture_not_positive = 0;
};
ShellOrientationCheck check_shell_orientation(const ShellSpace& shell);

/// The closed boundary surface of the tets of one chart (chart < 0: all tets),
/// outward oriented, in shell space: faces used by exactly one tet. The input
/// for tetrahedralizing a shell given by its boundary (tetgen_adapter.h).
void shell_boundary_surface(const ShellSpace& shell, int chart, Mesh& out);

/// Volume of a tet given by 4 points (positive if CGAL::orientation is POSITIVE).
double tet_signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

}  // namespace surftex
