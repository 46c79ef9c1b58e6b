// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Bakes per-vertex colours into a texture atlas image, so a vertex-coloured
// result also exists as an image (Bangay & Morkel 2006, section 3.5: "the
// surface colouring can be converted into a conventional texture map").
// Every triangle is drawn in UV space (kCornerUV, v up: v = 0 is the bottom
// row) by a small scan-converter: a pixel whose centre lies inside the
// triangle (barycentrics >= -1e-6) gets the barycentric blend of the three
// vertex colours. Then `dilate` rings of empty pixels around the charts are
// filled with the mean of their filled 8-neighbours (against bleeding when
// mip-mapped). Empty pixels stay `background`.
//
// Reads kCornerUV and kVertexColor. Throws InvalidInputError (non-triangle
// face, missing map, size outside 1..16384, dilate < 0).

#include <array>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

struct BakeOptions {
  int size = 1024;                                ///< atlas width = height, pixels
  int dilate = 4;                                 ///< gutter rings filled
  std::array<float, 3> background{0.f, 0.f, 0.f};
};

struct BakeResult {
  Image image;                 ///< size x size x 3
  std::size_t covered = 0;     ///< pixels covered by a triangle
};

BakeResult bake_vertex_colors(const Mesh& mesh, const BakeOptions& opt = {});

}  // namespace surftex
