// SPDX-License-Identifier: AGPL-3.0-or-later
// Adaptive sqrt(2)-subdivision (Bangay & Morkel 2006, section 3.2.2).
#include "texture/subdivision/adaptive_sqrt2_subdivide.h"

#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/polygon_util.h"

namespace surftex {

double face_area_std_percent(const Mesh& mesh) {
  double s = 0, s2 = 0;
  std::size_t n = 0;
  for (FaceIndex f : mesh.faces()) {
    const double a = polygon_area(mesh, f);
    s += a;
    s2 += a * a;
    ++n;
  }
  if (n == 0) throw InvalidInputError("face_area_std_percent: the mesh has no faces");
  const double mean = s / n;
  if (!(mean > 0)) return 0.0;
  const double var = std::max(0.0, s2 / n - mean * mean);
  return 100.0 * std::sqrt(var) / mean;
}

AdaptiveSubdivideResult adaptive_sqrt2_subdivide(Mesh& mesh, const AdaptiveSubdivideOptions& opt) {
  if (!(opt.factor > 0) || !std::isfinite(opt.factor))
    throw InvalidInputError("adaptive_sqrt2_subdivide: factor must be > 0 (got " + std::to_string(opt.factor) + ")");
  if (opt.steps < 0)
    throw InvalidInputError("adaptive_sqrt2_subdivide: steps must be >= 0 (got " + std::to_string(opt.steps) + ")");
  if (mesh.number_of_faces() == 0) throw InvalidInputError("adaptive_sqrt2_subdivide: the mesh has no faces");
  if (mesh.has_garbage()) mesh.collect_garbage();
  AdaptiveSubdivideResult res;
  res.area_std_percent.push_back(face_area_std_percent(mesh));
  for (int step = 0; step < opt.steps; ++step) {
    std::vector<double> area(mesh.number_of_faces());
    double sum = 0;
    for (FaceIndex f : mesh.faces()) sum += (area[f.idx()] = polygon_area(mesh, f));
    const double thr = opt.factor * sum / static_cast<double>(area.size());
    std::vector<char> sel(area.size(), 0);
    std::size_t count = 0;
    for (std::size_t i = 0; i < area.size(); ++i)
      if (area[i] > thr) sel[i] = 1, ++count;
    if (count == 0) break;
    sqrt2_subdivide_selected(mesh, sel, opt.split);
    res.faces_refined.push_back(count);
    res.area_std_percent.push_back(face_area_std_percent(mesh));
    ++res.steps_done;
  }
  return res;
}

}  // namespace surftex
