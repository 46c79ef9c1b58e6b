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

namespace {

// Random graph with integer capacities (exact sums, so labels compare bit for
// bit) and some nodes forced: +1 infinite source link, -1 infinite sink link.
RandomGraph random_integer_graph(std::mt19937_64& rng, int n, bool sink_links) {
  RandomGraph g = random_graph(rng, n);
  for (auto& e : g.edges) e.cuv = std::floor(e.cuv), e.cvu = std::floor(e.cvu);
  for (int u = 0; u < n; ++u) {
    g.cs[u] = std::floor(g.cs[u]);
    g.ct[u] = sink_links ? std::floor(g.ct[u]) : 0.0;
  }
  return g;
}

// The minimum over cuts that respect `forced`, and the intersection of the
// source sides of all minimum cuts (the unique smallest one: the nodes the
// source reaches in the residual graph of a maximum flow).
std::pair<double, unsigned> smallest_min_cut(const RandomGraph& g, const std::vector<int>& forced) {
  double best = std::numeric_limits<double>::infinity();
  unsigned side = 0;
  for (unsigned mask = 0; mask < (1u << g.n); ++mask) {
    bool ok = true;
    for (int u = 0; u < g.n; ++u)
      if ((forced[u] > 0 && !((mask >> u) & 1u)) || (forced[u] < 0 && ((mask >> u) & 1u))) ok = false;
    if (!ok) continue;
    const double c = cut_capacity(g, mask);
    if (c < best) {
      best = c;
      side = mask;
    } else if (c == best) {
      side &= mask;
    }
  }
  return {best, side};
}

}  // namespace

// solve() folds nodes with one infinite terminal link into that terminal.
// The labels and flow are those of the unfolded graph: the brute-force
// smallest minimum cut, and a graph folded by hand with no forced node.
TEST(GraphCut, FoldedForcedNodesGiveTheUnfoldedLabelsAndFlow) {
  std::mt19937_64 rng(2024);
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + trial % 11;
    const bool sink_links = trial % 4 != 3;  // every 4th: no sink link (the BFS shortcut)
    RandomGraph g = random_integer_graph(rng, n, sink_links);
    std::vector<int> forced(n, 0);
    for (int u = 0; u < n; ++u) {
      const auto r = rng() % 6;
      forced[u] = r == 0 ? 1 : (r == 1 && sink_links ? -1 : 0);
    }
    GraphCut gc(n);
    for (const auto& e : g.edges) gc.add_edge(e.u, e.v, e.cuv, e.cvu);
    for (int u = 0; u < n; ++u) {
      gc.add_terminal(u, g.cs[u], g.ct[u]);
      if (forced[u] > 0) gc.add_terminal(u, GraphCut::kInfinity, 0);
      if (forced[u] < 0) gc.add_terminal(u, 0, std::numeric_limits<double>::infinity());
    }
    const double flow = gc.solve();
    const auto [best, side] = smallest_min_cut(g, forced);
    ASSERT_EQ(flow, best) << "trial " << trial;
    for (int u = 0; u < n; ++u) {
      ASSERT_EQ(gc.is_source_side(u), ((side >> u) & 1u) != 0) << "trial " << trial << " u " << u;
    }

    // The same graph folded by hand: free nodes only.
    std::vector<int> id(n, -1);
    int nf = 0;
    for (int u = 0; u < n; ++u)
      if (forced[u] == 0) id[u] = nf++;
    GraphCut folded(nf);
    double constant = 0;
    for (int u = 0; u < n; ++u) {
      if (forced[u] == 0) folded.add_terminal(id[u], g.cs[u], g.ct[u]);
      if (forced[u] > 0) constant += g.ct[u];  // a forced node's finite link is always cut
      if (forced[u] < 0) constant += g.cs[u];
    }
    for (const auto& e : g.edges) {
      const int fu = forced[e.u], fv = forced[e.v];
      if (fu == 0 && fv == 0) folded.add_edge(id[e.u], id[e.v], e.cuv, e.cvu);
      else if (fu == 0) folded.add_terminal(id[e.u], fv > 0 ? e.cvu : 0.0, fv < 0 ? e.cuv : 0.0);
      else if (fv == 0) folded.add_terminal(id[e.v], fu > 0 ? e.cuv : 0.0, fu < 0 ? e.cvu : 0.0);
      else if (fu > 0 && fv < 0) constant += e.cuv;
      else if (fu < 0 && fv > 0) constant += e.cvu;
    }
    ASSERT_EQ(folded.solve() + constant, flow) << "trial " << trial;
    for (int u = 0; u < n; ++u) {
      if (forced[u] == 0) {
        ASSERT_EQ(folded.is_source_side(id[u]), gc.is_source_side(u)) << "trial " << trial;
      }
    }
  }
}

// reset() gives an empty graph again: a reused GraphCut solves like a new one.
TEST(GraphCut, ResetSolvesLikeANewGraph) {
  std::mt19937_64 rng(99);
  GraphCut reused(0);
  for (int trial = 0; trial < 50; ++trial) {
    const int n = 1 + trial % 9;
    const RandomGraph g = random_graph(rng, n);
    GraphCut fresh(n);
    reused.reset(n);
    EXPECT_EQ(reused.num_nodes(), n);
    for (GraphCut* gc : {&fresh, &reused}) {
      for (const auto& e : g.edges) gc->add_edge(e.u, e.v, e.cuv, e.cvu);
      for (int u = 0; u < n; ++u) gc->add_terminal(u, g.cs[u], g.ct[u]);
      gc->add_terminal(0, GraphCut::kInfinity, 0);
    }
    ASSERT_EQ(fresh.solve(), reused.solve()) << "trial " << trial;
    for (int u = 0; u < n; ++u) ASSERT_EQ(fresh.is_source_side(u), reused.is_source_side(u)) << "trial " << trial;
  }
  EXPECT_THROW(reused.reset(-1), InvalidInputError);
  reused.reset(3);
  EXPECT_THROW(reused.is_source_side(0), InvalidInputError);  // nothing solved after a reset
}
