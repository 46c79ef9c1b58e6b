// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mesh swatches the project makes itself (for tests, demos and benchmarks of
// mesh quilting, Zhou et al. 2006 section 2; their examples are chain mail,
// weaves and scattered nuts/apples). Each is deterministic from its seed, lies
// in z around 0 (z is the thin axis), and every element is a closed,
// consistently oriented triangle mesh. The result is written into `out`
// (cleared first) with kFaceElement = element id.
// Throws InvalidInputError on out-of-range options (named with the value).
#include <cstdint>

#include "geometry/mesh_fwd.h"

namespace surftex {

/// A flat chain-mail lattice: "flat" rings (axis z) on a square grid of
/// spacing 2.8 R, and "standing" rings (axis x or y) between every two grid
/// neighbours, each standing ring linked through the holes of both. With the
/// spacing 2.8 R and wire_radius <= 0.2 R the wires keep a clearance of at least
/// 0.6 R - 2 wire_radius (no intersection). The seed varies each ring's phase
/// and its radius by up to +-2%. Faces: 2 * segments * sides per ring.
struct ChainmailOptions {
  int rings_x = 4, rings_y = 4;  ///< flat rings per row / column, 1..64
  double ring_radius = 1.0;      ///< R (centre line), > 0
  double wire_radius = 0.15;     ///< r, in (0, 0.2 R]
  int segments = 20;             ///< around the ring, 6..256
  int sides = 8;                 ///< around the wire, 3..64
  std::uint64_t seed = 1;
};
void make_chainmail_swatch(Mesh& out, const ChainmailOptions& opt = {});

/// A plain weave: threads along x at y = j * spacing and along y at
/// x = i * spacing, each a capped tube whose centre line goes over and under
/// the crossing threads: z = +-amplitude * cos(pi * t / spacing), with signs
/// chosen so that at every crossing one thread is above the other. Needs
/// amplitude > radius (no intersection). The seed moves each thread sideways
/// by up to 4% of the spacing and changes its radius by up to +-5%.
struct WeaveOptions {
  int threads_x = 6, threads_y = 6;  ///< threads running along x / along y, 1..64
  double spacing = 1.0;              ///< > 0
  double amplitude = 0.2;            ///< over-under height, > radius * 1.06
  double radius = 0.12;              ///< tube radius, in (0, 0.4 spacing]
  int segments_per_spacing = 12;     ///< 2..64
  int sides = 8;                     ///< 3..64
  std::uint64_t seed = 1;
};
void make_weave_swatch(Mesh& out, const WeaveOptions& opt = {});

/// Small closed blobs ("nuts") scattered over [0,size]^2 by Poisson-disc dart
/// throwing: each blob an icosphere of radius in [min_radius, max_radius],
/// flattened to 60% in z and perturbed by a smooth random bump of at most 10%;
/// centres at least 2.3 * max_radius apart (blobs never overlap).
struct ScatterOptions {
  double size = 10.0;         ///< > 4 max_radius
  double min_radius = 0.45;   ///< > 0
  double max_radius = 0.65;   ///< >= min_radius
  int subdivisions = 2;       ///< icosphere level 0..4 (320 faces at 2)
  int max_elements = 200;     ///< 1..100000
  int attempts = 3000;        ///< dart throws
  std::uint64_t seed = 1;
};
void make_scatter_swatch(Mesh& out, const ScatterOptions& opt = {});

/// Separate tilted rings: a tori_x x tori_y grid of tori (major radius R,
/// minor radius r) at spacing `spacing`, each centre moved by up to 3% of the
/// spacing and each ring's plane tilted away from xy by an angle in
/// [0, tilt_max_deg] about a random horizontal axis (a layer of scattered
/// rings or washers: a disjoint-element swatch for Zhou et al. 2006, whose
/// elements must keep their spacing). The rings never touch: spacing must
/// exceed 2 (R + r) + 0.06 spacing. Faces: 2 * segments * sides per torus.
struct ToriOptions {
  int tori_x = 4, tori_y = 4;   ///< rings per row / column, 1..64
  double spacing = 3.0;         ///< centre spacing, > 2 (R + r) / 0.94
  double major_radius = 1.0;    ///< R, > 0
  double minor_radius = 0.25;   ///< r, in (0, 0.5 R]
  double tilt_max_deg = 35.0;   ///< in [0, 80]
  int segments = 24;            ///< around the ring, 6..256
  int sides = 8;                ///< around the tube, 3..64
  std::uint64_t seed = 1;
};
void make_tori_swatch(Mesh& out, const ToriOptions& opt = {});

}  // namespace surftex
