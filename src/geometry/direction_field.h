// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Smooth N-symmetry orientation field over faces (Ray et al. 2009, section
// 2.2): interpolates sparse orientation constraints (user strokes, principal
// curvature directions, a projected constant vector) into a unit tangent
// direction d_s per face; d_t is d_s rotated by +90 degrees in the face
// (d_t = n x d_s) and is not stored.
//
// Method (the paper gives no formulas; the standard representation-vector
// formulation): u_f = exp(i N theta) per face frame, the Levi-Civita
// connection across edges, minimise sum_e w_e |u_g - r_fg u_f|^2 (w_e =
// 3|e|^2 / (A_f + A_g), capped) with constrained and outside faces locked
// (Hermitian SPD, SimplicialLDLT); then the N representatives combed along a
// dual spanning tree. A component without constraints gets d_s = e1 (counted).
// In full: docs/decisions/308-direction-field.md.
//
// Reads/writes the face map `direction_map` (Vector3, default kFaceDirection
// "f:dir", created if absent). With an effect area, faces outside it keep their
// stored direction bit for bit. Throws InvalidInputError (bad symmetry, face
// index out of range, zero or normal-parallel constraint direction, no
// constraint and no locked face), SolverError if the factorisation fails.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "geometry/mesh_fwd.h"
#include "geometry/property_names.h"

namespace surftex {

struct EffectArea;

/// One orientation constraint: the face and a 3D direction (projected on the
/// face plane; only its orientation modulo 2 pi / N matters).
struct DirectionConstraint {
  std::uint32_t face = 0;
  std::array<double, 3> direction{1, 0, 0};
};

struct DirectionFieldOptions {
  int symmetry = 4;                     ///< N in {1, 2, 4}
  PropertyName<FaceIndex, Vector3> direction_map = kFaceDirection;  ///< face map written
  /// Free faces; nullptr = the whole mesh. Faces outside are locked to the
  /// current content of direction_map.
  const EffectArea* area = nullptr;
  /// >= 0. 0: constraints exact. > 0: one implicit smoothing step with soft
  /// constraints (about sqrt(smoothing) face rings), for noisy constraints.
  double smoothing = 0;
};

struct DirectionFieldResult {
  std::size_t constrained_faces = 0;
  std::size_t solved_faces = 0;
  std::size_t unconstrained_faces = 0;
};

DirectionFieldResult interpolate_direction_field(Mesh& mesh,
                                                 const std::vector<DirectionConstraint>& constraints,
                                                 const DirectionFieldOptions& options = {});
/// The same field without a property map: `directions` (one per face index,
/// mesh.num_faces()) holds the current directions on entry (kept outside the
/// area) and the field on return. options.direction_map is not used.
DirectionFieldResult interpolate_direction_field(const Mesh& mesh,
                                                 const std::vector<DirectionConstraint>& constraints,
                                                 std::vector<Vector3>& directions,
                                                 const DirectionFieldOptions& options = {});

/// Constraints from principal directions: the faces whose mean curvature
/// anisotropy |kmax - kmin| (averaged over the face's vertices) is among the
/// top `fraction` (0..1] get the face-projected average of their vertices'
/// kVertexDmax (sign-aligned, valid for N = 2 and 4). Needs the curvature maps
/// (compute_principal_curvatures); throws InvalidInputError if absent.
std::vector<DirectionConstraint> constraints_from_principal_directions(const Mesh& mesh,
                                                                       double fraction = 0.1);

/// A constant 3D vector projected on every face whose plane is not nearly
/// orthogonal to it (|projection| >= min_projection * |v|); the other faces are
/// left to the interpolation. Throws InvalidInputError for a zero vector.
std::vector<DirectionConstraint> constraints_from_constant_vector(const Mesh& mesh,
                                                                  std::array<double, 3> v,
                                                                  double min_projection = 0.3);

/// The direction a floor facing along v takes: v crossed with the world axis
/// least aligned with it (ties: x, then y, then z), unit. For v = +y (glTF's
/// up) it is -z, away from a viewer on +z, as a photograph of a pavement
/// looking down has its top away from the camera. Throws InvalidInputError
/// for a zero or non-finite vector.
std::array<double, 3> floor_vector(std::array<double, 3> v);

/// Floors and ceilings of a constant-vector field: the faces whose plane is
/// within `max_projection` of orthogonal to v (|projection| < max_projection
/// * |v|: flat tops and bottoms, a CAD part's faces facing along v) and whose
/// neighbours across every edge are too get the projection of
/// floor_vector(v). Interpolated from their rims instead, a flat top bounded
/// by walls holds the field's singularity in its middle (its rows circle the
/// walls: radial fragments); so constrained it holds parallel rows, and the
/// turn is at its rim. The neighbour rule leaves out the thin bands where a
/// curved surface turns through orthogonal (a flat torus's crest, whose
/// rows circle it without a singularity). Throws InvalidInputError for a zero
/// vector.
std::vector<DirectionConstraint> floor_constraints(const Mesh& mesh, std::array<double, 3> v,
                                                   double max_projection = 0.01);

}  // namespace surftex
