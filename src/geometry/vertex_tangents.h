// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Per-vertex tangent frames for tangent-space normal maps (glTF TANGENT), in
// the manner of MikkTSpace: per triangle the directions of increasing u and
// v on the surface (from the uv derivatives), projected into the tangent
// plane of each corner's vertex normal, weighted by the corner angle and
// summed per vertex; the tangent is the normalised sum along +u, and w = +1
// or -1 says whether cross(normal, tangent) points along +v (v up: the
// normal map's +Y, the "+Y up" / OpenGL convention glTF uses) or against it
// (mirrored uv). A vertex whose sum vanishes (degenerate uv) gets any unit
// vector perpendicular to its normal, w = +1. Inputs are the glTF vertices
// (one per distinct position + uv), so seams split the frames as the uv do.
// No CGAL here.

#include <array>
#include <cstdint>
#include <vector>

namespace surftex {

/// Tangents (x, y, z unit, w = +-1), one per vertex. `uv` with v up; `normals`
/// need not be unit. Throws InvalidInputError if sizes disagree or an index
/// is out of range.
std::vector<std::array<float, 4>> vertex_tangents(const std::vector<std::array<float, 3>>& positions,
                                                  const std::vector<std::array<float, 3>>& normals,
                                                  const std::vector<std::array<float, 2>>& uv,
                                                  const std::vector<std::uint32_t>& triangles);

}  // namespace surftex
