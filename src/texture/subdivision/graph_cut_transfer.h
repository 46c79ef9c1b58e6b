// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Graph-cut texture transfer onto a surface region (Bangay & Morkel 2006,
// section 3.4, figure 9; after Kwatra et al. 2003). Mesh independent: the
// caller gives the region's vertices as nodes and its mesh edges.
//
// Nodes are the region's vertices, each with its current surface colour C_s
// (if it has one) and the colour C_t of its corresponding texel of the
// matched neighbourhood. Terminals: the texture terminal (source) and the
// surface terminal (sink). Links:
//   - the target vertex (node `center`) -> texture terminal, infinite;
//   - every coloured vertex on the region's border (hops == border_hops) ->
//     surface terminal, infinite (it keeps its colour);
//   - every uncoloured vertex -> texture terminal, infinite (it has no colour
//     to keep; documented choice, the paper only discusses coloured ones);
//   - a `pinned` vertex (the matched neighbourhood has no texel for it: it
//     falls outside a non-periodic exemplar) -> surface terminal, infinite;
//     its mismatch term is 0 (it keeps its colour, or stays uncoloured);
//   - every region edge (A, B): W(A,B) = M(A,B) exp(-(x_A^2 + x_B^2) / (sigma r^2))
//     both ways, with M(A,B) = |C_s(A) - C_t(A)| + |C_s(B) - C_t(B)| (Euclidean
//     RGB norms; a term is 0 for an uncoloured vertex), x = the vertex's
//     distance from the target in texture space (texels), r = the diameter of
//     the texture neighbourhood (texels), sigma = the weighting parameter
//     (equation 1).
// The min cut (GraphCut, Boost.Graph boykov_kolmogorov_max_flow) splits the
// region: source-side vertices take the texture colour, the rest keep theirs.
// The seam cost of a labelling is the sum of W over edges whose ends take
// colour from different sources; the min cut's seam cost is never above that
// of pasting (every vertex except the coloured border takes the texture),
// which the result reports for comparison.
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
