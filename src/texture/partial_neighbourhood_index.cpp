// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/partial_neighbourhood_index.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/errors.h"

namespace surftex {

PartialNeighbourhoodIndex::PartialNeighbourhoodIndex(const float* planes, std::size_t plane_size, int pitch,
                                                     int channels, const std::vector<int>& ids, int window,
                                                     int pca_dims, int stride)
    : f_(window), C_(channels), pitch_(pitch), stride_(stride) {
  const std::string fn = "PartialNeighbourhoodIndex: ";
  if (ids.empty()) throw InvalidInputError(fn + "no candidate position");
  if (stride < 1) throw InvalidInputError(fn + "stride " + std::to_string(stride) + " < 1");
  if (window < 1 || channels < 1 || pitch < window)
    throw InvalidInputError(fn + "window " + std::to_string(window) + ", channels " + std::to_string(channels) +
                            ", pitch " + std::to_string(pitch));
  const int raw = f_ * f_ * C_;
  d_ = std::clamp(pca_dims, 1, raw);
  const int lo = -(f_ / 2);
  std::vector<int> offset(static_cast<std::size_t>(f_) * f_);
  for (int dy = 0; dy < f_; ++dy)
    for (int dx = 0; dx < f_; ++dx) offset[dy * f_ + dx] = (dy + lo) * pitch + (dx + lo);
  auto raw_vec = [&](int id, float* out) {
    for (int s = 0; s < f_ * f_; ++s)
      for (int c = 0; c < C_; ++c) out[s * C_ + c] = planes[c * plane_size + id + offset[s]];
  };
  // PCA on up to 16384 evenly spaced candidates.
  const std::size_t N = ids.size();
  const std::size_t step = std::max<std::size_t>(1, N / 16384);
  PcaFit fit(raw);
  std::vector<float> v(raw);
  for (std::size_t i = 0; i < N; i += step) {
    raw_vec(ids[i], v.data());
    fit.add(v.data());
  }
  pca_ = fit.fit(d_, "efros_leung approximate search");
  // Prior: residual variance per entry over each kept eigenvalue.
  double rest = 0;
  for (int j = d_; j < raw; ++j) rest += pca_.eigenvalues[j];
  const double s2 = std::max(raw > d_ ? rest / (raw - d_) : 0.0, 1e-6 * pca_.eigenvalues[0] + 1e-12);
  prior_.resize(d_);
  for (int j = 0; j < d_; ++j) prior_[j] = s2 / std::max(pca_.eigenvalues[j], s2);
  basis_t_.resize(static_cast<std::size_t>(raw) * d_);
  for (int r = 0; r < raw; ++r)
    for (int j = 0; j < d_; ++j) basis_t_[r * d_ + j] = pca_.basis_d[static_cast<std::size_t>(j) * raw + r];
  slot_gram_.assign(static_cast<std::size_t>(f_) * f_ * d_ * d_, 0.0);
  for (int s = 0; s < f_ * f_; ++s)
    for (int c = 0; c < C_; ++c) {
      const double* b = &basis_t_[(s * C_ + c) * d_];
      double* g = &slot_gram_[static_cast<std::size_t>(s) * d_ * d_];
      for (int i = 0; i < d_; ++i)
        for (int j = 0; j < d_; ++j) g[i * d_ + j] += b[i] * b[j];
    }
  // Coefficients of every indexed candidate (all, or those on the stride grid).
  for (int id : ids)
    if ((id % pitch) % stride == 0 && (id / pitch) % stride == 0) ids_.push_back(id);
  if (ids_.empty()) {  // no candidate on the grid (a tiny exemplar): index them all
    ids_ = ids;
    stride_ = 1;
  }
  if (stride_ > 1) {
    member_.assign(plane_size, 0);
    for (int id : ids) member_[id] = 1;
  }
  const std::size_t M = ids_.size();
  std::vector<float> pts(M * d_);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, M, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
    std::vector<float> rv(raw);
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      raw_vec(ids_[i], rv.data());
      pca_.project(rv.data(), &pts[i * d_]);
    }
  });
  tree_ = std::make_unique<KdIndex<float>>(std::move(pts), d_);
}

PartialNeighbourhoodIndex::~PartialNeighbourhoodIndex() = default;

std::size_t PartialNeighbourhoodIndex::query(const int* slot, const float* values, int known, std::size_t k,
                                             float eps, std::vector<int>& out, Scratch& s) const {
  if (known <= 0 || k == 0) return 0;
  const int d = d_;
  s.a.assign(static_cast<std::size_t>(d) * d, 0.0);
  s.rhs.assign(d, 0.0);
  for (int i = 0; i < known; ++i) {
    const int sl = slot[i];
    const double* g = &slot_gram_[static_cast<std::size_t>(sl) * d * d];
    for (int t = 0; t < d * d; ++t) s.a[t] += g[t];
    for (int c = 0; c < C_; ++c) {
      const int r = sl * C_ + c;
      const double x = static_cast<double>(values[i * C_ + c]) - pca_.mean_d[r];
      const double* b = &basis_t_[static_cast<std::size_t>(r) * d];
      for (int j = 0; j < d; ++j) s.rhs[j] += b[j] * x;
    }
  }
  for (int j = 0; j < d; ++j) s.a[j * d + j] += prior_[j];
  // Cholesky solve (the matrix is symmetric positive definite: Gram + prior).
  double* A = s.a.data();
  for (int j = 0; j < d; ++j) {
    double diag = A[j * d + j];
    for (int t = 0; t < j; ++t) diag -= A[j * d + t] * A[j * d + t];
    diag = std::sqrt(std::max(diag, 1e-300));
    A[j * d + j] = diag;
    for (int i = j + 1; i < d; ++i) {
      double v = A[i * d + j];
      for (int t = 0; t < j; ++t) v -= A[i * d + t] * A[j * d + t];
      A[i * d + j] = v / diag;
    }
  }
  double* y = s.rhs.data();
  for (int i = 0; i < d; ++i) {
    for (int t = 0; t < i; ++t) y[i] -= A[i * d + t] * y[t];
    y[i] /= A[i * d + i];
  }
  for (int i = d - 1; i >= 0; --i) {
    for (int t = i + 1; t < d; ++t) y[i] -= A[t * d + i] * y[t];
    y[i] /= A[i * d + i];
  }
  s.c.resize(d);
  for (int j = 0; j < d; ++j) s.c[j] = static_cast<float>(y[j]);
  s.hits.resize(k);
  s.d2.resize(k);
  const std::size_t r = tree_->knn(s.c.data(), k, eps, s.hits.data(), s.d2.data());
  const std::size_t before = out.size();
  for (std::size_t i = 0; i < r; ++i) {
    const int id = ids_[s.hits[i]];
    if (stride_ == 1) {
      out.push_back(id);
      continue;
    }
    for (int dy = 0; dy < stride_; ++dy)
      for (int dx = 0; dx < stride_; ++dx) {
        const std::size_t c = static_cast<std::size_t>(id) + static_cast<std::size_t>(dy) * pitch_ + dx;
        if (c < member_.size() && member_[c]) out.push_back(static_cast<int>(c));
      }
  }
  return out.size() - before;
}

std::size_t PartialNeighbourhoodIndex::bytes() const {
  return tree_->bytes() + ids_.size() * sizeof(int) + member_.size() +
         (slot_gram_.size() + basis_t_.size()) * sizeof(double);
}

}  // namespace surftex
