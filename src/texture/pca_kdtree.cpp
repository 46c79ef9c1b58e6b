// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/pca_kdtree.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <Eigen/Dense>
#include <nanoflann.hpp>

#include <algorithm>
#include <string>

#include "geometry/errors.h"

namespace surftex {

namespace {
// out[k] for k = k0 .. dims-1: four directions at a time, four independent
// sums, each still in index order (the same numbers as one at a time: a
// product rounded, then a sum rounded), so they overlap in the pipeline
// instead of waiting on one chain of additions.
template <class T>
void project_from(const float* v, const std::vector<T>& basis, const std::vector<T>& mean, int dim, int dims, int k0,
                  T* out) {
  int k = k0;
  for (; k + 4 <= dims; k += 4) {
    const T* b = &basis[static_cast<std::size_t>(k) * dim];
    T s0 = 0, s1 = 0, s2 = 0, s3 = 0;
    for (int i = 0; i < dim; ++i) {
      const T d = static_cast<T>(v[i]) - mean[i];
      s0 += b[i] * d;
      s1 += b[dim + i] * d;
      s2 += b[2 * dim + i] * d;
      s3 += b[3 * dim + i] * d;
    }
    out[k] = s0;
    out[k + 1] = s1;
    out[k + 2] = s2;
    out[k + 3] = s3;
  }
  for (; k < dims; ++k) {
    const T* b = &basis[static_cast<std::size_t>(k) * dim];
    T s = 0;
    for (int i = 0; i < dim; ++i) s += b[i] * (static_cast<T>(v[i]) - mean[i]);
    out[k] = s;
  }
}
}  // namespace

void PcaBasis::project(const float* v, float* out) const {
  int k = 0;
#if defined(__SSE2__)
  // With basis4, each group of four directions is one SSE lane each (the
  // same product and sum per lane as project_from's).
  const std::size_t quads = dim > 0 ? basis4.size() / (4 * static_cast<std::size_t>(dim)) : 0;
  for (; k + 4 <= dims && static_cast<std::size_t>(k / 4) < quads; k += 4) {
    const float* b = &basis4[static_cast<std::size_t>(k / 4) * 4 * dim];
    __m128 s = _mm_setzero_ps();
    for (int i = 0; i < dim; ++i) s = _mm_add_ps(s, _mm_mul_ps(_mm_loadu_ps(b + 4 * i), _mm_set1_ps(v[i] - mean[i])));
    _mm_storeu_ps(out + k, s);
  }
#endif
  project_from(v, basis, mean, dim, dims, k, out);
}

void PcaBasis::project(const float* v, double* out) const { project_from(v, basis_d, mean_d, dim, dims, 0, out); }

// Samples are summed in blocks of kBlock (one rank-kBlock update of the
// lower triangle instead of kBlock rank-1 updates: the search index's build
// fits 16,384 samples per rotation).
struct PcaFit::Sums {
  static constexpr int kBlock = 64;
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;    // lower triangle of sum x x^T
  Eigen::MatrixXd block;  // dim x kBlock samples not summed yet
  int pending = 0;
  void flush() {
    if (pending == 0) return;
    const auto b = block.leftCols(pending);
    mean += b.rowwise().sum();
    cov.selfadjointView<Eigen::Lower>().rankUpdate(b);
    pending = 0;
  }
};

PcaFit::PcaFit(int dim) : dim_(dim), sums_(std::make_unique<Sums>()) {
  if (dim < 1) throw InvalidInputError("PcaFit: dim " + std::to_string(dim) + " < 1");
  sums_->mean = Eigen::VectorXd::Zero(dim);
  sums_->cov = Eigen::MatrixXd::Zero(dim, dim);
  sums_->block = Eigen::MatrixXd(dim, Sums::kBlock);
}

PcaFit::~PcaFit() = default;

void PcaFit::add(const float* v) {
  sums_->block.col(sums_->pending) = Eigen::Map<const Eigen::VectorXf>(v, dim_).cast<double>();
  if (++sums_->pending == Sums::kBlock) sums_->flush();
  ++count_;
}

PcaBasis PcaFit::fit(int dims, const std::string& what) const {
  if (count_ == 0) throw InvalidInputError(what + ": PCA of no sample");
  sums_->flush();  // the sums, not the fit's result, change: logically const
  if (dims < 1 || dims > dim_)
    throw InvalidInputError(what + ": PCA dims " + std::to_string(dims) + " outside 1.." + std::to_string(dim_));
  const double n = static_cast<double>(count_);
  const Eigen::VectorXd mean = sums_->mean / n;
  Eigen::MatrixXd cov = sums_->cov.selfadjointView<Eigen::Lower>();
  cov = cov / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  if (eig.info() != Eigen::Success)
    throw SolverError(what + ": PCA eigen-decomposition failed (" + std::to_string(dim_) + " dimensions, " +
                      std::to_string(count_) + " samples)");
  PcaBasis b;
  b.dim = dim_;
  b.dims = dims;
  b.mean.resize(dim_);
  b.mean_d.resize(dim_);
  for (int i = 0; i < dim_; ++i) {
    b.mean_d[i] = mean[i];
    b.mean[i] = static_cast<float>(mean[i]);
  }
  b.eigenvalues.resize(dim_);
  for (int i = 0; i < dim_; ++i) b.eigenvalues[i] = std::max(0.0, eig.eigenvalues()[dim_ - 1 - i]);
  b.basis.assign(static_cast<std::size_t>(dims) * dim_, 0.f);
  b.basis_d.assign(static_cast<std::size_t>(dims) * dim_, 0.0);
  for (int k = 0; k < dims; ++k) {  // eigenvalues ascend: take the last dims
    Eigen::VectorXd ev = eig.eigenvectors().col(dim_ - 1 - k);
    int big = 0;
    ev.cwiseAbs().maxCoeff(&big);
    if (ev[big] < 0) ev = -ev;
    for (int i = 0; i < dim_; ++i) {
      b.basis_d[static_cast<std::size_t>(k) * dim_ + i] = ev[i];
      b.basis[static_cast<std::size_t>(k) * dim_ + i] = static_cast<float>(ev[i]);
    }
  }
  const int quads = dims / 4;
  b.basis4.assign(static_cast<std::size_t>(quads) * 4 * dim_, 0.f);
  for (int k = 0; k < quads * 4; ++k)
    for (int i = 0; i < dim_; ++i)
      b.basis4[static_cast<std::size_t>(k / 4) * 4 * dim_ + 4 * static_cast<std::size_t>(i) + k % 4] =
          b.basis[static_cast<std::size_t>(k) * dim_ + i];
  return b;
}

namespace {

template <class T>
struct Cloud {
  const std::vector<T>* pts;
  int dim;
  std::size_t kdtree_get_point_count() const { return dim ? pts->size() / dim : 0; }
  T kdtree_get_pt(std::size_t i, std::size_t d) const { return (*pts)[i * dim + d]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};

// Adapts a KdIndex visitor to nanoflann's result-set interface.
template <class T>
struct VisitorSet {
  typename KdIndex<T>::Visitor* v;
  const std::uint32_t* order;  // tree slot -> point index
  std::size_t n = 0;
  std::size_t size() const { return n; }
  bool full() const { return true; }
  T worstDist() const { return v->bound(); }
  bool addPoint(T d, std::uint32_t i) {
    if (d > v->bound()) return true;
    ++n;
    return v->add(d, order[i]);
  }
};

}  // namespace

template <class T>
struct KdIndex<T>::Tree {
  Cloud<T> cloud;
  nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<T, Cloud<T>>, Cloud<T>, -1, std::uint32_t>
      index;
  Tree(const std::vector<T>* pts, int dims)
      : cloud{pts, dims}, index(dims, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
};

template <class T>
KdIndex<T>::KdIndex(std::vector<T> points, int dims) : points_(std::move(points)), dims_(dims) {
  if (dims < 1) throw InvalidInputError("KdIndex: dims " + std::to_string(dims) + " < 1");
  if (points_.size() % static_cast<std::size_t>(dims) != 0)
    throw InvalidInputError("KdIndex: " + std::to_string(points_.size()) + " coordinates are not a multiple of " +
                            std::to_string(dims));
  tree_ = std::make_unique<Tree>(&points_, dims);
  store_in_tree_order();
}

// The points rearranged in the tree's leaf order (each leaf's points then lie
// together in memory instead of scattered over the cloud) and the tree's
// accessor made the identity; order_ maps back. The tree, its visiting order
// and hence every result are unchanged.
template <class T>
void KdIndex<T>::store_in_tree_order() {
  auto& acc = tree_->index.vAcc;
  const std::size_t n = acc.size();
  const std::size_t d = static_cast<std::size_t>(dims_);
  std::vector<T> moved(points_.size());
  order_.resize(n);
  slot_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    const std::size_t i = acc[j];
    std::copy_n(points_.data() + i * d, d, moved.data() + j * d);
    order_[j] = static_cast<std::uint32_t>(i);
    slot_[i] = static_cast<std::uint32_t>(j);
    acc[j] = j;
  }
  points_.swap(moved);
}

template <class T>
KdIndex<T>::~KdIndex() = default;

template <class T>
std::size_t KdIndex<T>::size() const {
  return points_.size() / dims_;
}

template <class T>
std::size_t KdIndex<T>::knn(const T* q, std::size_t k, float eps, std::uint32_t* index, T* d2) const {
  if (k == 0 || size() == 0) return 0;
  nanoflann::KNNResultSet<T, std::uint32_t> rs(k);
  rs.init(index, d2);
  tree_->index.findNeighbors(rs, q, nanoflann::SearchParams(32, eps));
  const std::size_t r = rs.size();
  for (std::size_t i = 0; i < r; ++i) index[i] = order_[index[i]];
  return r;
}

template <class T>
void KdIndex<T>::search(const T* q, Visitor& v, float eps) const {
  if (size() == 0) return;
  VisitorSet<T> rs{&v, order_.data()};
  tree_->index.findNeighbors(rs, q, nanoflann::SearchParams(32, eps));
}

template <class T>
std::size_t KdIndex<T>::bytes() const {
  // Points, the permutation and about 2 n / 16 nodes of ~ (2 dims + 4) words.
  const std::size_t n = size();
  return points_.size() * sizeof(T) + 3 * n * sizeof(std::uint32_t) +
         (2 * n / 16 + 1) * (2 * dims_ * sizeof(T) + 32);
}

template class KdIndex<float>;
template class KdIndex<double>;

}  // namespace surftex
