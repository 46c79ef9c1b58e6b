// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/bidirectional_similarity.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "texture/pca_kdtree.h"

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

// PCA (dims directions) fitted on a sample of the patches of both images.
PcaBasis fit_patch_pca(const Patches& a, const Patches& b, int d) {
  PcaFit fit(a.dim);
  auto add = [&](const Patches& p) {
    const std::size_t step = std::max<std::size_t>(1, p.count / 8000);
    for (std::size_t i = 0; i < p.count; i += step) fit.add(p.row(i));
  };
  add(a);
  add(b);
  return fit.fit(d, "bidirectional_similarity");
}

std::vector<double> project(const Patches& p, const PcaBasis& pca) {
  const int d = pca.dims;
  std::vector<double> out(p.count * d);
  tbb::parallel_for(std::size_t(0), p.count, [&](std::size_t i) { pca.project(p.row(i), out.data() + i * d); });
  return out;
}

// nanoflann result set doing a branch-and-bound nearest-neighbour search in
// the full patch space: the tree's squared distance in the PCA subspace is a
// lower bound of the full SSD (orthonormal projection), so every point whose
// bound reaches the best full SSD found so far is pruned, and each point the
// tree offers is re-ranked with the full SSD. The result is the exact minimum
// (the visiting order only changes the speed). With max_candidates > 0 the
// search stops after that many full evaluations (approximate, an upper
// bound); so does a search with eps > 0, which skips the tree nodes whose
// bound is within a factor 1 + eps of the best (nanoflann's eps).
// `visits` counts the looks at the bound: one per tree node or offered point.
struct NearestByBound : KdIndex<double>::Visitor {
  const float* query;
  const Patches* base;
  std::size_t max_candidates;
  double best = std::numeric_limits<double>::infinity();
  std::size_t evaluated = 0;
  mutable std::size_t visits = 0;
  NearestByBound(const float* q, const Patches* b, std::size_t m) : query(q), base(b), max_candidates(m) {}
  // Slack for the rounding of the projection (the bound is exact in exact
  // arithmetic).
  double bound() const override {
    ++visits;
    return best * (1.0 + 1e-9);
  }
  bool add(double, std::uint32_t index) override {
    best = std::min(best, ssd_bounded(query, base->row(index), base->dim, best));
    ++evaluated;
    return max_candidates == 0 || evaluated < max_candidates;
  }
};

struct SearchCost {
  std::size_t evaluations = 0, visits = 0;
};

// Mean over `queries` of the distance to the nearest patch of `base`; adds the
// search's work to `cost`. `subset`: the query indices to average over (empty = all).
double mean_nearest(const Patches& queries, const Patches& base, const PcaBasis* pca,
                    const std::vector<double>& qproj, const std::vector<double>& bproj,
                    std::size_t max_candidates, float eps, SearchCost& cost,
                    const std::vector<std::size_t>& subset = {}) {
  std::vector<std::size_t> all;
  if (subset.empty()) {
    all.resize(queries.count);
    for (std::size_t i = 0; i < queries.count; ++i) all[i] = i;
  }
  const std::vector<std::size_t>& qs = subset.empty() ? all : subset;
  std::vector<double> best(qs.size());
  std::vector<std::size_t> evaluated(qs.size(), base.count), visits(qs.size(), 0);
  if (!pca) {
    tbb::parallel_for(std::size_t(0), qs.size(), [&](std::size_t k) {
      const std::size_t i = qs[k];
      double b = std::numeric_limits<double>::infinity();
      for (std::size_t j = 0; j < base.count; ++j) b = std::min(b, ssd(queries.row(i), base.row(j), base.dim));
      best[k] = b;
    });
  } else {
    const int d = pca->dims;
    const KdIndex<double> tree(bproj, d);
    tbb::parallel_for(std::size_t(0), qs.size(), [&](std::size_t k) {
      const std::size_t i = qs[k];
      NearestByBound r(queries.row(i), &base, max_candidates);
      tree.search(qproj.data() + i * d, r, eps);
      best[k] = r.best;
      evaluated[k] = r.evaluated;
      visits[k] = r.visits;
    });
  }
  for (std::size_t k = 0; k < qs.size(); ++k) {
    cost.evaluations += evaluated[k];
    cost.visits += visits[k];
  }
  double sum = 0;
  for (double v : best) sum += v;
  return sum / static_cast<double>(qs.size()) / base.dim;
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
  if (!(opt.search_eps >= 0.f)) bad("search_eps " + std::to_string(opt.search_eps) + " < 0");
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
  SearchCost cost;
  if (opt.brute_force) {
    std::vector<double> none;
    r.coherence = mean_nearest(out, ex, nullptr, none, none, 0, 0.f, cost);
    r.completeness = mean_nearest(queries, out, nullptr, none, none, 0, 0.f, cost);
  } else {
    const PcaBasis pca = fit_patch_pca(ex, out, std::min(opt.pca_dims, ex.dim));
    const std::vector<double> pout = project(out, pca), pex = project(ex, pca);
    r.coherence = mean_nearest(out, ex, &pca, pout, pex, opt.max_candidates, opt.search_eps, cost);
    const std::vector<double> pq = opt.exemplar_stride > 1 ? project(queries, pca) : std::vector<double>();
    r.completeness = mean_nearest(queries, out, &pca, opt.exemplar_stride > 1 ? pq : pex, pout, opt.max_candidates,
                                  opt.search_eps, cost);
  }
  r.evaluations = cost.evaluations;
  r.visits = cost.visits;
  r.total = r.coherence + r.completeness;
  return r;
}

}  // namespace surftex
