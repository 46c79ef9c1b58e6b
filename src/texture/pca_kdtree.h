// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The texture module's one nearest-neighbour index over image
// neighbourhoods: a principal component analysis (PCA) of fixed-length
// vectors and a kd-tree (nanoflann) over their projections. Used by the
// approximate Efros-Leung search (efros_leung.h, Gorla 3.3), the constrained
// tile synthesis (Ray 2009, 1.2: "compression scheme similar to [LH06] ...
// kd-tree ... ANN") and the bidirectional similarity (its exact
// branch-and-bound search).
//
// PcaFit accumulates vectors (double sums) into a PcaBasis (mean, leading
// eigenvectors, each signed deterministically); KdIndex<T>: a kd-tree (leaf
// 16) for (1+eps)-approximate k-nearest queries and bounded visitor searches.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace surftex {

/// Mean and leading principal directions of a set of vectors.
struct PcaBasis {
  int dim = 0;   ///< length of the input vectors
  int dims = 0;  ///< number of kept directions
  std::vector<float> mean, basis;       ///< float copies: mean (dim), basis (dims x dim, row-major)
  std::vector<double> mean_d, basis_d;  ///< the same in double
  std::vector<double> eigenvalues;      ///< every eigenvalue (dim), decreasing, clamped at 0
  /// `basis` four directions at a time, interleaved: basis4[(k / 4) * 4 * dim + 4 * i + k % 4]
  /// for k < dims rounded down to 4 (set by PcaFit::fit; empty = not used).
  std::vector<float> basis4;
  /// out[k] = sum_i basis[k][i] * (v[i] - mean[i]), float arithmetic in index order.
  void project(const float* v, float* out) const;
  /// The same in double arithmetic.
  void project(const float* v, double* out) const;
};

/// Accumulates sample vectors of length `dim` for a PCA.
class PcaFit {
 public:
  explicit PcaFit(int dim);
  ~PcaFit();
  PcaFit(const PcaFit&) = delete;
  PcaFit& operator=(const PcaFit&) = delete;
  void add(const float* v);
  std::size_t count() const { return count_; }
  /// The `dims` (1..dim) leading directions. Throws InvalidInputError when no
  /// sample was added or dims is out of range, SolverError (its message
  /// starting with `what`) when the eigen decomposition fails.
  PcaBasis fit(int dims, const std::string& what) const;

 private:
  struct Sums;
  int dim_;
  std::size_t count_ = 0;
  std::unique_ptr<Sums> sums_;
};

/// Kd-tree over `n` points of `dims` coordinates of type T (float or double).
template <class T>
class KdIndex {
 public:
  /// Visitor for search(): bound() is the current pruning radius (squared
  /// distance; subtrees and points farther away are skipped), add() sees a
  /// point within it and returns false to stop the search.
  struct Visitor {
    virtual ~Visitor() = default;
    virtual T bound() const = 0;
    virtual bool add(T squared_distance, std::uint32_t index) = 0;
  };
  /// Builds the tree over `points` (n x dims, row-major; kept by the index).
  KdIndex(std::vector<T> points, int dims);
  ~KdIndex();
  KdIndex(const KdIndex&) = delete;
  KdIndex& operator=(const KdIndex&) = delete;
  std::size_t size() const;
  int dims() const { return dims_; }
  const T* point(std::size_t i) const { return points_.data() + slot_[i] * static_cast<std::size_t>(dims_); }
  /// The (up to) k nearest points to q, nearest first, (1+eps)-approximate
  /// (eps >= 0); writes index[0..r) and squared distance[0..r), returns r.
  std::size_t knn(const T* q, std::size_t k, float eps, std::uint32_t* index, T* squared_distance) const;
  /// Visits the points the tree cannot exclude with v.bound().
  void search(const T* q, Visitor& v, float eps = 0.f) const;
  /// Bytes held (points and tree nodes, estimated), for memory budgets.
  std::size_t bytes() const;

 private:
  struct Tree;
  void store_in_tree_order();
  std::vector<T> points_;  // in the tree's leaf order
  std::vector<std::uint32_t> order_, slot_;  // leaf slot -> point index, and back
  int dims_;
  std::unique_ptr<Tree> tree_;
};

extern template class KdIndex<float>;
extern template class KdIndex<double>;

}  // namespace surftex
