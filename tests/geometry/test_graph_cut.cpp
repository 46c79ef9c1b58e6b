// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "geometry/errors.h"
#include "geometry/graph_cut.h"

using namespace surftex;

namespace {

struct RandomGraph {
  int n = 0;
  struct E { int u, v; double cuv, cvu; };
  std::vector<E> edges;
  std::vector<double> cs, ct;
};

RandomGraph random_graph(std::mt19937_64& rng, int n) {
  RandomGraph g;
  g.n = n;
  std::uniform_real_distribution<double> cap(0.0, 10.0);
  std::uniform_int_distribution<int> node(0, n - 1);
  std::bernoulli_distribution coin(0.5);
  int m = n * 2 + static_cast<int>(rng() % static_cast<unsigned>(n * 2 + 1));
  for (int i = 0; i < m; ++i) {
    int u = node(rng), v = node(rng);
    if (u == v) continue;
    // Some one-way edges, some integer capacities (ties), some zeros.
    double a = coin(rng) ? std::floor(cap(rng)) : cap(rng);
    double b = coin(rng) ? 0.0 : cap(rng);
    g.edges.push_back({u, v, a, b});
  }
  g.cs.resize(n);
  g.ct.resize(n);
  for (int u = 0; u < n; ++u) {
    g.cs[u] = coin(rng) ? cap(rng) : 0.0;
    g.ct[u] = coin(rng) ? cap(rng) : 0.0;
  }
  return g;
}

// Capacity of the cut where bit u of `mask` set = node u on the source side.
double cut_capacity(const RandomGraph& g, unsigned mask) {
  auto src = [&](int u) { return ((mask >> u) & 1u) != 0; };
  double c = 0.0;
  for (int u = 0; u < g.n; ++u) c += src(u) ? g.ct[u] : g.cs[u];
  for (const auto& e : g.edges) {
    if (src(e.u) && !src(e.v)) c += e.cuv;
    if (src(e.v) && !src(e.u)) c += e.cvu;
  }
  return c;
}

}  // namespace

TEST(GraphCut, MaxFlowEqualsBruteForceMinCutOnRandomGraphs) {
  std::mt19937_64 rng(12345);
  for (int trial = 0; trial < 300; ++trial) {
    int n = 1 + static_cast<int>(trial % 12);
    RandomGraph g = random_graph(rng, n);
    GraphCut gc(n);
    for (const auto& e : g.edges) gc.add_edge(e.u, e.v, e.cuv, e.cvu);
    for (int u = 0; u < n; ++u) gc.add_terminal(u, g.cs[u], g.ct[u]);
    double flow = gc.solve();
    double best = std::numeric_limits<double>::infinity();
    for (unsigned mask = 0; mask < (1u << n); ++mask) best = std::min(best, cut_capacity(g, mask));
    ASSERT_NEAR(flow, best, 1e-9 * (1.0 + best)) << "trial " << trial << " n " << n;
    // The partition the wrapper reports is a minimum cut.
    unsigned side = 0;
    for (int u = 0; u < n; ++u)
      if (gc.is_source_side(u)) side |= 1u << u;
    ASSERT_NEAR(cut_capacity(g, side), best, 1e-9 * (1.0 + best)) << "trial " << trial;
  }
}

TEST(GraphCut, TextbookNetworkHasFlow23) {
  // CLRS figure 26.1: s=0, v1..v4, t=5; max flow 23.
  // Nodes here: v1=0, v2=1, v3=2, v4=3.
  GraphCut gc(4);
  gc.add_terminal(0, 16, 0);  // s->v1
  gc.add_terminal(1, 13, 0);  // s->v2
  gc.add_edge(0, 2, 12, 0);   // v1->v3
  gc.add_edge(1, 0, 4, 0);    // v2->v1
  gc.add_edge(2, 1, 9, 0);    // v3->v2
  gc.add_edge(1, 3, 14, 0);   // v2->v4
  gc.add_edge(3, 2, 7, 0);    // v4->v3
  gc.add_terminal(2, 0, 20);  // v3->t
  gc.add_terminal(3, 0, 4);   // v4->t
  EXPECT_DOUBLE_EQ(gc.solve(), 23.0);
  // Min cut {s, v1, v2, v4} | {v3, t}: 12 + 7 + 4 = 23.
  EXPECT_TRUE(gc.is_source_side(0));
  EXPECT_TRUE(gc.is_source_side(1));
  EXPECT_FALSE(gc.is_source_side(2));
  EXPECT_TRUE(gc.is_source_side(3));
}

TEST(GraphCut, InfiniteLinksAreNeverCut) {
  std::mt19937_64 rng(7);
  const double inf = std::numeric_limits<double>::infinity();
  for (int trial = 0; trial < 100; ++trial) {
    int n = 2 + static_cast<int>(trial % 9);
    RandomGraph g = random_graph(rng, n);
    // Pin node 0 to the source and node n-1 to the sink with infinite links,
    // and make a random chain infinite in both directions.
    GraphCut gc(n);
    for (const auto& e : g.edges) gc.add_edge(e.u, e.v, e.cuv, e.cvu);
    for (int u = 0; u < n; ++u) gc.add_terminal(u, g.cs[u], g.ct[u]);
    gc.add_terminal(0, inf, 0);
    gc.add_terminal(n - 1, 0, GraphCut::kInfinity);
    int a = static_cast<int>(rng() % static_cast<unsigned>(n)), b = (a + 1) % n;
    bool chain = (a != n - 1 && b != 0) && !(a == 0 && b == n - 1);
    if (chain) gc.add_edge(a, b, inf, inf);
    double flow = gc.solve();
    ASSERT_TRUE(std::isfinite(flow));
    EXPECT_TRUE(gc.is_source_side(0));
    EXPECT_FALSE(gc.is_source_side(n - 1));
    if (chain) {
      EXPECT_EQ(gc.is_source_side(a), gc.is_source_side(b));
    }
    // The flow is the cheapest cut among those that respect the constraints.
    double best = std::numeric_limits<double>::infinity();
    for (unsigned mask = 0; mask < (1u << n); ++mask) {
      bool s0 = mask & 1u, sn = (mask >> (n - 1)) & 1u;
      if (!s0 || sn) continue;
      if (chain && (((mask >> a) & 1u) != ((mask >> b) & 1u))) continue;
      best = std::min(best, cut_capacity(g, mask));
    }
    ASSERT_NEAR(flow, best, 1e-6 * (1.0 + best)) << "trial " << trial;
  }
}

TEST(GraphCut, AllCutsInfiniteReportsInfinity) {
  GraphCut gc(2);
  gc.add_terminal(0, GraphCut::kInfinity, 0);
  gc.add_terminal(1, 0, GraphCut::kInfinity);
  gc.add_edge(0, 1, GraphCut::kInfinity, 0);
  EXPECT_TRUE(std::isinf(gc.solve()));
}

TEST(GraphCut, InvalidArgumentsThrow) {
  EXPECT_THROW(GraphCut(-1), InvalidInputError);
  GraphCut gc(3);
  EXPECT_THROW(gc.add_edge(0, 3, 1, 1), InvalidInputError);
  EXPECT_THROW(gc.add_edge(1, 1, 1, 1), InvalidInputError);
  EXPECT_THROW(gc.add_edge(0, 1, -1, 1), InvalidInputError);
  EXPECT_THROW(gc.add_terminal(0, std::nan(""), 1), InvalidInputError);
  EXPECT_THROW(gc.is_source_side(0), InvalidInputError);
  gc.solve();
  EXPECT_THROW(gc.solve(), InvalidInputError);
}
