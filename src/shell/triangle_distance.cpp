// SPDX-License-Identifier: AGPL-3.0-or-later
// A bounding-volume hierarchy over the triangles (median splits of the
// centroids along the box's longest axis, leaves of up to 4 triangles) and a
// depth-first query visiting the nearer child first and skipping every box
// farther than the best hit so far. The closest point of one triangle is found
// by the Voronoi regions of its vertices, edges and face (Ericson, Real-Time
// Collision Detection, 5.1.5). Replaces CGAL's AABB tree here: its projection
// functor and kd-tree hint took 45% of a quilting run (decision 105).
#include "shell/triangle_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <tuple>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "geometry/errors.h"
#include "geometry/vec3.h"

namespace surftex {
namespace triangle_distance_detail {  // named: TriangleDistance::Impl holds these

struct Box {
  P3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
        std::numeric_limits<double>::infinity()};
  P3 hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
        -std::numeric_limits<double>::infinity()};
  void add(const P3& p) {
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  }
  double squared_distance(const Box& o) const {
    double d = 0;
    for (int k = 0; k < 3; ++k) {
      const double e = std::max({0.0, o.lo[k] - hi[k], lo[k] - o.hi[k]});
      d += e * e;
    }
    return d;
  }
  double squared_distance(const P3& q) const {
    double d = 0;
    for (int k = 0; k < 3; ++k) {
      const double e = q[k] < lo[k] ? lo[k] - q[k] : (q[k] > hi[k] ? q[k] - hi[k] : 0.0);
      d += e * e;
    }
    return d;
  }
};

// A leaf holds triangles [first, first + count) of the reordered list; an
// inner node (count 0) has its children at `first` and `first + 1`.
struct Node {
  Box box;
  int first = 0, count = 0;
};

}  // namespace triangle_distance_detail

namespace {
using triangle_distance_detail::Box;
using triangle_distance_detail::Node;
constexpr int kLeafSize = 4;

// Closest point of triangle abc to p as barycentrics (u, v, w) on (a, b, c).
// (vec3's helpers are called qualified: a using-declaration could meet another
// file's sub/dot in the same unity batch.)
// ab = b - a and ac = c - a are precomputed per triangle (the same values).
P3 closest_barycentric(const P3& p, const P3& a, const P3& b, const P3& c, const P3& ab, const P3& ac) {
  const P3 ap = vec3::sub(p, a);
  const double d1 = vec3::dot(ab, ap), d2 = vec3::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};  // vertex a
  const P3 bp = vec3::sub(p, b);
  const double d3 = vec3::dot(ab, bp), d4 = vec3::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};  // vertex b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {  // edge ab
    const double t = d1 / (d1 - d3);
    return {1 - t, t, 0};
  }
  const P3 cp = vec3::sub(p, c);
  const double d5 = vec3::dot(ab, cp), d6 = vec3::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};  // vertex c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {  // edge ac
    const double t = d2 / (d2 - d6);
    return {1 - t, 0, t};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {  // edge bc
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - t, t};
  }
  const double den = va + vb + vc;
  if (!(den > 0)) {  // degenerate (collinear) triangle: the nearest of its three edges
    auto on_edge = [&](const P3& s, const P3& e, double& t) {
      const P3 d = vec3::sub(e, s);
      const double l = vec3::dot(d, d);
      t = l > 0 ? std::clamp(vec3::dot(vec3::sub(p, s), d) / l, 0.0, 1.0) : 0.0;
      const P3 x{s[0] + t * d[0], s[1] + t * d[1], s[2] + t * d[2]};
      const P3 r = vec3::sub(p, x);
      return vec3::dot(r, r);
    };
    double t0, t1, t2;
    const double e0 = on_edge(a, b, t0), e1 = on_edge(a, c, t1), e2 = on_edge(b, c, t2);
    if (e0 <= e1 && e0 <= e2) return {1 - t0, t0, 0};
    if (e1 <= e2) return {1 - t1, 0, t1};
    return {0, 1 - t2, t2};
  }
  const double v = vb / den, w = vc / den;
  return {1 - v - w, v, w};
}

// Unit normal and offset of the plane through a with edges ab, ac; zero when
// the triangle is a sliver (|ab x ac| under 1e-6 of |ab| |ac|).
std::array<double, 4> plane_of(const P3& ab, const P3& ac, const P3& a) {
  const P3 n{ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
  const double len = std::sqrt(vec3::dot(n, n));
  if (!(len > 1e-6 * std::sqrt(vec3::dot(ab, ab) * vec3::dot(ac, ac)))) return {0, 0, 0, 0};
  const P3 u{n[0] / len, n[1] / len, n[2] / len};
  return {u[0], u[1], u[2], vec3::dot(u, a)};
}

}  // namespace

struct TriangleDistance::Impl {
  std::vector<std::array<P3, 3>> tris;  // in leaf order
  std::vector<std::array<P3, 2>> edges;  // per triangle in leaf order: b - a, c - a
  std::vector<triangle_distance_detail::Box> boxes;  // per triangle in leaf order
  // Per triangle in leaf order: unit normal and offset of its plane (n . x = d),
  // zero for a sliver whose normal rounding cannot be trusted; the plane's
  // distance is a lower bound of the triangle's.
  std::vector<std::array<double, 4>> planes;
  double rounding_slack = 0;  // (1e-9 of the largest coordinate)^2: the absolute slack of bounds against rounding
  std::vector<int> original;            // leaf order -> index into mesh.tris
  std::vector<int> leaf;                // index into mesh.tris -> leaf order
  std::vector<triangle_distance_detail::Node> nodes;
  // build_cell_lists: cell (i, j, k) lists cell_items[cell_start[c] ..
  // cell_start[c + 1]) (leaf-order triangles), c = (k * ny + j) * nx + i.
  P3 grid_lo{0, 0, 0};
  double grid_cell = 0;
  int nx = 0, ny = 0, nz = 0;
  struct CellItem {
    float bound;  ///< <= the squared distance from any point of the cell to the triangle's box
    int tri;      ///< leaf order
  };
  std::vector<std::size_t> cell_start;
  std::vector<CellItem> cell_items;

  /// The cell holding q, or -1 (outside the grid, no grid, not finite).
  long long cell_of(const P3& q) const {
    if (cell_start.empty()) return -1;
    long long c[3];
    const int n[3] = {nx, ny, nz};
    for (int k = 0; k < 3; ++k) {
      const double x = (q[k] - grid_lo[k]) / grid_cell;
      if (!(x >= 0) || !(x < n[k])) return -1;
      c[k] = static_cast<long long>(x);
    }
    return (c[2] * ny + c[1]) * nx + c[0];
  }
  /// Leaf-order triangles whose box is within sqrt(r2) of box b (tree walk).
  void triangles_near(const triangle_distance_detail::Box& b, double r2, std::vector<int>& out) const;

  void build(int node, int first, int count, std::vector<P3>& centroid) {
    Box box, cbox;
    for (int i = first; i < first + count; ++i) {
      for (const P3& p : tris[original[i]]) box.add(p);
      cbox.add(centroid[original[i]]);
    }
    nodes[node].box = box;
    if (count <= kLeafSize) {
      nodes[node].first = first;
      nodes[node].count = count;
      return;
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (cbox.hi[k] - cbox.lo[k] > cbox.hi[axis] - cbox.lo[axis]) axis = k;
    const int half = count / 2;
    // Ties broken by index: the same tree whatever the standard library's nth_element does with equal keys.
    std::nth_element(original.begin() + first, original.begin() + first + half, original.begin() + first + count,
                     [&](int x, int y) {
                       return centroid[x][axis] < centroid[y][axis] ||
                              (centroid[x][axis] == centroid[y][axis] && x < y);
                     });
    const int left = static_cast<int>(nodes.size());
    nodes.emplace_back();
    nodes.emplace_back();
    nodes[node].first = left;
    nodes[node].count = 0;
    build(left, first, half, centroid);
    build(left + 1, first + half, count - half, centroid);
  }
};

TriangleDistance::TriangleDistance(const ElementMesh& m) : impl_(std::make_unique<Impl>()) {
  const int n = static_cast<int>(m.tris.size());
  if (n == 0) return;
  std::vector<std::array<P3, 3>> tris(m.tris.size());
  std::vector<P3> centroid(m.tris.size());
  for (int t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) tris[t][k] = m.points[m.tris[t][k]];
    for (int k = 0; k < 3; ++k) centroid[t][k] = (tris[t][0][k] + tris[t][1][k] + tris[t][2][k]) / 3.0;
  }
  impl_->tris = std::move(tris);
  impl_->original.resize(n);
  std::iota(impl_->original.begin(), impl_->original.end(), 0);
  impl_->nodes.reserve(2 * static_cast<std::size_t>(n) / kLeafSize + 2);
  impl_->nodes.emplace_back();
  impl_->build(0, 0, n, centroid);
  // Store the triangles in leaf order so a leaf reads contiguous memory.
  std::vector<std::array<P3, 3>> ordered(n);
  for (int i = 0; i < n; ++i) ordered[i] = impl_->tris[impl_->original[i]];
  impl_->tris = std::move(ordered);
  impl_->leaf.resize(n);
  for (int i = 0; i < n; ++i) impl_->leaf[impl_->original[i]] = i;
  impl_->edges.resize(n);
  impl_->boxes.resize(n);
  impl_->planes.resize(n);
  for (int i = 0; i < n; ++i) {
    const auto& t = impl_->tris[i];
    impl_->edges[i] = {vec3::sub(t[1], t[0]), vec3::sub(t[2], t[0])};
    for (const P3& p : t) impl_->boxes[i].add(p);
    impl_->planes[i] = plane_of(impl_->edges[i][0], impl_->edges[i][1], t[0]);
  }
  const auto& all = impl_->nodes[0].box;
  double extent = 0;
  for (int k = 0; k < 3; ++k) extent = std::max({extent, std::abs(all.lo[k]), std::abs(all.hi[k])});
  impl_->rounding_slack = (1e-9 * extent) * (1e-9 * extent);
}
void TriangleDistance::Impl::triangles_near(const Box& b, double r2, std::vector<int>& out) const {
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& nd = nodes[stack[--top]];
    if (nd.box.squared_distance(b) > r2) continue;
    if (nd.count > 0) {
      for (int i = nd.first; i < nd.first + nd.count; ++i)
        if (boxes[i].squared_distance(b) <= r2) out.push_back(i);
      continue;
    }
    stack[top++] = nd.first;
    stack[top++] = nd.first + 1;
  }
  std::sort(out.begin(), out.end());
}

// A point p of a cell is at most |p - centre| <= half its diagonal from the
// centre, so its closest triangle is within U = d(centre) + half diagonal of
// p, and that triangle's box within U of the cell's box: the list holds it,
// and every triangle tying with it (a slack of 1e-9 covers rounding).
void TriangleDistance::build_cell_lists(double cell, std::size_t max_cells) {
  Impl& I = *impl_;
  if (I.tris.empty() || !(cell > 0) || !std::isfinite(cell)) return;
  const Box& all = I.nodes[0].box;
  auto count_for = [&](double h, int n[3]) {
    std::size_t total = 1;
    for (int k = 0; k < 3; ++k) {
      n[k] = static_cast<int>(std::ceil((all.hi[k] - all.lo[k]) / h)) + 4;  // two cells of margin each side
      total *= static_cast<std::size_t>(n[k]);
    }
    return total;
  };
  int n[3];
  while (count_for(cell, n) > max_cells) cell *= 1.25;
  I.grid_cell = cell;
  for (int k = 0; k < 3; ++k) I.grid_lo[k] = all.lo[k] - 2 * cell;
  I.nx = n[0], I.ny = n[1], I.nz = n[2];
  const std::size_t cells = static_cast<std::size_t>(n[0]) * n[1] * n[2];
  std::vector<std::vector<Impl::CellItem>> lists(cells);
  const double half_diag = 0.5 * std::sqrt(3.0) * cell;
  auto fill = [&](std::size_t c) {
    const std::size_t i = c % n[0], j = (c / n[0]) % n[1], k = c / (static_cast<std::size_t>(n[0]) * n[1]);
    Box b;
    b.lo = {I.grid_lo[0] + i * cell, I.grid_lo[1] + j * cell, I.grid_lo[2] + k * cell};
    b.hi = {b.lo[0] + cell, b.lo[1] + cell, b.lo[2] + cell};
    const P3 centre{b.lo[0] + 0.5 * cell, b.lo[1] + 0.5 * cell, b.lo[2] + 0.5 * cell};
    const double u = (closest(centre).distance + half_diag) * (1 + 1e-9) + 1e-12 * cell;
    std::vector<int> near;
    I.triangles_near(b, u * u, near);
    // Ordered by the least squared distance from any point of the cell to the
    // triangle's box (then nearest to the centre first): a query stops at the
    // first entry whose bound is past its best hit, every later one being
    // farther still (the bound is shrunk by 1e-6 so that float rounding never
    // raises it past the box's own distance).
    std::vector<std::tuple<double, double, int>> by_d;
    by_d.reserve(near.size());
    for (int t : near) {
      const Box& tb = I.boxes[static_cast<std::size_t>(t)];
      by_d.emplace_back(tb.squared_distance(b), tb.squared_distance(centre), t);
    }
    std::sort(by_d.begin(), by_d.end());
    lists[c].reserve(by_d.size());
    for (const auto& [lb, dc, t] : by_d) lists[c].push_back({static_cast<float>(lb * (1 - 1e-6)), t});
  };
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, 256), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c < r.end(); ++c) fill(c);
  });
  I.cell_start.assign(cells + 1, 0);
  for (std::size_t c = 0; c < cells; ++c) I.cell_start[c + 1] = I.cell_start[c] + lists[c].size();
  I.cell_items.resize(I.cell_start[cells]);
  for (std::size_t c = 0; c < cells; ++c)
    std::copy(lists[c].begin(), lists[c].end(), I.cell_items.begin() + I.cell_start[c]);
}

TriangleDistance::~TriangleDistance() = default;
TriangleDistance::TriangleDistance(TriangleDistance&&) noexcept = default;
TriangleDistance& TriangleDistance::operator=(TriangleDistance&&) noexcept = default;

bool TriangleDistance::empty() const { return impl_->tris.empty(); }

double TriangleDistance::box_squared_distance(const P3& q) const {
  return impl_->nodes.empty() ? 0.0 : impl_->nodes[0].box.squared_distance(q);
}

TriangleDistance::Hit TriangleDistance::closest(const P3& q, int hint) const {
  return closest_below(q, hint, std::numeric_limits<double>::infinity());
}

TriangleDistance::Hit TriangleDistance::closest_within(const P3& q, double radius, int hint) const {
  if (!(radius >= 0)) throw InvalidInputError("TriangleDistance::closest_within: radius must be >= 0");
  // Margins of 1e-9 relative and 1e-9 of the mesh's extent: rounding never
  // decides against a triangle at the radius, even a radius of 0 (the caller
  // compares the distance with its radius itself).
  const double bound = radius * (1 + 1e-9);
  Hit h = closest_below(q, hint, bound * bound + impl_->rounding_slack + 1e-300);
  if (h.tri < 0) h.distance = std::numeric_limits<double>::infinity();
  return h;
}

// The closest triangle among those nearer than sqrt(start) (all: infinity);
// tri = -1 when there is none.
TriangleDistance::Hit TriangleDistance::closest_below(const P3& q, int hint, double start) const {
  Hit h;
  const Impl& I = *impl_;
  if (I.tris.empty()) return h;
  double best = start;
  int best_i = -1;
  P3 best_bary{1, 0, 0};
  auto try_triangle = [&](int i) {
    // A triangle whose box is farther than the best hit can neither win nor tie.
    if (I.boxes[i].squared_distance(q) > best) return;
    // Nor one whose plane is (with a margin for the rounding of both sides).
    const auto& pl = I.planes[i];
    const double pd = pl[0] * q[0] + pl[1] * q[1] + pl[2] * q[2] - pl[3];
    if (pd * pd > best * (1 + 1e-9) + I.rounding_slack) return;
    const auto& t = I.tris[i];
    const P3 b = closest_barycentric(q, t[0], t[1], t[2], I.edges[i][0], I.edges[i][1]);
    P3 x;
    for (int k = 0; k < 3; ++k) x[k] = b[0] * t[0][k] + b[1] * t[1][k] + b[2] * t[2][k];
    const P3 r = vec3::sub(q, x);
    const double d = vec3::dot(r, r);
    // Ties: the triangle first in the mesh (independent of the traversal).
    if (d < best || (d == best && best_i >= 0 && I.original[i] < I.original[best_i])) {
      best = d;
      best_i = i;
      best_bary = b;
      h.point = x;
    }
  };
  // Each stack entry carries its box's squared distance, computed once when pushed.
  auto walk_tree = [&] {
    int stack[128];
    double stack_d[128];
    int top = 0;
    stack[top] = 0;
    stack_d[top++] = I.nodes[0].box.squared_distance(q);
    while (top > 0) {
      --top;
      if (stack_d[top] > best) continue;  // (equal: a tie may still win, see below)
      const Node& nd = I.nodes[stack[top]];
      if (nd.count > 0) {
        for (int i = nd.first; i < nd.first + nd.count; ++i) try_triangle(i);
        continue;
      }
      const int l = nd.first, r = nd.first + 1;
      const double dl = I.nodes[l].box.squared_distance(q), dr = I.nodes[r].box.squared_distance(q);
      // Nearer child on top of the stack (visited first); the depth is below 2 log2(n) + 2.
      if (dl <= dr) {
        stack[top] = r, stack_d[top++] = dr;
        stack[top] = l, stack_d[top++] = dl;
      } else {
        stack[top] = l, stack_d[top++] = dl;
        stack[top] = r, stack_d[top++] = dr;
      }
    }
  };
  if (const long long c = I.cell_of(q); c >= 0) {  // the cell's list holds the winner and its ties
    for (std::size_t k = I.cell_start[c]; k < I.cell_start[c + 1]; ++k) {
      if (I.cell_items[k].bound > best) break;  // this and every later triangle lie farther than the best hit
      try_triangle(I.cell_items[k].tri);
    }
  } else {
    // The hint first: a near hit prunes the walk. The winner is the least
    // (distance, index) over all triangles, and no box holding it is ever
    // pruned (its distance is at most the best), so the hint changes only
    // how many boxes are opened.
    if (hint >= 0 && hint < static_cast<int>(I.leaf.size())) try_triangle(I.leaf[static_cast<std::size_t>(hint)]);
    walk_tree();
  }
  if (best_i < 0 && std::isfinite(start)) return h;  // none nearer than the bound (or q not finite)
  if (best_i < 0) {  // a non-finite query point: no distance compares
    h.tri = I.original[0];
    h.distance = std::numeric_limits<double>::quiet_NaN();
    return h;
  }
  h.tri = I.original[best_i];
  h.distance = std::sqrt(best);
  h.bary = best_bary;
  return h;
}

}  // namespace surftex
