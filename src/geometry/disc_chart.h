// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Disc charts: a topological disc of faces grown breadth-first from a seed
// face, and its LSCM flattening. One routine for the two places that need
// it: the base mesh's texture atlas (base_mesh_atlas.h; Zhou et al. 2006,
// section 3.2) and the surface patches of mesh quilting (shell/
// surface_quilting.h, section 3.1: "growing the region using breadth-first
// traversal", "flattened ... using LSCM").
//
// Growth: breadth-first across edges; a face is accepted when accept(f)
// holds, the chart is below max_faces and stays a disc (one shared edge and a
// new opposite vertex, or two shared edges). Flattening: a disc check, LSCM
// (CGAL's, or the same system solved directly: LscmSolver), mirrored if
// negative, scaled to the 3D area. Valid (an embedding) when every uv face is
// positive and the border loop simple (exact tests). Thread-safe.
#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"

namespace surftex {

/// The signed area of uv triangle (a, b, c),
/// positive when counter-clockwise.
double uv_signed_area(const std::array<double, 2>& a, const std::array<double, 2>& b,
                      const std::array<double, 2>& c);

/// Stamps shared by successive growths (no clearing between charts).
struct DiscGrowthState {
  std::vector<int> face, vertex;  ///< last growth id that took the face / touched the vertex
  int next_id = 0;
  explicit DiscGrowthState(const Mesh& mesh);
};

/// Grows a disc chart from face index `seed` (always in it); see the header.
/// Returns its face indices in the order they were accepted. max_faces >= 1.
std::vector<int> grow_disc_chart(const Mesh& mesh, int seed, const std::function<bool(int)>& accept,
                                 std::size_t max_faces, DiscGrowthState& state);

struct DiscChartFlattening {
  std::vector<int> vertices;                  ///< chart vertex -> mesh vertex index
  std::vector<std::array<double, 2>> uv;      ///< per chart vertex (3D length units)
  double area3d = 0;                          ///< the chart's 3D area
  /// Area-weighted mean over faces of max(a3d/auv, auv/a3d) (1 = no area distortion).
  double area_distortion = 0;
  std::size_t flipped_faces = 0;     ///< faces whose uv orientation is not positive
  std::size_t border_crossings = 0;  ///< non-adjacent border edge pairs that touch or cross in uv
  bool embedded() const { return status == Status::kOk && flipped_faces == 0 && border_crossings == 0; }
  enum class Status { kOk, kTopology, kSolver } status = Status::kOk;
  std::string error;                          ///< why not, when status != kOk
};

/// How the LSCM system is solved. kCgal: CGAL's LSCM_parameterizer_3.
/// kDirect: the same energy and pinned vertices, its normal equations in
/// complex form assembled directly (about 3x faster; uvs equal to ~1e-10 of
/// the chart's size, not bit-equal). Default: kCgal (decision 210).
enum class LscmSolver { kCgal, kDirect };

/// Flattens the disc chart `faces` (triangles); see the header. Never throws
/// for a bad chart: the result's status and error say what went wrong (a
/// non-manifold chart or not a disc: kTopology; LSCM failed, non-finite or
/// zero-area uv: kSolver).
DiscChartFlattening flatten_disc_chart(const Mesh& mesh, const std::vector<int>& faces,
                                       LscmSolver solver = LscmSolver::kCgal);

}  // namespace surftex
