// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Disjoint sets over 0..n-1: path halving, and a union keeps the smaller root,
// so every set's root is its lowest index whatever the order of the unions
// (labels that do not depend on traversal order).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

namespace surftex {

template <typename Index = int>
class UnionFind {
 public:
  explicit UnionFind(std::size_t n = 0) { reset(n); }

  /// n singleton sets.
  void reset(std::size_t n) {
    parent_.resize(n);
    std::iota(parent_.begin(), parent_.end(), Index{0});
  }

  /// The root (lowest index) of x's set.
  Index find(Index x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }

  /// Merges the sets of a and b; returns false when they were one set already.
  bool unite(Index a, Index b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    parent_[std::max(a, b)] = std::min(a, b);
    return true;
  }

  std::size_t size() const { return parent_.size(); }

 private:
  std::vector<Index> parent_;
};

}  // namespace surftex
