// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Approximate nearest neighbourhoods for partially known queries: the
// candidate short list of efros_leung.h's approximate first pass (Gorla 3.3).
//
// Index: every candidate's f x f neighbourhood reduced by PCA (pca_kdtree.h)
// in a kd-tree. Query: coefficients of a partly known neighbourhood as the
// probabilistic-PCA posterior mean (Tipping & Bishop 1999) from its known
// entries; the k (1+eps)-approximate nearest returned, ranked exactly by the
// caller. Cost independent of the candidate count. In full: decision 501.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "texture/pca_kdtree.h"

namespace surftex {

class PartialNeighbourhoodIndex {
 public:
  /// `planes`: `channels` planes (row pitch `pitch`); `ids`: candidate centres
  /// whose f x f window lies inside; pca_dims clamped to 1..f*f*channels;
  /// `stride` >= 1: only positions on multiples of it are indexed, each hit
  /// standing for its block. Throws InvalidInputError (empty ids, bad sizes),
  /// SolverError (PCA).
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
