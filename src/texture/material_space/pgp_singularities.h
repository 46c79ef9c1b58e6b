// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Singular zones of a periodic global parameterization and their fix at
// rendering time (Ray et al. 2009, section 3, after jump maps [ZG04]).
//
// Detection. A vertex's 1-ring is singular if it contains
//   - a distorted triangle: |grad s - g_s|^2 > threshold |g_s|^2 or the same
//     for t (grad s from T's corner values, g from the direction field and
//     scale). The paper writes an absolute 0.5 on |grad s - g_s|^2, which has
//     units 1/length^2; we make it relative to |g|^2 (same value 0.5), which is
//     what a scale-independent test must mean;
//   - or a mismatched edge: s_j^T - s_i^T != s_j^T' - s_i^T' (or t), beyond
//     `mismatch_tolerance` periods.
// "An edge (i,j)" of the neighbourhood of i is read as a spoke from i (the
// rim edges of the ring do not affect i's chart): the fix below is continuous
// across every edge as soon as each regular endpoint's spokes match, so a
// mismatched edge makes its two endpoints singular, not the whole 2-ring (an
// earlier version also counted rim edges, which roughly doubled the singular
// faces). A face is singular when one of its vertices is.
//
// What singular_fraction counts: the faces with at least one singular
// vertex, i.e. the triangles that get three texture lookups, which is what
// the paper's figure refers to: "Each triangle T=(i,j,k) now has three sets
// of texture coordinates (obtained from the neighborhoods of each vertex
// i,j,k). Then, we use them to perform three texture lookups" (section 3) and
// "we only need one 3D texture lookup for non-singular regions and three 3D
// texture lookups around singularities (5 to 10 percent of the triangles)"
// (section 4, Rendering). It is not the fraction of distorted triangles (the
// first criterion alone), which is about a third of it (armadillo_52k, 8 mean
// edges per period: 9.4% distorted, 29.6% three-lookup faces without the
// curl correction; 7.7% and 24.0% with it). Our reading counts no more than
// the literal one: spokes only (the literal "contains an edge" would add the
// rim edges), and the threshold relative to |g|^2 (the literal absolute 0.5
// is stricter whenever the period S is shorter than 1 mesh unit, as |g| = 1/S).
// The paper does not state the period of its examples (in mesh units or
// edges), so its 5-10% cannot be matched at "its" scale; the fraction grows
// with the period (a vortex core is about one period wide): see bench_pgp.
// The distortion test compares with the target the PGP followed
// (PgpSingularityOptions::pgp; with the curl correction, the corrected g).
//
// Fix. Each singular vertex i gets its own 1-ring chart: s'_{i,i} = s_i^T (T =
// the face of halfedge(i)), s'_{i,j} = s'_{i,i} + alpha_ij (alpha of eq. 3, in
// periods), t likewise; a regular vertex's chart in face T is T's own corners.
// A point of face T = (a,b,c) with barycentrics (b_a,b_b,b_c) is looked up
// three times, once in each corner's chart, and the three results are blended
// with the barycentrics: colour = sum_k b_k lookup(sum_l b_l chart_k[l]).
// Corners and barycentrics are ordered as the face's halfedges: corner 0 =
// target(halfedge(f)), 1 = target(next), 2 = target(next(next)).
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
