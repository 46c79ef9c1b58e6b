// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/graph_cut.h"

// GCC 12 reports a false -Wmaybe-uninitialized inside Boost.Graph's edge
// iterator (boost::optional storage) when boykov_kolmogorov_max_flow is
// instantiated; silenced for this translation unit only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/graph/compressed_sparse_row_graph.hpp>
#include <boost/property_map/property_map.hpp>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>
#include <limits>
#include <string>

#include "geometry/errors.h"

namespace surftex {
namespace {

// A compact graph for boykov_kolmogorov_max_flow: compressed sparse rows
// (two arrays, no per-edge or per-vertex allocation; the adjacency_list it
// replaces allocated every edge's properties on the heap, which dominated
// small cuts such as the per-vertex ones of subdivision synthesis). Edge
// properties live in plain vectors indexed by the CSR edge index. Every
// node's out-edges keep the order they were added in (a stable counting sort
// by source), so the algorithm visits edges in the same order as before and
// the cut is the same, bit for bit.
using Csr = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                               boost::no_property, std::uint32_t, std::uint32_t>;
using CsrEdge = boost::graph_traits<Csr>::edge_descriptor;

/// Per-thread buffers of GraphCut::solve: many small cuts (one per vertex in
/// subdivision synthesis) reuse their storage instead of allocating it every time.
struct Scratch {
  std::vector<signed char> forced;    ///< +1 forced to the source, -1 to the sink, 0 free
  std::vector<std::uint32_t> index;   ///< compact index of a free node
  std::vector<double> term_s, term_t; ///< folded terminal capacities of the free nodes
  std::vector<std::uint32_t> start, next, queue;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sorted;
  std::vector<double> capacity, residual;
  std::vector<CsrEdge> reverse, predecessor;
  std::vector<boost::default_color_type> color;
  std::vector<long> distance;
};

/// The folded graph of one solve: its sizes and constant (the arrays in `scr`).
struct FoldedGraph {
  explicit FoldedGraph(Scratch& s) : scr(s) {}
  Scratch& scr;
  std::size_t n = 0;       ///< nodes of the GraphCut
  std::uint32_t nf = 0;    ///< free nodes (compact indices 0..nf-1)
  std::size_t nn = 0;      ///< free nodes and the two terminals
  std::uint32_t s = 0, t = 0;  ///< the terminals' indices
  std::size_t na = 0;      ///< arcs
  double constant = 0.0;   ///< paid by every cut
  bool any_source = false, any_sink = false;  ///< some free node keeps a source (sink) link
};

void add_capped(double& c, double x) { c = std::min(GraphCut::kInfinity, c + x); }

/// Step 1a: forced nodes (an infinite link to one terminal only) marked and
/// their finite other link paid by every finite cut; the free nodes numbered
/// compactly with their terminal capacities. Why this keeps the cut: solve().
void fold_forced_nodes(const std::vector<double>& src_cap, const std::vector<double>& sink_cap, FoldedGraph& g) {
  constexpr double kInfinity = GraphCut::kInfinity;
  Scratch& scr = g.scr;
  const std::size_t n = g.n;
  auto& forced = scr.forced;
  auto& index = scr.index;
  forced.assign(n, 0);
  index.assign(n, 0);
  for (std::size_t u = 0; u < n; ++u) {
    const bool s_inf = src_cap[u] >= kInfinity, t_inf = sink_cap[u] >= kInfinity;
    if (s_inf && t_inf) g.constant = kInfinity;  // infinite both ways: every cut is infinite
    if (s_inf && !t_inf) {  // its finite sink link is paid by every finite cut
      forced[u] = 1;
      g.constant += sink_cap[u];
    } else if (t_inf && !s_inf) {
      forced[u] = -1;
      g.constant += src_cap[u];
    } else {
      index[u] = g.nf++;
    }
  }
  scr.term_s.resize(g.nf);
  scr.term_t.resize(g.nf);
  for (std::size_t u = 0; u < n; ++u)
    if (forced[u] == 0) {
      scr.term_s[index[u]] = src_cap[u];
      scr.term_t[index[u]] = sink_cap[u];
    }
  g.nn = std::size_t(g.nf) + 2;
  g.s = g.nf;
  g.t = g.nf + 1;
  scr.start.assign(g.nn + 1, 0);  // start[u + 1] counts u's out-arcs first
}

/// Step 1b: the edges folded: one between two free nodes is counted as two
/// arcs; one to a forced node becomes a terminal link of the free end; one
/// between a source-forced and a sink-forced node is a constant. (Templated
/// on the edge list: GraphCut::Edge is private.)
template <class Edges>
void fold_forced_edges(const Edges& edges, FoldedGraph& g) {
  Scratch& scr = g.scr;
  auto& term_s = scr.term_s;
  auto& term_t = scr.term_t;
  for (const auto& e : edges) {
    if (e.cap_uv <= 0.0 && e.cap_vu <= 0.0) continue;
    const int fu = scr.forced[static_cast<std::size_t>(e.u)], fv = scr.forced[static_cast<std::size_t>(e.v)];
    const std::uint32_t iu = scr.index[static_cast<std::size_t>(e.u)], iv = scr.index[static_cast<std::size_t>(e.v)];
    if (fu == 0 && fv == 0) {
      ++scr.start[iu + 1];
      ++scr.start[iv + 1];
    } else if (fu == 0) {  // v forced
      if (fv > 0) add_capped(term_s[iu], e.cap_vu);
      else add_capped(term_t[iu], e.cap_uv);
    } else if (fv == 0) {  // u forced
      if (fu > 0) add_capped(term_s[iv], e.cap_uv);
      else add_capped(term_t[iv], e.cap_vu);
    } else if (fu != fv) {
      add_capped(g.constant, fu > 0 ? e.cap_uv : e.cap_vu);
    }
  }
}

/// Step 1c: a node's two terminal links: only the part exceeding the smaller
/// one matters for the cut (min(cs, ct) is paid either way); the links left
/// are counted as arcs.
void reduce_terminal_links(FoldedGraph& g) {
  Scratch& scr = g.scr;
  auto& term_s = scr.term_s;
  auto& term_t = scr.term_t;
  for (std::uint32_t u = 0; u < g.nf; ++u) {
    const double m = std::min(term_s[u], term_t[u]);
    if (m >= GraphCut::kInfinity) {
      g.constant = GraphCut::kInfinity;
      term_s[u] = term_t[u] = 0.0;
      continue;
    }
    add_capped(g.constant, m);
    term_s[u] -= m;
    term_t[u] -= m;
    if (term_s[u] > 0.0) ++scr.start[g.s + 1], ++scr.start[u + 1], g.any_source = true;
    if (term_t[u] > 0.0) ++scr.start[u + 1], ++scr.start[g.t + 1], g.any_sink = true;
  }
}

/// Step 3: CSR arrays: arcs sorted by source (counting sort; every node's
/// arcs in the order they are added: terminal links by node, then the
/// edges), each with its capacity and reverse arc.
template <class Edges>
void build_arcs(const Edges& edges, FoldedGraph& g) {
  Scratch& scr = g.scr;
  auto& start = scr.start;
  for (std::size_t u = 0; u < g.nn; ++u) start[u + 1] += start[u];
  g.na = start[g.nn];
  auto& next = scr.next;
  next.assign(start.begin(), start.end() - 1);
  auto& sorted = scr.sorted;
  auto& capacity = scr.capacity;
  auto& reverse = scr.reverse;
  sorted.resize(g.na);
  capacity.resize(g.na);
  reverse.resize(g.na);
  auto add_pair = [&](std::uint32_t u, std::uint32_t v, double cuv, double cvu) {
    const std::uint32_t a = next[u]++, b = next[v]++;
    sorted[a] = {u, v};
    sorted[b] = {v, u};
    capacity[a] = cuv;
    capacity[b] = cvu;
    reverse[a] = CsrEdge(v, b);
    reverse[b] = CsrEdge(u, a);
  };
  for (std::uint32_t u = 0; u < g.nf; ++u) {
    if (scr.term_s[u] > 0.0) add_pair(g.s, u, scr.term_s[u], 0.0);
    if (scr.term_t[u] > 0.0) add_pair(u, g.t, scr.term_t[u], 0.0);
  }
  for (const auto& e : edges) {
    if (e.cap_uv <= 0.0 && e.cap_vu <= 0.0) continue;
    if (scr.forced[static_cast<std::size_t>(e.u)] != 0 || scr.forced[static_cast<std::size_t>(e.v)] != 0) continue;
    add_pair(scr.index[static_cast<std::size_t>(e.u)], scr.index[static_cast<std::size_t>(e.v)], e.cap_uv, e.cap_vu);
  }
}

/// No arc enters the sink: flow 0, residual = capacity; the source side is
/// what a breadth-first search from the source reaches (black in scr.color).
void reach_from_source(FoldedGraph& g) {
  Scratch& scr = g.scr;
  auto& queue = scr.queue;
  queue.assign(1, g.s);
  std::vector<boost::default_color_type>& seen = scr.color;
  seen.assign(g.nn, boost::white_color);
  seen[g.s] = boost::black_color;
  for (std::size_t q = 0; q < queue.size(); ++q)
    for (std::uint32_t a = scr.start[queue[q]]; a < scr.start[queue[q] + 1]; ++a) {
      const std::uint32_t v = scr.sorted[a].second;
      if (scr.capacity[a] > 0.0 && seen[v] != boost::black_color) {
        seen[v] = boost::black_color;
        queue.push_back(v);
      }
    }
}

/// Boost's Boykov-Kolmogorov max-flow on the CSR graph; the source side is
/// left black in scr.color. Returns the flow.
double bk_max_flow(FoldedGraph& g) {
  Scratch& scr = g.scr;
  const std::size_t nn = g.nn;
  const Csr csr(boost::edges_are_sorted, scr.sorted.begin(), scr.sorted.end(), static_cast<std::uint32_t>(nn));
  auto& residual = scr.residual;
  residual.assign(g.na, 0.0);
  std::vector<CsrEdge>& predecessor = scr.predecessor;
  std::vector<boost::default_color_type>& color = scr.color;
  std::vector<long>& distance = scr.distance;
  predecessor.assign(nn, CsrEdge());
  color.assign(nn, boost::white_color);
  distance.assign(nn, 0);
  const auto eidx = boost::get(boost::edge_index, csr);
  const auto vidx = boost::get(boost::vertex_index, csr);
  return boost::boykov_kolmogorov_max_flow(
      csr, boost::make_iterator_property_map(scr.capacity.begin(), eidx),
      boost::make_iterator_property_map(residual.begin(), eidx),
      boost::make_iterator_property_map(scr.reverse.begin(), eidx),
      boost::make_iterator_property_map(predecessor.begin(), vidx),
      boost::make_iterator_property_map(color.begin(), vidx),
      boost::make_iterator_property_map(distance.begin(), vidx), vidx, g.s, g.t);
}

}  // namespace

GraphCut::GraphCut(int num_nodes) : n_(0) { reset(num_nodes); }

void GraphCut::reset(int num_nodes) {
  if (num_nodes < 0)
    throw InvalidInputError("GraphCut: num_nodes must be >= 0, got " + std::to_string(num_nodes));
  n_ = num_nodes;
  src_cap_.assign(static_cast<std::size_t>(n_), 0.0);
  sink_cap_.assign(static_cast<std::size_t>(n_), 0.0);
  edges_.clear();
  source_side_.clear();
  solved_ = false;
}

void GraphCut::throw_node_out_of_range(int u, const char* what) const {
  throw InvalidInputError(std::string("GraphCut: ") + what + " node " + std::to_string(u) +
                          " out of range [0, " + std::to_string(n_) + ")");
}

double GraphCut::clamp_capacity(double c, const char* what) {
  if (std::isnan(c) || c < 0.0)
    throw InvalidInputError(std::string("GraphCut: ") + what +
                            " capacity must be >= 0, got " + std::to_string(c));
  return c >= kInfinity ? kInfinity : c;
}

void GraphCut::add_edge(int u, int v, double cap_uv, double cap_vu) {
  check_node(u, "add_edge");
  check_node(v, "add_edge");
  if (u == v)
    throw InvalidInputError("GraphCut: add_edge with u == v == " + std::to_string(u));
  if (solved_) throw InvalidInputError("GraphCut: add_edge after solve()");
  edges_.push_back({u, v, clamp_capacity(cap_uv, "edge"), clamp_capacity(cap_vu, "edge")});
}

void GraphCut::add_terminal(int u, double cap_source, double cap_sink) {
  check_node(u, "add_terminal");
  if (solved_) throw InvalidInputError("GraphCut: add_terminal after solve()");
  auto& s = src_cap_[static_cast<std::size_t>(u)];
  auto& t = sink_cap_[static_cast<std::size_t>(u)];
  s = std::min(kInfinity, s + clamp_capacity(cap_source, "source"));
  t = std::min(kInfinity, t + clamp_capacity(cap_sink, "sink"));
}

double GraphCut::solve() {
  if (solved_) throw InvalidInputError("GraphCut: solve() called twice");
  solved_ = true;
  thread_local Scratch scr;
  FoldedGraph g(scr);
  g.n = static_cast<std::size_t>(n_);
  const std::size_t n = g.n;
  // 1. Fold the forced nodes into the terminals. A node with an infinite link
  // to one terminal only (and a finite cut exists) is on that terminal's side
  // of every finite cut, so it is that terminal as far as the cut is
  // concerned: an edge u->v from a source-forced u to a free v is paid exactly
  // when v is on the sink side, i.e. it is a source link of v; v->u is never
  // paid. Likewise for sink-forced nodes, and an edge between a source-forced
  // and a sink-forced node is paid by every cut (a constant). The folded graph
  // has the same finite cuts, restricted to the free nodes, with the same
  // capacities; so the same max-flow value and the same minimal source set
  // (the nodes reachable from the source in the residual graph of any maximum
  // flow, which is what BK reports and which is unique), hence the same
  // labels, with fewer nodes and edges.
  fold_forced_nodes(src_cap_, sink_cap_, g);
  fold_forced_edges(edges_, g);
  reduce_terminal_links(g);
  source_side_.assign(n, 0);
  for (std::size_t u = 0; u < n; ++u) source_side_[u] = scr.forced[u] > 0 ? 1 : 0;
  auto finish = [&](double flow) {
    const double total = flow + g.constant;
    return total >= kInfinity ? std::numeric_limits<double>::infinity() : total;
  };
  // 2. Without a source link or without a sink link no path joins the
  // terminals: the max flow is 0 and the source side is what the source
  // reaches through positive capacities (BK's source tree when it stops),
  // which is empty without source links. Skip the max-flow then.
  if (!g.any_source) return finish(0.0);
  build_arcs(edges_, g);
  double flow = 0.0;
  if (g.any_sink)
    flow = bk_max_flow(g);
  else
    reach_from_source(g);  // no arc enters the sink: flow 0
  for (std::size_t u = 0; u < n; ++u)
    if (scr.forced[u] == 0) source_side_[u] = scr.color[scr.index[u]] == boost::black_color ? 1 : 0;
  return finish(flow);
}

bool GraphCut::is_source_side(int u) const {
  if (!solved_) throw InvalidInputError("GraphCut: is_source_side() before solve()");
  check_node(u, "is_source_side");
  return source_side_[static_cast<std::size_t>(u)] != 0;
}

}  // namespace surftex
