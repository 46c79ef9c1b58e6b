// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The one s-t min-cut / max-flow wrapper of surftex (docs/DESIGN.md: "Boost.Graph for
// every max-flow / graph cut"). Every graph cut in the project (graph-cut
// textures, tileable tiles, mesh quilting, subdivision graph matching) goes
// through this class; it runs Boost.Graph's boykov_kolmogorov_max_flow
// (Boykov & Kolmogorov 2004). Boost headers stay in graph_cut.cpp.
//
// Usage: build the graph with add_edge / add_terminal, call solve() once, then
// read the partition with is_source_side(). Nodes are 0..num_nodes-1; the
// source and sink terminals are implicit.
//
// Capacities are non-negative doubles; kInfinity (or +inf) is never cut while
// a finite cut exists, and finite sums should stay far below it. solve()
// folds nodes with one infinite terminal link into that terminal before BK
// (same flow and partition; proof in graph_cut.cpp).

#include <cstddef>
#include <vector>

namespace surftex {

class GraphCut {
 public:
  /// The value used for "infinite" capacities (a finite double so that
  /// residual arithmetic never produces inf - inf).
  static constexpr double kInfinity = 1e18;

  /// A graph with `num_nodes` non-terminal nodes. Throws InvalidInputError if
  /// num_nodes < 0.
  explicit GraphCut(int num_nodes);

  int num_nodes() const { return n_; }

  /// Starts over with an empty graph of `num_nodes` nodes, keeping the
  /// storage (for callers that solve many small cuts). Throws like the
  /// constructor.
  void reset(int num_nodes);

  /// Reserves room for `edges` add_edge calls (optional; saves reallocations).
  void reserve_edges(std::size_t edges) { edges_.reserve(edges); }

  /// Adds the edge pair u->v (capacity cap_uv) and v->u (capacity cap_vu).
  /// Parallel edges add up. Throws InvalidInputError for a node out of range,
  /// u == v, or a negative / NaN capacity.
  void add_edge(int u, int v, double cap_uv, double cap_vu);

  /// Adds terminal links source->u (cap_source, paid when u ends on the sink
  /// side) and u->sink (cap_sink, paid when u ends on the source side).
  /// Repeated calls for the same node add up. Throws like add_edge.
  void add_terminal(int u, double cap_source, double cap_sink);

  /// Runs max-flow and returns its value (= the min-cut capacity). Returns
  /// +infinity if every cut contains an infinite edge. Can be called once;
  /// a second call throws InvalidInputError.
  double solve();

  /// After solve(): true if u is on the source side of the minimum cut (the
  /// nodes reachable from the source in the residual graph, i.e. the source
  /// side of the smallest minimum cut); false otherwise. When solve()
  /// returned infinity only the forced nodes' sides are meaningful.
  /// Throws InvalidInputError before solve() or for u out of range.
  bool is_source_side(int u) const;

 private:
  struct Edge {
    int u, v;
    double cap_uv, cap_vu;
  };
  void check_node(int u, const char* what) const {
    if (u < 0 || u >= n_) throw_node_out_of_range(u, what);
  }
  [[noreturn]] void throw_node_out_of_range(int u, const char* what) const;
  static double clamp_capacity(double c, const char* what);

  int n_;
  std::vector<Edge> edges_;
  std::vector<double> src_cap_, sink_cap_;
  std::vector<char> source_side_;
  bool solved_ = false;
};

}  // namespace surftex
