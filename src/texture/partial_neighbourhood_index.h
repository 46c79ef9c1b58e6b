// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Approximate nearest neighbourhoods for partially known queries: the
// candidate short list of efros_leung.h's approximate first pass (Gorla 3.3).
//
// Index: the f x f neighbourhood (all channels) of every given candidate
// position of an image (channel planes), reduced by PCA to `pca_dims`
// coefficients (texture/pca_kdtree.h, fitted on up to 16384 evenly spaced
// candidates) and put in a kd-tree.
//
// Query: a neighbourhood of which only some pixels are known (the rest of
// an Efros-Leung window is not synthesised yet). Its coefficients are
// estimated from the known entries as the posterior mean of probabilistic
// PCA (Tipping & Bishop 1999): c = (B_K^T B_K + s2 L^-1)^-1 B_K^T (x_K - mu_K),
// with B_K the basis rows of the known entries, L the kept eigenvalues and s2
// the mean of the discarded ones (the residual variance per entry). With
// every entry known and s2 small this is the plain projection. The k nearest
// candidates of c ((1+eps)-approximate) are returned; the caller ranks them
// exactly. Cost per query: O(known pixels * pca_dims^2 + pca_dims^3 + tree
// search), independent of the number of candidates but for the tree's depth.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "texture/pca_kdtree.h"

namespace surftex {

class PartialNeighbourhoodIndex {
 public:
  /// `planes`: `channels` planes of plane_size floats, row pitch `pitch`;
  /// `ids`: candidate centres (buffer offsets y * pitch + x) whose whole f x f
  /// window (offsets -f/2 .. f-1-f/2) lies in the buffer; f = `window` >= 1;
  /// pca_dims in 1..f*f*channels (clamped). Throws InvalidInputError on
  /// empty ids or bad sizes, SolverError if the PCA fails.
  /// `stride` >= 1: only the candidates at buffer positions whose x and y
  /// are multiples of it go in the kd-tree (stride^2 times fewer points); a
  /// query then returns, for each hit, the candidates of its stride x stride
  /// block.
  PartialNeighbourhoodIndex(const float* planes, std::size_t plane_size, int pitch, int channels,
                            const std::vector<int>& ids, int window, int pca_dims, int stride = 1);
  ~PartialNeighbourhoodIndex();

  /// Per-caller scratch (queries are const and thread-safe with one scratch each).
  struct Scratch {
    std::vector<double> a, rhs;
    std::vector<float> c, d2;
    std::vector<std::uint32_t> hits;
  };
  /// The known pixels of the query: slot[i] = (dy - lo) * f + (dx - lo) for
  /// window offset (dx, dy), lo = -f/2, values[i * channels + c]. Appends
  /// the candidate centres (from `ids`) of up to k kd-tree hits to `out`
  /// (stride^2 per hit at most); returns how many were appended.
  std::size_t query(const int* slot, const float* values, int known, std::size_t k, float eps,
                    std::vector<int>& out, Scratch& scratch) const;

  int window() const { return f_; }
  int pca_dims() const { return d_; }
  std::size_t bytes() const;

 private:
  int f_ = 0, C_ = 0, d_ = 0, pitch_ = 0, stride_ = 1;
  std::vector<std::uint8_t> member_;  // per buffer position: 1 = one of `ids`
  PcaBasis pca_;
  std::vector<double> slot_gram_;   // per slot: d x d sum over its channels of b b^T
  std::vector<double> basis_t_;     // per raw entry r: its d basis coefficients
  std::vector<double> prior_;       // s2 / lambda_j
  std::vector<int> ids_;
  std::unique_ptr<KdIndex<float>> tree_;
};

}  // namespace surftex
