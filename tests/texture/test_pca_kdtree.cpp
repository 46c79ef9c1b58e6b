// SPDX-License-Identifier: AGPL-3.0-or-later
// The shared PCA + kd-tree (texture/pca_kdtree.h) and the partial-query
// index built on it (texture/partial_neighbourhood_index.h): exact k-nearest
// against brute force, the visitor's pruning, the PCA of a known covariance,
// and the recall of half-known neighbourhoods of a real texture.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "test_support.h"
#include "texture/partial_neighbourhood_index.h"
#include "texture/pca_kdtree.h"

using namespace surftex;

TEST(PcaKdTree, KnnWithoutApproximationIsTheBruteForceNearest) {
  std::mt19937_64 rng(3);
  std::normal_distribution<float> g(0.f, 1.f);
  const int dims = 5, n = 3000;
  std::vector<float> pts(n * dims);
  for (float& v : pts) v = g(rng);
  const KdIndex<float> tree(pts, dims);
  ASSERT_EQ(tree.size(), std::size_t(n));
  // The index stores the points in its own order; point(i) is still the i-th given.
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < dims; ++k) ASSERT_EQ(tree.point(i)[k], pts[i * dims + k]) << "point " << i;
  for (int t = 0; t < 50; ++t) {
    float q[dims];
    for (float& v : q) v = g(rng);
    std::vector<std::pair<float, std::uint32_t>> all;
    for (int i = 0; i < n; ++i) {
      float d = 0;
      for (int k = 0; k < dims; ++k) d += (pts[i * dims + k] - q[k]) * (pts[i * dims + k] - q[k]);
      all.push_back({d, std::uint32_t(i)});
    }
    std::sort(all.begin(), all.end());
    std::uint32_t idx[8];
    float d2[8];
    ASSERT_EQ(tree.knn(q, 8, 0.f, idx, d2), 8u);
    for (int k = 0; k < 8; ++k) {
      EXPECT_EQ(idx[k], all[k].second) << "query " << t << " rank " << k;
      EXPECT_NEAR(d2[k], all[k].first, 1e-4f);
    }
  }
}

TEST(PcaKdTree, VisitorSeesEveryPointWithinItsBound) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int dims = 3, n = 2000;
  std::vector<double> pts(n * dims);
  for (double& v : pts) v = u(rng);
  const KdIndex<double> tree(pts, dims);
  struct Within : KdIndex<double>::Visitor {
    double r2;
    std::vector<std::uint32_t> seen;
    double bound() const override { return r2; }
    bool add(double, std::uint32_t i) override {
      seen.push_back(i);
      return true;
    }
  } v;
  v.r2 = 0.01;
  const double q[3] = {0.5, 0.4, 0.6};
  tree.search(q, v);
  std::vector<std::uint32_t> expect;
  for (int i = 0; i < n; ++i) {
    double d = 0;
    for (int k = 0; k < dims; ++k) d += (pts[i * dims + k] - q[k]) * (pts[i * dims + k] - q[k]);
    if (d < v.r2) expect.push_back(std::uint32_t(i));
  }
  std::sort(v.seen.begin(), v.seen.end());
  EXPECT_GT(expect.size(), 10u);
  EXPECT_EQ(v.seen, expect);
}

TEST(PcaKdTree, PcaFindsTheDirectionsOfAKnownCovariance) {
  // Samples along (1, 1, 0) with variance 4, (1, -1, 0) with variance 1, z with 0.01.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  PcaFit fit(3);
  for (int i = 0; i < 20000; ++i) {
    const double a = 2 * g(rng), b = g(rng), c = 0.1 * g(rng);
    const float v[3] = {float(1 + (a + b) / std::sqrt(2.0)), float(-2 + (a - b) / std::sqrt(2.0)), float(c)};
    fit.add(v);
  }
  const PcaBasis p = fit.fit(2, "test");
  EXPECT_NEAR(p.mean[0], 1.0, 0.05);
  EXPECT_NEAR(p.mean[1], -2.0, 0.05);
  EXPECT_NEAR(p.eigenvalues[0], 4.0, 0.15);
  EXPECT_NEAR(p.eigenvalues[1], 1.0, 0.05);
  EXPECT_NEAR(p.eigenvalues[2], 0.01, 0.002);
  EXPECT_NEAR(p.basis_d[0], 1 / std::sqrt(2.0), 0.02);  // sign: largest entry positive
  EXPECT_NEAR(p.basis_d[1], 1 / std::sqrt(2.0), 0.02);
  EXPECT_NEAR(std::abs(p.basis_d[3]), 1 / std::sqrt(2.0), 0.02);
  EXPECT_NEAR(p.basis_d[3] * p.basis_d[4], -0.5, 0.02);
  const float x[3] = {1.f, -2.f, 0.f};
  float c[2];
  p.project(x, c);  // the mean projects to ~0
  EXPECT_NEAR(c[0], 0.0, 0.05);
  EXPECT_NEAR(c[1], 0.0, 0.05);
  PcaFit empty(3);
  EXPECT_THROW(empty.fit(1, "test"), InvalidInputError);
  EXPECT_THROW(fit.fit(4, "test"), InvalidInputError);
}

// The projections are computed four directions at a time (SSE lanes for
// float), yet each coefficient must be the same number as one sum in index
// order: a product rounded, then a sum rounded. Checked bit for bit against
// that sum for 4, 6 and 9 directions of 243-long vectors (a 9x9 RGB window).
TEST(PcaKdTree, ProjectionsAreTheSumsInIndexOrderBitForBit) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  const int dim = 243;
  PcaFit fit(dim);
  std::vector<float> v(dim);
  for (int n = 0; n < 400; ++n) {
    for (float& x : v) x = u(rng);
    fit.add(v.data());
  }
  for (int dims : {4, 6, 9}) {
    const PcaBasis p = fit.fit(dims, "test");
    for (int n = 0; n < 50; ++n) {
      for (float& x : v) x = u(rng);
      std::vector<float> cf(dims);
      std::vector<double> cd(dims);
      p.project(v.data(), cf.data());
      p.project(v.data(), cd.data());
      for (int k = 0; k < dims; ++k) {
        volatile float sf = 0;  // volatile: no reassociation or contraction
        volatile double sd = 0;
        for (int i = 0; i < dim; ++i) {
          const float df = v[i] - p.mean[i];
          const float pf = p.basis[static_cast<std::size_t>(k) * dim + i] * df;
          sf = sf + pf;
          const double dd = static_cast<double>(v[i]) - p.mean_d[i];
          const double pd = p.basis_d[static_cast<std::size_t>(k) * dim + i] * dd;
          sd = sd + pd;
        }
        EXPECT_EQ(cf[k], sf) << "dims " << dims << " k " << k;
        EXPECT_EQ(cd[k], sd) << "dims " << dims << " k " << k;
      }
    }
  }
}

TEST(PartialNeighbourhoodIndex, HalfKnownQueriesReturnTopRankedCandidates) {
  // Queries are exemplar neighbourhoods of which only the upper half (rows
  // above the centre and the left part of the centre row, the known side of
  // a scanline fill) is given. Ranked by the SSD over the known entries
  // among all candidate positions, the best of the 16 returned candidates
  // must be in the top 1% for most queries (16 random candidates would reach
  // that for about 15% of the queries).
  const Image src = read_image(test::shared_data("textures/pebbles_256.png"));
  const int side = 160;
  const int C = src.channels, pw = side, f = 5, lo = -2;
  const std::size_t ps = std::size_t(side) * side;
  std::vector<float> planes(ps * C + 64, 0.f);
  for (int y = 0; y < side; ++y)
    for (int x = 0; x < side; ++x)
      for (int c = 0; c < C; ++c) planes[c * ps + std::size_t(y) * side + x] = src.at(x, y, c);
  std::vector<int> ids;
  for (int y = 2; y < side - 2; ++y)
    for (int x = 2; x < side - 2; ++x) ids.push_back(y * pw + x);
  // stride 2 (the Efros-Leung default): a quarter of the positions in the
  // tree, each hit standing for its 2x2 block of candidates.
  for (int stride : {1, 2}) {
    SCOPED_TRACE("stride " + std::to_string(stride));
    std::vector<char> is_id(ps, 0);
    for (int c : ids) is_id[c] = 1;
    const PartialNeighbourhoodIndex index(planes.data(), ps, pw, C, ids, f, 4, stride);
    EXPECT_EQ(index.pca_dims(), 4);
    PartialNeighbourhoodIndex::Scratch scratch;
    std::mt19937_64 rng(6);
    const int trials = 100;
    int good = 0;
    std::vector<int> slot, offset;
    std::vector<float> val;
    for (int t = 0; t < trials; ++t) {
      const int id = ids[rng() % ids.size()];
      slot.clear();
      offset.clear();
      val.clear();
      for (int dy = lo; dy <= 2; ++dy)
        for (int dx = lo; dx <= 2; ++dx) {
          if (dy > 0 || (dy == 0 && dx >= 0)) continue;
          slot.push_back((dy - lo) * f + (dx - lo));
          offset.push_back(dy * pw + dx);
          for (int c = 0; c < C; ++c) val.push_back(planes[c * ps + id + dy * pw + dx]);
        }
      auto known_ssd = [&](int cand) {
        double e = 0;
        for (std::size_t k = 0; k < offset.size(); ++k)
          for (int c = 0; c < C; ++c) {
            const double d = planes[c * ps + cand + offset[k]] - val[k * C + c];
            e += d * d;
          }
        return e;
      };
      std::vector<int> out;
      index.query(slot.data(), val.data(), static_cast<int>(slot.size()), 16, 0.f, out, scratch);
      ASSERT_FALSE(out.empty());
      EXPECT_LE(out.size(), 16u * stride * stride);
      for (int c : out) ASSERT_TRUE(c >= 0 && std::size_t(c) < ps && is_id[c]) << c;
      double best = 1e300;
      for (int c : out) best = std::min(best, known_ssd(c));
      std::size_t better = 0;
      for (int c : ids) better += known_ssd(c) < best;
      good += better < ids.size() / 100;
    }
    EXPECT_GT(good, trials * 7 / 10) << good << " of " << trials;
  }
  EXPECT_THROW(PartialNeighbourhoodIndex(planes.data(), ps, pw, C, ids, f, 4, 0), InvalidInputError);
  {  // no candidate on the stride grid (odd x and y): all of them are indexed
    const std::vector<int> odd = {3 * pw + 3, 3 * pw + 5, 5 * pw + 3};
    const PartialNeighbourhoodIndex small(planes.data(), ps, pw, C, odd, f, 2, 2);
    PartialNeighbourhoodIndex::Scratch sc;
    const int slot0[1] = {0};
    std::vector<float> v(C, 0.5f);
    std::vector<int> got;
    EXPECT_EQ(small.query(slot0, v.data(), 1, 3, 0.f, got, sc), 3u);
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, odd);
  }
  EXPECT_THROW(PartialNeighbourhoodIndex(planes.data(), ps, pw, C, {}, f, 4), InvalidInputError);
}
