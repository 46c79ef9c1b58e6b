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

struct ArcList {
  std::vector<std::uint32_t> from, to;  ///< arcs in insertion order (pairs: 2i, 2i+1 reverse each other)
  std::vector<double> cap;
  void add_pair(std::size_t u, std::size_t v, double cuv, double cvu) {
    from.push_back(static_cast<std::uint32_t>(u));
    to.push_back(static_cast<std::uint32_t>(v));
    cap.push_back(cuv);
    from.push_back(static_cast<std::uint32_t>(v));
    to.push_back(static_cast<std::uint32_t>(u));
    cap.push_back(cvu);
  }
};

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
  // Per-thread buffers: many small cuts (one per vertex in subdivision
  // synthesis) reuse their storage instead of allocating it every time.
  struct Scratch {
    ArcList arcs;
    std::vector<std::uint32_t> start, pos, next;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> sorted;
    std::vector<double> capacity, residual;
    std::vector<CsrEdge> reverse, predecessor;
    std::vector<boost::default_color_type> color;
    std::vector<long> distance;
  };
  thread_local Scratch scr;
  ArcList& arcs = scr.arcs;
  arcs.from.clear();
  arcs.to.clear();
  arcs.cap.clear();
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
    if (cs > 0.0) arcs.add_pair(s, u, cs, 0.0);
    if (ct > 0.0) arcs.add_pair(u, t, ct, 0.0);
  }
  for (const Edge& e : edges_) {
    if (e.cap_uv <= 0.0 && e.cap_vu <= 0.0) continue;
    arcs.add_pair(static_cast<std::size_t>(e.u), static_cast<std::size_t>(e.v), e.cap_uv, e.cap_vu);
  }
  // Stable counting sort of the arcs by source: CSR position of arc i.
  const std::size_t nn = n + 2, na = arcs.from.size();
  std::vector<std::uint32_t>& start = scr.start;
  std::vector<std::uint32_t>& pos = scr.pos;
  start.assign(nn + 1, 0);
  pos.resize(na);
  for (std::uint32_t f : arcs.from) ++start[f + 1];
  for (std::size_t u = 0; u < nn; ++u) start[u + 1] += start[u];
  scr.next.assign(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < na; ++i) pos[i] = scr.next[arcs.from[i]]++;
  auto& sorted = scr.sorted;
  auto& capacity = scr.capacity;
  auto& residual = scr.residual;
  sorted.resize(na);
  capacity.resize(na);
  residual.assign(na, 0.0);
  for (std::size_t i = 0; i < na; ++i) {
    sorted[pos[i]] = {arcs.from[i], arcs.to[i]};
    capacity[pos[i]] = arcs.cap[i];
  }
  const Csr g(boost::edges_are_sorted, sorted.begin(), sorted.end(), static_cast<std::uint32_t>(nn));
  std::vector<CsrEdge>& reverse = scr.reverse;
  reverse.resize(na);
  for (std::size_t i = 0; i < na; ++i) reverse[pos[i]] = CsrEdge(arcs.from[i ^ 1], pos[i ^ 1]);
  std::vector<CsrEdge>& predecessor = scr.predecessor;
  std::vector<boost::default_color_type>& color = scr.color;
  std::vector<long>& distance = scr.distance;
  predecessor.assign(nn, CsrEdge());
  color.assign(nn, boost::white_color);
  distance.assign(nn, 0);
  const auto eidx = boost::get(boost::edge_index, g);
  const auto vidx = boost::get(boost::vertex_index, g);
  const double flow = boost::boykov_kolmogorov_max_flow(
      g, boost::make_iterator_property_map(capacity.begin(), eidx),
      boost::make_iterator_property_map(residual.begin(), eidx),
      boost::make_iterator_property_map(reverse.begin(), eidx),
      boost::make_iterator_property_map(predecessor.begin(), vidx),
      boost::make_iterator_property_map(color.begin(), vidx),
      boost::make_iterator_property_map(distance.begin(), vidx), vidx, static_cast<std::uint32_t>(s),
      static_cast<std::uint32_t>(t));
  source_side_.assign(n, 0);
  for (std::size_t u = 0; u < n; ++u)
    source_side_[u] = color[u] == boost::black_color ? 1 : 0;
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
