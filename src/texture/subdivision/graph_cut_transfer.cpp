// SPDX-License-Identifier: AGPL-3.0-or-later
// Graph-cut transfer (Bangay & Morkel 2006, section 3.4). See graph_cut_transfer.h.
#include "texture/subdivision/graph_cut_transfer.h"

#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/graph_cut.h"

namespace surftex {
namespace {

double mismatch(const TransferNode& n) {
  if (!n.colored || n.pinned) return 0.0;
  double s = 0;
  for (int c = 0; c < 3; ++c) s += (double(n.surface[c]) - n.texture[c]) * (double(n.surface[c]) - n.texture[c]);
  return std::sqrt(s);
}

// exp(-(x_A^2 + x_B^2) / (sigma r^2)) = g(A) g(B) with g(X) = exp(-x_X^2 / (sigma r^2)):
// one exp per node instead of one per edge (graph_cut_transfer and
// transfer_seam_cost compute W the same way, so their costs agree exactly).
double falloff(const TransferNode& a, double denom) { return std::exp(-(a.distance * a.distance) / denom); }

double edge_weight(const TransferNode& a, const TransferNode& b, double r, double sigma) {
  const double denom = sigma * r * r;
  return (mismatch(a) + mismatch(b)) * (falloff(a, denom) * falloff(b, denom));
}

void check(const std::vector<TransferNode>& nodes, const std::vector<std::array<int, 2>>& edges, double r,
           double sigma) {
  if (!(r > 0) || !(sigma > 0) || !std::isfinite(r) || !std::isfinite(sigma))
    throw InvalidInputError("graph_cut_transfer: r and sigma must be > 0 (got r=" + std::to_string(r) +
                            ", sigma=" + std::to_string(sigma) + ")");
  const int n = static_cast<int>(nodes.size());
  for (const auto& e : edges)
    if (e[0] < 0 || e[1] < 0 || e[0] >= n || e[1] >= n || e[0] == e[1])
      throw InvalidInputError("graph_cut_transfer: edge (" + std::to_string(e[0]) + "," + std::to_string(e[1]) +
                              ") out of range for " + std::to_string(n) + " nodes");
}

}  // namespace

double transfer_seam_cost(const std::vector<TransferNode>& nodes, const std::vector<std::array<int, 2>>& edges,
                          const std::vector<char>& take, double r, double sigma) {
  check(nodes, edges, r, sigma);
  double c = 0;
  for (const auto& e : edges)
    if (take[e[0]] != take[e[1]]) c += edge_weight(nodes[e[0]], nodes[e[1]], r, sigma);
  return c;
}

GraphCutTransferResult graph_cut_transfer(const std::vector<TransferNode>& nodes,
                                          const std::vector<std::array<int, 2>>& edges, int center,
                                          int border_hops, double r, const GraphCutTransferOptions& opt) {
  check(nodes, edges, r, opt.sigma);
  const int n = static_cast<int>(nodes.size());
  if (center < 0 || center >= n)
    throw InvalidInputError("graph_cut_transfer: center " + std::to_string(center) + " out of range");
  // Mismatches once per node, weights once per edge (each W is used by the
  // graph and by both seam costs).
  thread_local std::vector<double> mis, fall, w;
  mis.resize(n);
  fall.resize(n);
  const double denom = opt.sigma * r * r;
  for (int i = 0; i < n; ++i) {
    mis[i] = mismatch(nodes[i]);
    fall[i] = falloff(nodes[i], denom);
  }
  w.resize(edges.size());
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const int a = edges[k][0], b = edges[k][1];
    w[k] = (mis[a] + mis[b]) * (fall[a] * fall[b]);
  }
  thread_local GraphCut gc(0);  // storage reused by the many small cuts of a pass
  gc.reset(n);
  gc.reserve_edges(edges.size());
  thread_local std::vector<char> paste;
  paste.assign(n, 1);
  for (int i = 0; i < n; ++i) {
    const TransferNode& a = nodes[i];
    if (a.pinned && i != center) {
      gc.add_terminal(i, 0, GraphCut::kInfinity);
      paste[i] = 0;
    } else if (i == center || !a.colored) {
      gc.add_terminal(i, GraphCut::kInfinity, 0);
    } else if (a.hops >= border_hops) {
      gc.add_terminal(i, 0, GraphCut::kInfinity);
      paste[i] = 0;
    }
  }
  for (std::size_t k = 0; k < edges.size(); ++k)
    if (w[k] > 0) gc.add_edge(edges[k][0], edges[k][1], w[k], w[k]);
  gc.solve();
  GraphCutTransferResult res;
  res.take_texture.resize(n);
  for (int i = 0; i < n; ++i) {
    res.take_texture[i] = gc.is_source_side(i) ? 1 : 0;
    res.taken += res.take_texture[i];
  }
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const int u = edges[k][0], v = edges[k][1];
    if (res.take_texture[u] != res.take_texture[v]) res.cut_cost += w[k];
    if (paste[u] != paste[v]) res.paste_cost += w[k];
  }
  return res;
}

}  // namespace surftex
