// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/mesh_quilting.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/timer.h"
#include "shell/swatch.h"

namespace surftex {

QuiltResult quilt_plane(const Swatch& swatch, double width, double height, Mesh& out, const PlanarQuiltOptions& opt) {
  if (!(width > 0) || !std::isfinite(width)) throw InvalidInputError("quilt_plane: width must be > 0 (" + std::to_string(width) + ")");
  if (!(height > 0) || !std::isfinite(height))
    throw InvalidInputError("quilt_plane: height must be > 0 (" + std::to_string(height) + ")");
  if (!(opt.cell_size >= 0)) throw InvalidInputError("quilt_plane: cell_size must be >= 0 (" + std::to_string(opt.cell_size) + ")");
  Timer timer;
  QuiltResult res;
  const double c = opt.cell_size > 0 ? opt.cell_size : std::max(swatch.length(), swatch.width()) / 10.0;
  int sx = 0, sy = 0;
  swatch_cells(swatch, c, "quilt_plane", sx, sy);
  const int r = opt.subpatch_radius > 0 ? opt.subpatch_radius : std::max(1, std::min(sx, sy) / 4);
  if (2 * r + 1 > std::min(sx, sy))
    throw InvalidInputError("quilt_plane: subpatch_radius " + std::to_string(r) + " too large for a swatch of " +
                            std::to_string(sx) + "x" + std::to_string(sy) + " cells");
  // Domain cells plus a margin of one swatch on each side.
  const int dx = static_cast<int>(std::ceil(width / c - 1e-9)), dy = static_cast<int>(std::ceil(height / c - 1e-9));
  QuiltGrid grid;
  grid.cell = c;
  grid.nx = dx + 2 * sx;
  grid.ny = dy + 2 * sy;
  grid.x0 = -sx * c;
  grid.y0 = -sy * c;
  grid.processed.assign(static_cast<std::size_t>(grid.nx) * grid.ny, 0);
  auto in_domain = [&](int i, int j) { return i >= sx && i < sx + dx && j >= sy && j < sy + dy; };

  TriangleDistance tree(swatch.mesh);
  std::mt19937_64 rng(opt.seed);
  std::vector<ElementMesh> elements;
  std::vector<char> alive;
  const int total = dx * dy;
  for (;;) {
    // 2.3 Seed finding.
    int seed = -1, best = -1, done = 0;
    for (int j = sy; j < sy + dy; ++j)
      for (int i = sx; i < sx + dx; ++i) {
        if (grid.processed[j * grid.nx + i]) {
          ++done;
          continue;
        }
        int n = 0;
        for (int b = -1; b <= 1; ++b)
          for (int a = -1; a <= 1; ++a)
            if ((a || b) && grid.processed[(j + b) * grid.nx + i + a]) ++n;
        if (n > best) best = n, seed = j * grid.nx + i;
      }
    report_progress(opt.progress, "quilt", static_cast<double>(done) / total);
    if (seed < 0) break;
    const int si = seed % grid.nx, sj = seed / grid.nx;
    grid.subpatch.assign(grid.processed.size(), 0);
    for (int j = sj - r; j <= sj + r; ++j)
      for (int i = si - r; i <= si + r; ++i)
        if (in_domain(i, j)) grid.subpatch[j * grid.nx + i] = 1;
    QuiltStepStats st;
    quilt_step(swatch, tree, grid, elements, alive, rng, opt.step, st);
    res.stats.add(st);
    ++res.steps;
  }
  // Keep elements whose vertex centroid lies in the rectangle.
  std::vector<ElementMesh> kept;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    if (!alive[e] || elements[e].tris.empty()) continue;
    double cx = 0, cy = 0;
    for (const P3& p : elements[e].points) cx += p[0], cy += p[1];
    cx /= static_cast<double>(elements[e].points.size());
    cy /= static_cast<double>(elements[e].points.size());
    if (cx >= 0 && cx <= width && cy >= 0 && cy <= height) kept.push_back(std::move(elements[e]));
  }
  mesh_from_elements(kept, out);
  res.elements = label_elements(out);
  res.faces = out.number_of_faces();
  res.vertices = out.number_of_vertices();
  res.seconds = timer.seconds();
  report_progress(opt.progress, "quilt", 1.0);
  return res;
}

}  // namespace surftex
