// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The shell map (Zhou et al. 2006, section 3.2; Porumbescu et al. 2005): the
// piecewise-linear bijection between shell space and texture space defined by
// barycentric coordinates in corresponding tetrahedra of a ShellSpace.
//
// Points are located with a uniform grid over the tets (texture space in
// metric units), inside = every barycentric >= -tolerance, ties to the
// largest smallest coordinate then the lower index (deterministic).
// locate_texture_from() walks across tet faces instead, so it never leaves
// the start tet's chart (our reading of 3.2's per-patch bijection), falling
// back to the chart's grid. In full: docs/decisions/104-shell-space.md.
//
// The map copies what it needs from the ShellSpace at construction: rebuild it
// after shell_map_minimize_stretch changes texture coordinates.
// Throws: InvalidInputError (empty shell; a point outside the shell for the
// throwing accessors).

#include <array>
#include <memory>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "shell/shell_space.h"

namespace surftex {

struct ShellMapOptions {
  /// Barycentric slack for "inside" (relative, unitless); >= 0.
  double tolerance = 1e-10;
  /// Steps of locate_texture_from's walk before it falls back to the grid; >= 1.
  int max_walk_steps = 256;
};

class ShellMap {
 public:
  explicit ShellMap(const ShellSpace& shell, const ShellMapOptions& opt = {});
  ~ShellMap();
  ShellMap(ShellMap&&) noexcept;
  ShellMap& operator=(ShellMap&&) noexcept;

  /// A tet and barycentric coordinates in it (sum to 1).
  struct Location {
    int tet = -1;
    std::array<double, 4> bary{};
    bool inside = false;  ///< every coordinate >= -tolerance
  };

  /// Locates (u, v, w) (w in [0,1]) in texture space. `nearest` = when no tet
  /// contains the point, return the tet of the nearest grid cells whose
  /// smallest barycentric coordinate is largest (extrapolation), inside = false.
  Location locate_texture(const Vec3& uvw, bool nearest = false) const;
  /// Locates (u, v, w) in the texture-space tets of the chart of `start_tet`,
  /// walking from `start_tet` (see the header comment); inside = false and tet
  /// = -1 when no tet of that chart contains the point. Throws
  /// InvalidInputError if start_tet is out of range.
  Location locate_texture_from(const Vec3& uvw, int start_tet) const;
  /// Locates a 3D point in shell space (same rules).
  Location locate_shell(const Vec3& p, bool nearest = false) const;

  /// Image of a texture-space location in shell space / of a shell location in texture space.
  Vec3 shell_point(const Location& texture_loc) const;
  Vec3 texture_point(const Location& shell_loc) const;

  /// texture (u,v,w) -> shell space. Throws InvalidInputError if outside the texture space.
  Point3 texture_to_shell(const Vec3& uvw) const;
  /// shell space -> texture (u,v,w). Throws InvalidInputError if outside the shell.
  Vec3 shell_to_texture(const Point3& p) const;

  std::size_t num_tets() const;
  /// Chart of a tet (ShellSpace::chart of its corners).
  int tet_chart(int tet) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace surftex
