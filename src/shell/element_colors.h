// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Colours and preview renders of geometric-texture elements (Zhou et al. 2006,
// section 4: editing the colours of synthesized elements): one colour per
// element id, and a shaded software render (geometry/rasterizer.h) to look at.
#include <cstdint>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

/// Writes kVertexColor: every vertex gets a colour drawn (deterministically
/// from `seed` and the id) for the kFaceElement id of one of its faces.
/// Throws InvalidInputError if the mesh has no kFaceElement map.
void color_by_element(Mesh& mesh, std::uint64_t seed = 1);

/// Shaded render of a z-up scene (vertex colours if present, else a
/// constant): geometry/render_view.h with ViewOptions::Up::Z, camera fitted
/// to the bounding box at the given azimuth / elevation (degrees), size x size
/// pixels. Throws as render_view().
Image render_preview(const Mesh& mesh, float azimuth_deg = 30.f, float elevation_deg = 35.f, int size = 800);

}  // namespace surftex
