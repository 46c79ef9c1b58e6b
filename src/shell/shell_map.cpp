// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/shell_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"

namespace surftex {

namespace {

// Uniform grid over tet bounding boxes, cells stored CSR.
struct TetGrid {
  Vec3 lo{}, hi{};
  double cell = 1;
  int n[3] = {1, 1, 1};
  std::vector<int> start, items;

  void build(const std::vector<Vec3>& pts, const std::vector<Tet>& tets) {
    lo = {1e300, 1e300, 1e300};
    hi = {-1e300, -1e300, -1e300};
    for (const Tet& t : tets)
      for (int i : t)
        for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], pts[i][k]), hi[k] = std::max(hi[k], pts[i][k]);
    double ext[3], vol = 1, maxext = 0;
    for (int k = 0; k < 3; ++k) ext[k] = hi[k] - lo[k], maxext = std::max(maxext, ext[k]);
    if (!(maxext > 0)) maxext = 1;
    for (int k = 0; k < 3; ++k) vol *= std::max(ext[k], 1e-6 * maxext);
    cell = std::cbrt(vol / (2.0 * static_cast<double>(std::max<std::size_t>(tets.size(), 1))));
    // Keep the grid within a memory budget (about 4 cells per tet at most).
    for (;;) {
      double cells = 1;
      for (int k = 0; k < 3; ++k) n[k] = std::max(1, static_cast<int>(std::ceil(ext[k] / cell))), cells *= n[k];
      if (cells <= 4.0 * static_cast<double>(tets.size()) + 64) break;
      cell *= 1.25;
    }
    const std::size_t ncell = static_cast<std::size_t>(n[0]) * n[1] * n[2];
    std::vector<int> count(ncell + 1, 0);
    auto range = [&](const Tet& t, int a[3], int b[3]) {
      for (int k = 0; k < 3; ++k) {
        double mn = 1e300, mx = -1e300;
        for (int i : t) mn = std::min(mn, pts[i][k]), mx = std::max(mx, pts[i][k]);
        a[k] = clampi(static_cast<int>(std::floor((mn - lo[k]) / cell)), k);
        b[k] = clampi(static_cast<int>(std::floor((mx - lo[k]) / cell)), k);
      }
    };
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t ti = 0; ti < tets.size(); ++ti) {
        int a[3], b[3];
        range(tets[ti], a, b);
        for (int x = a[0]; x <= b[0]; ++x)
          for (int y = a[1]; y <= b[1]; ++y)
            for (int z = a[2]; z <= b[2]; ++z) {
              const std::size_t c = index(x, y, z);
              if (pass == 0)
                ++count[c + 1];
              else
                items[static_cast<std::size_t>(start[c] + count[c]++)] = static_cast<int>(ti);
            }
      }
      if (pass == 0) {
        for (std::size_t c = 0; c < ncell; ++c) count[c + 1] += count[c];
        start = count;
        items.assign(static_cast<std::size_t>(start[ncell]), -1);
        std::fill(count.begin(), count.end(), 0);
      }
    }
  }
  int clampi(int i, int k) const { return std::clamp(i, 0, n[k] - 1); }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * n[1] + y) * n[0] + x;
  }
  void cell_of(const Vec3& p, int c[3]) const {
    for (int k = 0; k < 3; ++k) c[k] = clampi(static_cast<int>(std::floor((p[k] - lo[k]) / cell)), k);
  }
};

std::array<double, 4> barycentric(const std::vector<Vec3>& pts, const Tet& t, const Vec3& x) {
  const Vec3 &p0 = pts[t[0]], &p1 = pts[t[1]], &p2 = pts[t[2]], &p3 = pts[t[3]];
  const double a[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
  const double b[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
  const double c[3] = {p3[0] - p0[0], p3[1] - p0[1], p3[2] - p0[2]};
  const double d[3] = {x[0] - p0[0], x[1] - p0[1], x[2] - p0[2]};
  auto det = [](const double* u, const double* v, const double* w) {
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
  };
  const double D = det(a, b, c);
  if (!(std::abs(D) > 0)) return {-1e300, -1e300, -1e300, -1e300};
  const double l1 = det(d, b, c) / D, l2 = det(a, d, c) / D, l3 = det(a, b, d) / D;
  return {1.0 - l1 - l2 - l3, l1, l2, l3};
}

double min4(const std::array<double, 4>& b) { return std::min(std::min(b[0], b[1]), std::min(b[2], b[3])); }

struct Space {
  std::vector<Vec3> pts;
  TetGrid grid;
};

}  // namespace

struct ShellMap::Impl {
  std::vector<Tet> tets;
  std::vector<int> chart;                   // per tet
  std::vector<std::array<int, 4>> across;   // per tet, the tet across the face opposite corner k (-1: none)
  int max_walk = 256;
  Space shell, texture;  // texture points in metric units (u, v, w * w_scale)
  double w_scale = 1;
  double tol = 1e-10;

  Location locate(const Space& sp, const Vec3& x, bool nearest, int only_chart = -1) const {
    Location best;
    double best_min = -std::numeric_limits<double>::infinity();
    int c[3];
    sp.grid.cell_of(x, c);
    const int max_r = nearest ? std::max({sp.grid.n[0], sp.grid.n[1], sp.grid.n[2]}) : 0;
    for (int r = 0; r <= max_r; ++r) {
      for (int x0 = c[0] - r; x0 <= c[0] + r; ++x0)
        for (int y0 = c[1] - r; y0 <= c[1] + r; ++y0)
          for (int z0 = c[2] - r; z0 <= c[2] + r; ++z0) {
            if (std::max({std::abs(x0 - c[0]), std::abs(y0 - c[1]), std::abs(z0 - c[2])}) != r) continue;
            if (x0 < 0 || y0 < 0 || z0 < 0 || x0 >= sp.grid.n[0] || y0 >= sp.grid.n[1] || z0 >= sp.grid.n[2])
              continue;
            const std::size_t cell = sp.grid.index(x0, y0, z0);
            for (int i = sp.grid.start[cell]; i < sp.grid.start[cell + 1]; ++i) {
              const int t = sp.grid.items[static_cast<std::size_t>(i)];
              if (only_chart >= 0 && chart[static_cast<std::size_t>(t)] != only_chart) continue;
              const auto b = barycentric(sp.pts, tets[static_cast<std::size_t>(t)], x);
              const double m = min4(b);
              if (m > best_min || (m == best_min && t < best.tet)) best_min = m, best.tet = t, best.bary = b;
            }
          }
      if (best.tet >= 0 && (best_min >= -tol || r >= 1)) break;
    }
    best.inside = best.tet >= 0 && best_min >= -tol;
    return best;
  }

  // Walk in texture space from `start`; falls back to the chart's grid search.
  Location walk(const Vec3& x, int start) const {
    int cur = start;
    for (int step = 0; step < max_walk; ++step) {
      const auto b = barycentric(texture.pts, tets[static_cast<std::size_t>(cur)], x);
      int k = 0;
      for (int j = 1; j < 4; ++j)
        if (b[static_cast<std::size_t>(j)] < b[static_cast<std::size_t>(k)]) k = j;
      if (b[static_cast<std::size_t>(k)] >= -tol) {
        Location loc;
        loc.tet = cur;
        loc.bary = b;
        loc.inside = true;
        return loc;
      }
      const int next = across[static_cast<std::size_t>(cur)][static_cast<std::size_t>(k)];
      if (next < 0) break;  // the chart's boundary: bottom, top or a lateral wall
      cur = next;
    }
    Location loc = locate(texture, x, false, chart[static_cast<std::size_t>(start)]);
    if (!loc.inside) loc = Location{};
    return loc;
  }

  Vec3 apply(const Space& sp, const Location& loc) const {
    const Tet& t = tets[static_cast<std::size_t>(loc.tet)];
    Vec3 r{0, 0, 0};
    for (int i = 0; i < 4; ++i)
      for (int k = 0; k < 3; ++k) r[k] += loc.bary[i] * sp.pts[t[i]][k];
    return r;
  }
};

ShellMap::ShellMap(const ShellSpace& s, const ShellMapOptions& opt) : impl_(std::make_unique<Impl>()) {
  if (s.tets.empty()) throw InvalidInputError("shell map: the shell has no tetrahedra");
  if (!(opt.tolerance >= 0)) throw InvalidInputError("shell map: tolerance must be >= 0");
  if (opt.max_walk_steps < 1)
    throw InvalidInputError("shell map: max_walk_steps must be >= 1, got " + std::to_string(opt.max_walk_steps));
  impl_->tets = s.tets;
  impl_->tol = opt.tolerance;
  impl_->max_walk = opt.max_walk_steps;
  const std::size_t nt = s.tets.size();
  impl_->chart.resize(nt);
  for (std::size_t t = 0; t < nt; ++t)
    impl_->chart[t] = s.chart.empty() ? 0 : s.chart[static_cast<std::size_t>(s.tets[t][0])];
  // Face adjacency: the face opposite corner k of tet t, keyed by its sorted corners.
  {
    struct FaceRef {
      std::array<int, 3> key;
      int tet, corner;
    };
    std::vector<FaceRef> faces;
    faces.reserve(4 * nt);
    for (std::size_t t = 0; t < nt; ++t)
      for (int k = 0; k < 4; ++k) {
        FaceRef f{{}, static_cast<int>(t), k};
        int j = 0;
        for (int i = 0; i < 4; ++i)
          if (i != k) f.key[static_cast<std::size_t>(j++)] = s.tets[t][static_cast<std::size_t>(i)];
        std::sort(f.key.begin(), f.key.end());
        faces.push_back(f);
      }
    std::sort(faces.begin(), faces.end(), [](const FaceRef& a, const FaceRef& b) {
      return a.key != b.key ? a.key < b.key : a.tet < b.tet;
    });
    impl_->across.assign(nt, {-1, -1, -1, -1});
    for (std::size_t i = 0; i + 1 < faces.size(); ++i)
      if (faces[i].key == faces[i + 1].key) {
        impl_->across[static_cast<std::size_t>(faces[i].tet)][static_cast<std::size_t>(faces[i].corner)] = faces[i + 1].tet;
        impl_->across[static_cast<std::size_t>(faces[i + 1].tet)][static_cast<std::size_t>(faces[i + 1].corner)] = faces[i].tet;
      }
  }
  impl_->w_scale = s.w_scale > 0 ? s.w_scale : 1.0;
  impl_->shell.pts = s.shell_points;
  impl_->texture.pts.resize(s.texture_points.size());
  for (std::size_t i = 0; i < s.texture_points.size(); ++i) impl_->texture.pts[i] = s.texture_metric(static_cast<int>(i));
  impl_->shell.grid.build(impl_->shell.pts, impl_->tets);
  impl_->texture.grid.build(impl_->texture.pts, impl_->tets);
}
ShellMap::~ShellMap() = default;
ShellMap::ShellMap(ShellMap&&) noexcept = default;
ShellMap& ShellMap::operator=(ShellMap&&) noexcept = default;

std::size_t ShellMap::num_tets() const { return impl_->tets.size(); }

int ShellMap::tet_chart(int tet) const {
  if (tet < 0 || static_cast<std::size_t>(tet) >= impl_->tets.size())
    throw InvalidInputError("shell map: tet " + std::to_string(tet) + " out of range (" +
                            std::to_string(impl_->tets.size()) + " tets)");
  return impl_->chart[static_cast<std::size_t>(tet)];
}

ShellMap::Location ShellMap::locate_texture_from(const Vec3& uvw, int start_tet) const {
  if (start_tet < 0 || static_cast<std::size_t>(start_tet) >= impl_->tets.size())
    throw InvalidInputError("shell map: start tet " + std::to_string(start_tet) + " out of range (" +
                            std::to_string(impl_->tets.size()) + " tets)");
  return impl_->walk({uvw[0], uvw[1], uvw[2] * impl_->w_scale}, start_tet);
}

ShellMap::Location ShellMap::locate_texture(const Vec3& uvw, bool nearest) const {
  return impl_->locate(impl_->texture, {uvw[0], uvw[1], uvw[2] * impl_->w_scale}, nearest);
}
ShellMap::Location ShellMap::locate_shell(const Vec3& p, bool nearest) const {
  return impl_->locate(impl_->shell, p, nearest);
}
Vec3 ShellMap::shell_point(const Location& loc) const { return impl_->apply(impl_->shell, loc); }
Vec3 ShellMap::texture_point(const Location& loc) const {
  Vec3 t = impl_->apply(impl_->texture, loc);
  t[2] /= impl_->w_scale;
  return t;
}

Point3 ShellMap::texture_to_shell(const Vec3& uvw) const {
  const Location loc = locate_texture(uvw);
  if (!loc.inside)
    throw InvalidInputError("shell map: texture point (" + std::to_string(uvw[0]) + ", " + std::to_string(uvw[1]) +
                            ", " + std::to_string(uvw[2]) + ") is outside the texture space");
  const Vec3 p = shell_point(loc);
  return Point3(p[0], p[1], p[2]);
}

Vec3 ShellMap::shell_to_texture(const Point3& p) const {
  const Location loc = locate_shell({p.x(), p.y(), p.z()});
  if (!loc.inside)
    throw InvalidInputError("shell map: point (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                            std::to_string(p.z()) + ") is outside the shell");
  return texture_point(loc);
}

}  // namespace surftex
