// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/embed_outside_shell.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "geometry/errors.h"
#include "shell/triangle_distance.h"

namespace surftex {

namespace {
// Boundary triangles of the union of the shell's tets, outward oriented:
// bottom (layer 0) first, then top (layer 1), then mesh-border walls.
struct ShellSurface {
  ElementMesh mesh;
  std::vector<int> kind;  // 0 bottom, 1 top, 2 wall
  std::vector<int> face;  // base face of the owning prism
};

ShellSurface shell_surface(const ShellSpace& s) {
  // Faces used by one tet of a chart (shell vertices are per chart, so the key
  // by shell vertex ids is per chart).
  std::map<std::array<int, 3>, std::pair<std::array<int, 3>, int>> once;  // sorted -> (oriented, tet)
  std::map<std::array<int, 3>, int> count;
  for (std::size_t ti = 0; ti < s.tets.size(); ++ti) {
    const Tet& t = s.tets[ti];
    const std::array<std::array<int, 3>, 4> fs = {std::array<int, 3>{t[0], t[2], t[1]}, {t[0], t[1], t[3]},
                                                   {t[0], t[3], t[2]}, {t[1], t[2], t[3]}};
    for (const auto& f : fs) {
      std::array<int, 3> key = f;
      std::sort(key.begin(), key.end());
      if (++count[key] == 1) once[key] = {f, static_cast<int>(ti)};
    }
  }
  // Walls between two charts: the same (base vertex, layer) triple in two charts.
  auto vkey = [&](int i) { return 2 * s.base_vertex[static_cast<std::size_t>(i)] + s.layer[static_cast<std::size_t>(i)]; };
  std::map<std::array<int, 3>, int> walls;
  std::vector<std::pair<std::array<int, 3>, int>> faces[3];
  for (const auto& [key, val] : once) {
    if (count[key] != 1) continue;
    const auto& f = val.first;
    const int l0 = s.layer[static_cast<std::size_t>(f[0])], l1 = s.layer[static_cast<std::size_t>(f[1])],
              l2 = s.layer[static_cast<std::size_t>(f[2])];
    const int kind = (l0 == l1 && l1 == l2) ? l0 : 2;
    if (kind == 2) {
      std::array<int, 3> k{vkey(f[0]), vkey(f[1]), vkey(f[2])};
      std::sort(k.begin(), k.end());
      ++walls[k];
    }
    faces[kind].push_back(val);
  }
  ShellSurface out;
  out.mesh.points = s.shell_points;
  for (int kind = 0; kind < 3; ++kind)
    for (const auto& [f, ti] : faces[kind]) {
      if (kind == 2) {
        std::array<int, 3> k{vkey(f[0]), vkey(f[1]), vkey(f[2])};
        std::sort(k.begin(), k.end());
        if (walls[k] > 1) continue;
      }
      out.mesh.tris.push_back({f[0], f[1], f[2]});
      out.kind.push_back(kind);
      out.face.push_back(s.tet_face[static_cast<std::size_t>(ti)]);
    }
  return out;
}
}  // namespace

OutsideShellResult measure_outside_shell(const std::vector<Vec3>& points, const ShellSpace& shell,
                                         const ShellMap& map, const OutsideShellOptions& opt) {
  if (shell.tets.empty()) throw InvalidInputError("measure_outside_shell: the shell has no tetrahedra");
  if (!(opt.tolerance >= 0) || !std::isfinite(opt.tolerance))
    throw InvalidInputError("measure_outside_shell: tolerance must be >= 0 (" + std::to_string(opt.tolerance) + ")");
  OutsideShellResult r;
  r.points = points.size();
  const std::size_t n = points.size();
  std::vector<char> in(n, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t i = rg.begin(); i != rg.end(); ++i) in[i] = map.locate_shell(points[i]).inside ? 1 : 0;
  });
  std::vector<int> candidates;
  for (std::size_t i = 0; i < n; ++i)
    if (!in[i]) candidates.push_back(static_cast<int>(i));
  if (candidates.empty()) return r;
  const ShellSurface surf = shell_surface(shell);
  const TriangleDistance dist(surf.mesh);
  std::vector<TriangleDistance::Hit> hits(candidates.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size()), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t k = rg.begin(); k != rg.end(); ++k)
      hits[k] = dist.closest(points[static_cast<std::size_t>(candidates[k])]);
  });
  const double limit = opt.tolerance * shell.height;
  double sum = 0;
  for (std::size_t k = 0; k < candidates.size(); ++k) {  // sequential: deterministic sums
    const TriangleDistance::Hit& h = hits[k];
    if (h.tri < 0 || !(h.distance > limit)) continue;
    ++r.outside;
    const int kind = surf.kind[static_cast<std::size_t>(h.tri)];
    (kind == 0 ? r.below : kind == 1 ? r.above : r.side)++;
    r.max_distance = std::max(r.max_distance, h.distance);
    sum += h.distance;
    r.outside_points.push_back(candidates[k]);
    r.nearest_face.push_back(surf.face[static_cast<std::size_t>(h.tri)]);
  }
  if (r.outside > 0) r.mean_distance = sum / static_cast<double>(r.outside);
  return r;
}

}  // namespace surftex
