// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Singular zones of a periodic global parameterization and their fix at
// rendering time (Ray et al. 2009, section 3, after jump maps [ZG04]).
//
// Detection: a vertex is singular if its 1-ring holds a distorted triangle
// (|grad s - g_s|^2 > threshold |g_s|^2, or t; the paper's absolute 0.5 made
// relative) or a mismatched spoke edge (beyond mismatch_tolerance periods). A
// face is singular when one of its vertices is; singular_fraction counts
// those (the three-lookup faces of section 4). Fix: each singular vertex gets
// its own 1-ring chart; a point of face T is looked up in each corner's chart
// and blended by its barycentrics. Corner order: target(halfedge(f)), next,
// next-next. Our readings and figures: docs/decisions/304-pgp-options.md.
//
// Reads the STM corner map and the maps of PgpOptions (direction, scale).
// Throws InvalidInputError if a map is absent or options are out of range.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "texture/material_space/periodic_global_parameterization.h"

namespace surftex {

struct PgpSingularityOptions {
  double distortion_threshold = 0.5;  ///< relative, > 0
  double mismatch_tolerance = 1e-6;   ///< in periods, >= 0
  PgpOptions pgp;                     ///< maps and symmetry used by the PGP
};

using StmPoint = std::array<double, 3>;
/// Three charts (one per corner) x three corners.
using FaceCharts = std::array<std::array<StmPoint, 3>, 3>;

struct PgpSingularities {
  std::vector<char> distorted_face;   ///< per face index
  std::vector<char> mismatched_edge;  ///< per edge index
  std::vector<char> singular_vertex;  ///< per vertex index
  std::vector<char> singular_face;    ///< per face index
  std::vector<FaceCharts> charts;     ///< per face index (all faces)
  std::vector<std::array<StmPoint, 3>> corners;  ///< per face: its own STM corners
  std::size_t singular_faces = 0;
  double singular_fraction = 0;  ///< singular faces / faces (paper: 5-10%)
};

PgpSingularities detect_pgp_singularities(const Mesh& mesh, const PgpSingularityOptions& options = {});

/// The three (s,t,m) lookup positions of a point of `face` with barycentrics
/// `bary` (one per corner chart). For a regular face they coincide.
inline std::array<StmPoint, 3> singular_lookup_positions(const PgpSingularities& s, std::uint32_t face,
                                                         const std::array<double, 3>& bary) {
  std::array<StmPoint, 3> out{};
  const FaceCharts& ch = s.charts[face];
  for (int k = 0; k < 3; ++k)
    for (int d = 0; d < 3; ++d)
      out[k][d] = bary[0] * ch[k][0][d] + bary[1] * ch[k][1][d] + bary[2] * ch[k][2][d];
  return out;
}

/// Blended lookup (pure; for a rasterizer's per-fragment callback): `lookup`
/// maps an (s,t,m) point to a value with +, * double (e.g. std::array-based
/// colour wrapped in a small struct, or Eigen::Vector3f).
template <class Lookup>
auto blended_lookup(const PgpSingularities& s, std::uint32_t face, const std::array<double, 3>& bary,
                    const Lookup& lookup) {
  const auto p = singular_lookup_positions(s, face, bary);
  if (!s.singular_face[face]) return lookup(p[0]);
  auto acc = lookup(p[0]) * bary[0];
  acc = acc + lookup(p[1]) * bary[1];
  acc = acc + lookup(p[2]) * bary[2];
  return acc;
}

/// Unfixed lookup position (what a renderer without the fix uses): the
/// face's own corner coordinates interpolated.
inline StmPoint plain_lookup_position(const PgpSingularities& s, std::uint32_t face,
                                      const std::array<double, 3>& bary) {
  const auto& c = s.corners[face];
  StmPoint out{};
  for (int d = 0; d < 3; ++d) out[d] = bary[0] * c[0][d] + bary[1] * c[1][d] + bary[2] * c[2][d];
  return out;
}

}  // namespace surftex
