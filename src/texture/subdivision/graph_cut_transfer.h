// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Graph-cut texture transfer onto a surface region (Bangay & Morkel 2006,
// section 3.4, figure 9; after Kwatra et al. 2003). Mesh independent: the
// caller gives the region's vertices as nodes and its mesh edges.
//
// Nodes: the region's vertices (surface colour C_s if any, texel colour C_t).
// Infinite links: the centre to the texture side; coloured border vertices
// and `pinned` ones (no texel: outside a non-periodic exemplar) to the
// surface side; uncoloured vertices to the texture side (our choice). Edges:
// W(A,B) = M(A,B) exp(-(x_A^2 + x_B^2) / (sigma r^2)) (eq. 1), M the summed
// colour mismatch. Source-side vertices take the texture colour; the cut's
// seam cost never exceeds pasting's, reported beside it. In full: decision 206.
//
// Throws InvalidInputError (center out of range, edge index out of range,
// sigma or r not > 0).

#include <array>
#include <cstddef>
#include <vector>

namespace surftex {

struct TransferNode {
  bool colored = false;
  std::array<float, 3> surface{};  ///< C_s (ignored when !colored)
  std::array<float, 3> texture{};  ///< C_t
  double distance = 0;             ///< x: texels from the target
  int hops = 0;                    ///< edges from the target
  bool pinned = false;             ///< no texture for it: keeps its colour (or none)
};

struct GraphCutTransferOptions {
  /// sigma of equation (1), > 0. Default 1.
  double sigma = 1.0;
};

struct GraphCutTransferResult {
  std::vector<char> take_texture;  ///< per node: 1 = receives C_t
  double cut_cost = 0;             ///< seam cost of the min cut
  double paste_cost = 0;           ///< seam cost of pasting without a cut
  std::size_t taken = 0;           ///< nodes that take the texture colour
};

/// `r` = neighbourhood diameter in texels; border_hops = the region's k.
GraphCutTransferResult graph_cut_transfer(const std::vector<TransferNode>& nodes,
                                          const std::vector<std::array<int, 2>>& edges, int center,
                                          int border_hops, double r, const GraphCutTransferOptions& opt = {});

/// Seam cost (sum of W over edges whose ends differ in `take_texture`).
double transfer_seam_cost(const std::vector<TransferNode>& nodes, const std::vector<std::array<int, 2>>& edges,
                          const std::vector<char>& take_texture, double r, double sigma);

}  // namespace surftex
