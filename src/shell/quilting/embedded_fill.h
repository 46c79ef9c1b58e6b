// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The scatter fill once more, on the embedded quilt (issue 17 item 4): the
// embedding (Zhou et al. 2006 s.3.2) cuts threads that the shell map folds
// over a sharp rim, which the quilt's lifted approximation did not see, and
// leaves bare what they covered. Here templates (pieces of the swatch's
// threads) are placed into what the output leaves bare, in mesh space: each
// template vertex's planar position on the face's tangent plane is projected
// to its closest point on the base and lifted along the interpolated vertex
// normal by its swatch height, as the quilt lifts its vertices. A placement
// is kept only if it stays on one side of the surface (every foot's face
// within a normal cone of the face) and over it (each point off its foot
// along the normal more than beside it: not past an open border), no edge is
// stretched past the bounds, it crosses no element (exact, ElementCollider)
// and not itself beyond the swatch's own crossings: so it adds no crossing
// and no shard.
//
// Orientation: a piece runs along the nearest embedded element's long axis
// (the weave's threads near it), or a quarter turn of it; given an up
// direction, along its projection (the quilt's guidance field, unsmoothed).
//
// Compact elements (rings, tubes, pebbles: `rigid`) are placed whole, as the
// embedding places them (affinely, not bent): a rigid copy in the face's
// tangent frame, rested on the base (lifted until no vertex lies below its
// height over the base), kept only if no vertex floats more than max_float
// over its height, it crosses neither the base nor an element (exact), and
// keeps `clearance` to every element (the quilt scatter's gap). Where the
// full size rests nowhere, passes with copies scaled by `smaller` follow
// (legs, horns, rims narrower than an element). Each rigid attempt places a
// proxy of ~48 template vertices first, so most failures cost little.
// Reads: the base (triangles), the elements. Writes: appends to `els`.
// Deterministic for a seed (faces in order, one generator).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "shell/element_mesh.h"

namespace surftex {

struct EmbeddedFillOptions {
  /// What is placed: swatch units, centred in xy (thread_scatter_pieces). Empty: nothing.
  std::vector<ElementMesh> templates;
  double scale = 0;   ///< mesh units per swatch unit (> 0 when templates are given)
  double z0 = 0;      ///< the swatch z that lies on the base
  double radius = 0;  ///< bare radius, mesh units (the bare-area measure's, > 0)
  int attempts = 16;  ///< tries per bare face (quarter turns, then moved), 1..64
  /// No placed edge longer than max_stretch times its template edge, scaled, nor than max_edge (> 0).
  double max_stretch = 2.0, max_edge = 0;
  /// Every foot's face normal within this angle of the bare face's (deg).
  double max_normal_angle_deg = 60.0;
  /// Self-intersecting pairs a placed piece may keep (the swatch's own).
  std::size_t own_crossings = 0;
  /// Whole rigid copies (compact elements) instead of pieces bent over the base.
  bool rigid = false;
  /// Rigid copies: how far a vertex may float over its height above the base (mesh units, >= 0).
  double max_float = 0;
  /// Gap kept to every element (mesh units, >= 0; 0: only no crossing).
  double clearance = 0;
  /// Rigid copies: further passes over what is still bare, with copies
  /// scaled by these factors in turn (each in (0, 1); max_float and clearance
  /// scaled with them): legs and horns narrower than an element take smaller
  /// ones. Empty: the full size only.
  std::vector<double> smaller;
  /// Quarter turns tried before the copy is moved: 4, or 1 (the direction only).
  int turns = 4;
  /// Non-zero: pieces run along its projection on the face (else the nearest element's axis).
  P3 up{0, 0, 0};
  std::uint64_t seed = 1;
};

struct EmbeddedFillResult {
  std::size_t faces_tried = 0;  ///< base faces with a bare sample point
  std::size_t placed = 0;       ///< pieces appended
  std::size_t placed_smaller = 0;  ///< of which rigid copies smaller than the full size
};

/// See the header comment. Throws InvalidInputError for bad options.
EmbeddedFillResult fill_embedded_bare(const ElementMesh& base, std::vector<ElementMesh>& els,
                                      const EmbeddedFillOptions& opt);

}  // namespace surftex
