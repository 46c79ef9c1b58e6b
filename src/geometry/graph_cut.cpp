// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/graph_cut.h"

// GCC 12 reports a false -Wmaybe-uninitialized inside Boost.Graph's edge
// iterator (boost::optional storage) when boykov_kolmogorov_max_flow is
// instantiated; silenced for this translation unit only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/boykov_kolmogorov_max_flow.hpp>

#include <cmath>
#include <limits>
#include <string>

#include "geometry/errors.h"

namespace surftex {
namespace {

using Traits = boost::adjacency_list_traits<boost::vecS, boost::vecS, boost::directedS>;
using EdgeDesc = Traits::edge_descriptor;

struct VertexProps {
  boost::default_color_type color = boost::white_color;
  long distance = 0;
  EdgeDesc predecessor{};
};
struct EdgeProps {
  double capacity = 0.0;
  double residual = 0.0;
  EdgeDesc reverse{};
};
using Graph = boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS, VertexProps,
                                    EdgeProps>;

void add_pair(Graph& g, std::size_t u, std::size_t v, double cuv, double cvu) {
  EdgeDesc e1 = boost::add_edge(u, v, g).first;
  EdgeDesc e2 = boost::add_edge(v, u, g).first;
  g[e1].capacity = cuv;
  g[e2].capacity = cvu;
  g[e1].reverse = e2;
  g[e2].reverse = e1;
}

}  // namespace

GraphCut::GraphCut(int num_nodes) : n_(num_nodes) {
  if (num_nodes < 0)
    throw InvalidInputError("GraphCut: num_nodes must be >= 0, got " + std::to_string(num_nodes));
  src_cap_.assign(static_cast<std::size_t>(n_), 0.0);
  sink_cap_.assign(static_cast<std::size_t>(n_), 0.0);
}

void GraphCut::check_node(int u, const char* what) const {
  if (u < 0 || u >= n_)
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
  const std::size_t n = static_cast<std::size_t>(n_);
  const std::size_t s = n, t = n + 1;
  Graph g(n + 2);
  // A node's two terminal links: only the part exceeding the smaller one
  // matters for the cut (min(cs, ct) is paid either way); keeping both would
  // be correct too, this just shortens augmenting paths.
  double constant = 0.0;
  for (std::size_t u = 0; u < n; ++u) {
    double cs = src_cap_[u], ct = sink_cap_[u];
    double m = std::min(cs, ct);
    if (m >= kInfinity) {
      // Infinite both ways: every cut is infinite.
      constant = kInfinity;
      continue;
    }
    constant += m;
    cs -= m;
    ct -= m;
    if (cs > 0.0) add_pair(g, s, u, cs, 0.0);
    if (ct > 0.0) add_pair(g, u, t, ct, 0.0);
  }
  for (const Edge& e : edges_) {
    if (e.cap_uv <= 0.0 && e.cap_vu <= 0.0) continue;
    add_pair(g, static_cast<std::size_t>(e.u), static_cast<std::size_t>(e.v), e.cap_uv, e.cap_vu);
  }
  double flow = boost::boykov_kolmogorov_max_flow(
      g, boost::get(&EdgeProps::capacity, g), boost::get(&EdgeProps::residual, g),
      boost::get(&EdgeProps::reverse, g), boost::get(&VertexProps::predecessor, g),
      boost::get(&VertexProps::color, g), boost::get(&VertexProps::distance, g),
      boost::get(boost::vertex_index, g), s, t);
  source_side_.assign(n, 0);
  for (std::size_t u = 0; u < n; ++u)
    source_side_[u] = g[u].color == boost::black_color ? 1 : 0;
  double total = flow + constant;
  if (total >= kInfinity) return std::numeric_limits<double>::infinity();
  return total;
}

bool GraphCut::is_source_side(int u) const {
  if (!solved_) throw InvalidInputError("GraphCut: is_source_side() before solve()");
  check_node(u, "is_source_side");
  return source_side_[static_cast<std::size_t>(u)] != 0;
}

}  // namespace surftex
