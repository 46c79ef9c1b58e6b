// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Principal curvatures and directions per vertex by jet fitting (CGAL
// Monge_via_jet_fitting, Cazals & Pouget 2003): a degree-`jet_degree` height
// function is fitted in the least-squares sense to the vertex's k-ring
// neighbourhood and its Monge form gives kmax >= kmin and their directions.
// Used to steer direction fields from geometry (Ray et al. 2009, section 2.2:
// "singularities emerge from the geometric constraints").
//
// Sign convention: curvature is positive where the surface bends away from its
// outward (area-weighted) vertex normal, so a sphere of radius r has
// kmax = kmin = +1/r and a saddle has kmax > 0 > kmin.
//
// Robustness: the k-ring grows (max_rings) to min_points points; at umbilic
// or flat vertices (umbilic_tolerance) and on failed fits the directions are
// `reference` projected (k = 0 on failure), never NaN. Directions are unit,
// tangent, dmin = n x dmax.
//
// Writes kVertexKmax, kVertexKmin (1/length units), kVertexDmax, kVertexDmin
// (created if absent). Throws InvalidInputError for non-triangle faces or
// out-of-range options.

#include <array>
#include <cstddef>

#include "geometry/mesh_fwd.h"

namespace surftex {

struct PrincipalCurvatureOptions {
  int rings = 2;              ///< k of the k-ring neighbourhood, >= 1
  int max_rings = 5;          ///< grow the ring up to this many to reach min_points
  int min_points = 12;        ///< >= (d+1)(d+2)/2 of the jet degree
  int jet_degree = 2;         ///< degree d of the fitted jet, 2..4
  double umbilic_tolerance = 1e-2;  ///< relative anisotropy below which directions fall back
  std::array<double, 3> reference{1.0, 0.0, 0.0};  ///< fallback direction (projected)
};

struct PrincipalCurvatureResult {
  std::size_t umbilic_vertices = 0;  ///< vertices whose directions fell back to the reference
  std::size_t failed_fits = 0;       ///< vertices with too few points or a non-finite fit
};

PrincipalCurvatureResult compute_principal_curvatures(Mesh& mesh,
                                                      const PrincipalCurvatureOptions& options = {});

}  // namespace surftex
