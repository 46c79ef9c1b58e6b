// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Shell space over a base mesh and its texture space (Zhou et al. 2006, section
// 3.2 "Final Mesh Embedding"; the shell map of Porumbescu et al. 2005).
//
// The shell is the thin volume between the base mesh M_base (layer w = 0) and
// its offset along the vertex normals (layer w = 1). It is built per chart of
// the base mesh's texture atlas: every (chart, base vertex) pair gives one
// bottom and one top shell vertex, so shell vertices on chart borders are
// duplicated (their 3D positions coincide; their texture coordinates differ).
// The prism over each triangle is split into 3 tetrahedra by a rule that
// depends only on the base vertex indices, so neighbouring prisms agree on the
// diagonal of their common lateral quad: with bottom a < b < c (by base vertex
// index) and top A, B, C, the tets are (a,b,c,C), (a,b,B,C), (a,A,B,C), i.e.
// every lateral quad is cut from the bottom of its smaller-index vertex to the
// top of its larger one.
//
// Why prisms, not TetGen, for the shell map (a decision, issue #8 item 4):
// section 3.2 meshes the shell with tetrahedra and maps by barycentric
// coordinates (the shell map of Porumbescu et al. 2005, whose tets come from
// splitting each prism). The map needs every tet corner to be a shell vertex
// with known texture coordinates, and every tet positive in BOTH spaces.
// The prism split guarantees both by construction. A TetGen mesh of a chart's
// closed shell boundary (tetgen_adapter.h with shell_boundary_surface(); the
// test TetGenAdapter.ShellGivenByItsBoundaryIsTetrahedralizedToTheSameVolume
// checks it fills the same volume with positive tets) may add interior
// Steiner points (no texture coordinates) and connects corners of distant
// prisms, whose image in texture space can be inverted where the shell
// curves; so the embedding uses the prism tets and TetGen serves shells
// given only by their boundary.
//
// Texture space: a shell vertex of base vertex v in chart c has texture
// coordinates (u, v, w) with (u, v) the atlas coordinate of v in c
// (kCornerUV) and w = 0 (bottom) or 1 (top). For distances and volumes the w
// axis is measured in uv units: w_metric = w * w_scale with w_scale = the
// nominal shell height times the atlas' uv-per-length scale, so that a flat,
// unclamped shell maps to texture space by a similarity (the paper does not
// say how w is scaled against (u, v); this makes the stretch of section 3.2
// scale-free and 1 for an undistorted shell).
//
// Height: h = height * (mean edge length) if relative_height, else height.
// Local clamping (the paper leaves the offset unspecified): per base vertex the
// height starts at h; every prism whose tetrahedra are not all positively
// oriented in 3D (CGAL::orientation, exact) or whose top triangle turns over
// against its base triangle has the heights of its three vertices multiplied
// by shrink_factor, until no prism is bad (at most max_shrink_steps rounds).
// Where shrinking cannot help (a face turned over against its neighbours
// inverts its prism at any height), the shell's bottom layer is unfolded
// there: those vertices move to their neighbours' mean and shrinking resumes.
// This keeps the offset surface locally embedded (no flipped face, no inverted
// tet); it does not test global self-intersection of the offset surface
// (thin shells, h << feature size, are the caller's responsibility).
//
// Every tetrahedron is stored positively oriented in texture space; the
// builder verifies with the exact predicate that it is positively oriented in
// shell space too, and refuses (SolverError) otherwise.
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
