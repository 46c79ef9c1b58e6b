// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/bidirectional_similarity.h"

#include <Eigen/Dense>
#include <nanoflann.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "geometry/errors.h"

namespace surftex {
namespace {

struct Patches {
  int dim = 0;
  std::size_t count = 0;
  std::vector<float> v;  // count x dim
  const float* row(std::size_t i) const { return v.data() + i * dim; }
};

// Patches of `img` at every stride-th position; with `valid` (width*height),
// only those whose k*k pixels are all valid.
Patches extract(const Image& img, int k, bool wrap, int stride, const std::vector<char>* valid = nullptr) {
  Patches p;
  p.dim = k * k * img.channels;
  const int nx = wrap ? img.width : img.width - k + 1;
  const int ny = wrap ? img.height : img.height - k + 1;
  // Valid patch corners: a summed-area table of invalid pixels.
  std::vector<int> bad;
  if (valid) {
    const int W = img.width, H = img.height;
    bad.assign(static_cast<std::size_t>(W + 1) * (H + 1), 0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x)
        bad[static_cast<std::size_t>(y + 1) * (W + 1) + x + 1] =
            ((*valid)[static_cast<std::size_t>(y) * W + x] ? 0 : 1) + bad[static_cast<std::size_t>(y) * (W + 1) + x + 1] +
            bad[static_cast<std::size_t>(y + 1) * (W + 1) + x] - bad[static_cast<std::size_t>(y) * (W + 1) + x];
  }
  auto all_valid = [&](int x, int y) {
    if (!valid) return true;
    const std::size_t W1 = img.width + 1;
    return bad[(y + k) * W1 + x + k] - bad[y * W1 + x + k] - bad[(y + k) * W1 + x] + bad[y * W1 + x] == 0;
  };
  for (int y = 0; y < ny; y += stride)
    for (int x = 0; x < nx; x += stride) {
      if (!all_valid(x, y)) continue;
      for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
          const int sx = (x + i) % img.width, sy = (y + j) % img.height;
          const float* px = img.pixel(sx, sy);
          p.v.insert(p.v.end(), px, px + img.channels);
        }
      ++p.count;
    }
  return p;
}

double ssd(const float* a, const float* b, int dim) {
  double s = 0;
  for (int i = 0; i < dim; ++i) {
    const double d = static_cast<double>(a[i]) - b[i];
    s += d * d;
  }
  return s;
}

// As ssd, but stops once the running sum exceeds `bound` and returns that
// partial sum (> bound): min(bound, result) is unchanged, so exact searches
// stay exact while rejected candidates cost a fraction of the full distance.
double ssd_bounded(const float* a, const float* b, int dim, double bound) {
  double s = 0;
  int i = 0;
  for (; i + 16 <= dim; i += 16) {
    for (int j = i; j < i + 16; ++j) {
      const double d = static_cast<double>(a[j]) - b[j];
      s += d * d;
    }
    if (s > bound) return s;
  }
  for (; i < dim; ++i) {
    const double d = static_cast<double>(a[i]) - b[i];
    s += d * d;
  }
  return s;
}

struct Cloud {
  const std::vector<double>* pts;
  int dim;
  std::size_t n;
  std::size_t kdtree_get_point_count() const { return n; }
  double kdtree_get_pt(std::size_t i, std::size_t d) const { return (*pts)[i * dim + d]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud,
                                                 -1, std::uint32_t>;

// PCA basis (dim x d, orthonormal columns) and mean from a sample of patches.
struct Pca {
  Eigen::VectorXd mean;
  Eigen::MatrixXd basis;
};

Pca fit_pca(const Patches& a, const Patches& b, int d) {
  const int dim = a.dim;
  Pca pca;
  pca.mean = Eigen::VectorXd::Zero(dim);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(dim, dim);
  std::size_t used = 0;
  auto add = [&](const Patches& p) {
    const std::size_t step = std::max<std::size_t>(1, p.count / 8000);
    for (std::size_t i = 0; i < p.count; i += step) {
      Eigen::Map<const Eigen::VectorXf> r(p.row(i), dim);
      Eigen::VectorXd x = r.cast<double>();
      pca.mean += x;
      cov.selfadjointView<Eigen::Lower>().rankUpdate(x);
      ++used;
    }
  };
  add(a);
  add(b);
  pca.mean /= static_cast<double>(used);
  cov = cov.selfadjointView<Eigen::Lower>();
  cov /= static_cast<double>(used);
  cov -= pca.mean * pca.mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(cov);
  if (es.info() != Eigen::Success)
    throw SolverError("bidirectional_similarity: PCA eigen decomposition failed");
  pca.basis = es.eigenvectors().rightCols(d);  // eigenvalues ascend: keep the largest
  return pca;
}

std::vector<double> project(const Patches& p, const Pca& pca) {
  const int d = static_cast<int>(pca.basis.cols());
  std::vector<double> out(p.count * d);
  tbb::parallel_for(std::size_t(0), p.count, [&](std::size_t i) {
    Eigen::Map<const Eigen::VectorXf> r(p.row(i), p.dim);
    Eigen::VectorXd c = pca.basis.transpose() * (r.cast<double>() - pca.mean);
    std::copy(c.data(), c.data() + d, out.begin() + i * d);
  });
  return out;
}

// nanoflann result set doing a branch-and-bound nearest-neighbour search in
// the full patch space: the tree's squared distance in the PCA subspace is a
// lower bound of the full SSD (orthonormal projection), so every point whose
// bound reaches the best full SSD found so far is pruned, and each point the
// tree offers is re-ranked with the full SSD. The result is the exact minimum
// (the visiting order only changes the speed). With max_candidates > 0 the
// search stops after that many full evaluations (approximate, an upper bound).
struct NearestByBound {
  const float* query;
  const Patches* base;
  std::size_t max_candidates;
  double best = std::numeric_limits<double>::infinity();
  std::size_t evaluated = 0;
  std::size_t size() const { return evaluated; }
  bool full() const { return true; }
  // Slack for the float rounding of the projection (the bound is exact in
  // exact arithmetic).
  double worstDist() const { return best * (1.0 + 1e-9); }
  bool addPoint(double lower_bound, std::uint32_t index) {
    if (lower_bound > worstDist()) return true;
    best = std::min(best, ssd_bounded(query, base->row(index), base->dim, best));
    ++evaluated;
    return max_candidates == 0 || evaluated < max_candidates;
  }
};

// Mean over `queries` of the distance to the nearest patch of `base`.
double mean_nearest(const Patches& queries, const Patches& base, const Pca* pca,
                    const std::vector<double>& qproj, const std::vector<double>& bproj,
                    std::size_t max_candidates) {
  std::vector<double> best(queries.count);
  if (!pca) {
    tbb::parallel_for(std::size_t(0), queries.count, [&](std::size_t i) {
      double b = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < base.count; ++j) b = std::min(b, ssd(queries.row(i), base.row(j), base.dim));
      best[i] = b;
    });
  } else {
    const int d = static_cast<int>(pca->basis.cols());
    Cloud cloud{&bproj, d, base.count};
    Tree tree(d, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tbb::parallel_for(std::size_t(0), queries.count, [&](std::size_t i) {
      NearestByBound r{queries.row(i), &base, max_candidates};
      tree.findNeighbors(r, qproj.data() + i * d, nanoflann::SearchParams());
      best[i] = r.best;
    });
  }
  double sum = 0;
  for (double v : best) sum += v;
  return sum / static_cast<double>(queries.count) / base.dim;
}

}  // namespace

BidirectionalResult bidirectional_similarity(const Image& output, const Image& exemplar,
                                             const BidirectionalOptions& opt) {
  auto bad = [](const std::string& m) { throw InvalidInputError("bidirectional_similarity: " + m); };
  if (output.empty()) bad("output image is empty");
  if (exemplar.empty()) bad("exemplar image is empty");
  if (output.channels != exemplar.channels)
    bad("output has " + std::to_string(output.channels) + " channels, exemplar " +
        std::to_string(exemplar.channels));
  if (opt.patch < 1 || opt.patch > 31) bad("patch " + std::to_string(opt.patch) + " outside 1..31");
  if (opt.stride < 1) bad("stride " + std::to_string(opt.stride) + " < 1");
  if (opt.exemplar_stride < 1) bad("exemplar_stride " + std::to_string(opt.exemplar_stride) + " < 1");
  if (opt.max_candidates < 0) bad("max_candidates " + std::to_string(opt.max_candidates) + " < 0");
  if (opt.pca_dims < 1) bad("pca_dims " + std::to_string(opt.pca_dims) + " < 1");
  if (output.width < opt.patch || output.height < opt.patch)
    bad("patch " + std::to_string(opt.patch) + " larger than the output (" +
        std::to_string(output.width) + "x" + std::to_string(output.height) + ")");
  if (!opt.periodic_exemplar && (exemplar.width < opt.patch || exemplar.height < opt.patch))
    bad("patch " + std::to_string(opt.patch) + " larger than the exemplar (" +
        std::to_string(exemplar.width) + "x" + std::to_string(exemplar.height) + ")");
  const bool masked = !opt.output_valid.empty();
  if (masked && opt.output_valid.size() != static_cast<std::size_t>(output.width) * output.height)
    bad("output_valid has " + std::to_string(opt.output_valid.size()) + " entries for a " +
        std::to_string(output.width) + "x" + std::to_string(output.height) + " output");
  const Patches out = extract(output, opt.patch, false, opt.stride, masked ? &opt.output_valid : nullptr);
  if (out.count == 0) bad("the output mask leaves no valid " + std::to_string(opt.patch) + "x" +
                          std::to_string(opt.patch) + " patch");
  const Patches ex = extract(exemplar, opt.patch, opt.periodic_exemplar, 1);
  BidirectionalResult r;
  r.output_patches = out.count;
  r.exemplar_patches = ex.count;
  // Completeness queries: every exemplar_stride-th exemplar patch.
  const Patches exq = opt.exemplar_stride > 1 ? extract(exemplar, opt.patch, opt.periodic_exemplar, opt.exemplar_stride)
                                              : Patches{};
  const Patches& queries = opt.exemplar_stride > 1 ? exq : ex;
  if (opt.brute_force) {
    std::vector<double> none;
    r.coherence = mean_nearest(out, ex, nullptr, none, none, 0);
    r.completeness = mean_nearest(queries, out, nullptr, none, none, 0);
  } else {
    const Pca pca = fit_pca(ex, out, std::min(opt.pca_dims, ex.dim));
    const std::vector<double> pout = project(out, pca), pex = project(ex, pca);
    r.coherence = mean_nearest(out, ex, &pca, pout, pex, opt.max_candidates);
    const std::vector<double> pq = opt.exemplar_stride > 1 ? project(queries, pca) : std::vector<double>();
    r.completeness = mean_nearest(queries, out, &pca, opt.exemplar_stride > 1 ? pq : pex, pout, opt.max_candidates);
  }
  r.total = r.coherence + r.completeness;
  return r;
}

}  // namespace surftex
