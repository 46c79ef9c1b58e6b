// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/primitive_meshes.h"
#include "geometry/constants.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw InvalidInputError(what);
}

// Builds `mesh` from points and triangles (indices into points).
void build(Mesh& mesh, const std::vector<Point3>& pts, const std::vector<std::array<int, 3>>& tris) {
  mesh.clear();
  std::vector<VertexIndex> v;
  v.reserve(pts.size());
  for (const auto& p : pts) v.push_back(mesh.add_vertex(p));
  for (const auto& t : tris) {
    FaceIndex f = mesh.add_face(v[t[0]], v[t[1]], v[t[2]]);
    if (f == Mesh::null_face()) throw TopologyError("internal: primitive mesh face could not be added");
  }
}
}  // namespace

void make_tetrahedron(Mesh& mesh) {
  const double s = 1.0 / std::sqrt(3.0);
  std::vector<Point3> p{{s, s, s}, {s, -s, -s}, {-s, s, -s}, {-s, -s, s}};
  build(mesh, p, {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}});
}

void make_cube(Mesh& mesh, double size) {
  require(size > 0 && std::isfinite(size), "cube size must be positive, got " + std::to_string(size));
  const double h = size / 2;
  std::vector<Point3> p;
  for (int i = 0; i < 8; ++i) p.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  // Quads listed counter-clockwise seen from outside.
  const int q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<std::array<int, 3>> t;
  for (auto& f : q) {
    t.push_back({f[0], f[1], f[2]});
    t.push_back({f[0], f[2], f[3]});
  }
  build(mesh, p, t);
}

void make_grid(Mesh& mesh, int nx, int ny, double width, double height) {
  require(nx >= 1 && ny >= 1, "grid resolution must be at least 1x1, got " + std::to_string(nx) + "x" +
                                  std::to_string(ny));
  require(width > 0 && height > 0, "grid size must be positive");
  std::vector<Point3> p;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) p.emplace_back(width * i / nx, height * j / ny, 0.0);
  std::vector<std::array<int, 3>> t;
  auto id = [nx](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  build(mesh, p, t);
}

void make_icosphere(Mesh& mesh, int subdivisions, double radius) {
  require(subdivisions >= 0 && subdivisions <= 8,
          "icosphere subdivisions must be in 0..8, got " + std::to_string(subdivisions));
  require(radius > 0, "icosphere radius must be positive");
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<std::array<double, 3>> p{{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                       {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                       {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  std::vector<std::array<int, 3>> t{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  auto normalize = [](std::array<double, 3> a) {
    double l = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    return std::array<double, 3>{a[0] / l, a[1] / l, a[2] / l};
  };
  for (auto& q : p) q = normalize(q);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      std::array<double, 3> m{(p[a][0] + p[b][0]) / 2, (p[a][1] + p[b][1]) / 2, (p[a][2] + p[b][2]) / 2};
      p.push_back(normalize(m));
      int id = static_cast<int>(p.size()) - 1;
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> nt;
    nt.reserve(t.size() * 4);
    for (auto& f : t) {
      int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      nt.push_back({f[0], a, c});
      nt.push_back({f[1], b, a});
      nt.push_back({f[2], c, b});
      nt.push_back({a, b, c});
    }
    t.swap(nt);
  }
  std::vector<Point3> pts;
  for (auto& q : p) pts.emplace_back(q[0] * radius, q[1] * radius, q[2] * radius);
  build(mesh, pts, t);
}

void make_torus(Mesh& mesh, double R, double r, int nu, int nv) {
  require(R > 0 && r > 0 && r < R, "torus needs 0 < r < R");
  require(nu >= 3 && nv >= 3, "torus resolution must be at least 3x3");
  std::vector<Point3> p;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      double u = 2 * kPi * i / nu, v = 2 * kPi * j / nv;
      p.emplace_back((R + r * std::cos(v)) * std::cos(u), (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
    }
  auto id = [nu, nv](int i, int j) { return ((j + nv) % nv) * nu + (i + nu) % nu; };
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  build(mesh, p, t);
}

void assign_torus_uvs(Mesh& mesh, double R, double repeats_u, double repeats_v) {
  require(repeats_u > 0 && repeats_v > 0, "torus UV repeats must be positive");
  auto uv = get_or_add(mesh, kCornerUV);
  for (FaceIndex f : mesh.faces()) {
    std::array<double, 3> us{}, vs{};
    std::array<HalfedgeIndex, 3> hs{};
    int k = 0;
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      if (k == 3) throw InvalidInputError("assign_torus_uvs needs a triangle mesh");
      const Point3& p = mesh.point(mesh.target(h));
      double rho = std::sqrt(p.x() * p.x() + p.y() * p.y());
      double a = std::atan2(p.y(), p.x()), b = std::atan2(p.z(), rho - R);
      us[k] = (a < 0 ? a + 2 * kPi : a) / (2 * kPi);
      vs[k] = (b < 0 ? b + 2 * kPi : b) / (2 * kPi);
      hs[k++] = h;
    }
    // Unwrap across the seam: lift small values when the face spans it.
    for (auto* c : {&us, &vs}) {
      double hi = std::max({(*c)[0], (*c)[1], (*c)[2]});
      for (double& x : *c)
        if (hi - x > 0.5) x += 1.0;
    }
    for (int i = 0; i < k; ++i) uv[hs[i]] = {us[i] * repeats_u, vs[i] * repeats_v};
  }
}

void make_cylinder(Mesh& mesh, double radius, double height, int nu, int nv) {
  require(radius > 0 && height > 0, "cylinder radius and height must be positive");
  require(nu >= 3 && nv >= 1, "cylinder needs at least 3 segments around and 1 along");
  std::vector<Point3> p;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      double u = 2 * kPi * i / nu;
      p.emplace_back(radius * std::cos(u), radius * std::sin(u), height * j / nv);
    }
  auto id = [nu](int i, int j) { return j * nu + (i + nu) % nu; };
  std::vector<std::array<int, 3>> t;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      t.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  build(mesh, p, t);
}

void make_open_cone(Mesh& mesh, double radius, double height, int nu, int nv) {
  require(radius > 0 && height > 0, "cone radius and height must be positive");
  require(nu >= 3 && nv >= 1, "cone needs at least 3 segments around and 1 ring");
  std::vector<Point3> p{Point3(0, 0, height)};
  for (int j = 1; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      double u = 2 * kPi * i / nu, f = static_cast<double>(j) / nv;
      p.emplace_back(f * radius * std::cos(u), f * radius * std::sin(u), height * (1 - f));
    }
  auto id = [nu](int i, int j) { return 1 + (j - 1) * nu + (i + nu) % nu; };  // ring j >= 1
  std::vector<std::array<int, 3>> t;
  for (int i = 0; i < nu; ++i) t.push_back({0, id(i, 1), id(i + 1, 1)});
  for (int j = 1; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      t.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1)});
      t.push_back({id(i, j), id(i + 1, j + 1), id(i + 1, j)});
    }
  build(mesh, p, t);
}

void make_ellipsoid(Mesh& mesh, double a, double b, double c, int subdivisions) {
  require(a > 0 && b > 0 && c > 0, "ellipsoid semi-axes must be positive");
  make_icosphere(mesh, subdivisions, 1.0);
  for (VertexIndex v : mesh.vertices()) {
    const Point3& q = mesh.point(v);
    mesh.point(v) = Point3(q.x() * a, q.y() * b, q.z() * c);
  }
}

}  // namespace surftex
