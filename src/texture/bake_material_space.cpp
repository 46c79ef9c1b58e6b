// SPDX-License-Identifier: AGPL-3.0-or-later
// Material-space mapping -> UV atlas (see bake_material_space.h).
#include "texture/bake_material_space.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <string>

#include "geometry/atlas_gutter.h"
#include "geometry/gutter_atlas.h"
#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/timer.h"

namespace surftex {

namespace {

double luminance(const Vec3f& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

}  // namespace

Vec3f material_space_color(const PgpSingularities& sing, const MaterialTile& tile, std::uint32_t face,
                           const std::array<double, 3>& b, bool fix) {
  if (!fix || !sing.singular_face[face]) {
    const StmPoint p = plain_lookup_position(sing, face, b);
    return sample_material_tile(tile, p[0], p[1], p[2]);
  }
  const auto p = singular_lookup_positions(sing, face, b);
  Vec3f out{0.f, 0.f, 0.f};
  for (int k = 0; k < 3; ++k) {
    const Vec3f c = sample_material_tile(tile, p[k][0], p[k][1], p[k][2]);
    for (int d = 0; d < 3; ++d) out[d] += static_cast<float>(b[k]) * c[d];
  }
  return out;
}

MaterialBakeResult bake_material_space(Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile,
                                       const MaterialBakeOptions& opt) {
  if (opt.size < 64 || opt.size > 8192)
    throw InvalidInputError("bake_material_space: size " + std::to_string(opt.size) + " outside 64..8192");
  if (opt.min_mip_size < 1)
    throw InvalidInputError("bake_material_space: min_mip_size must be >= 1, got " + std::to_string(opt.min_mip_size));
  validate_material_tile(tile);
  if (mesh.has_garbage() || sing.charts.size() != mesh.num_faces() || sing.singular_face.size() != mesh.num_faces() ||
      sing.corners.size() != mesh.num_faces())
    throw InvalidInputError("bake_material_space: the singularities cover " + std::to_string(sing.charts.size()) +
                            " faces, the mesh has " + std::to_string(mesh.num_faces()));
  MaterialBakeResult r;
  const int N = opt.size;
  GutterAtlas ga = compute_gutter_atlas(mesh, N, opt.min_mip_size);
  r.seconds_atlas = ga.seconds;
  r.charts = ga.atlas.num_charts;
  r.texels_per_length = ga.atlas.uv_per_length * N;
  r.gutter = ga.gutter;
  r.protected_mip_size = ga.protected_mip_size;
  r.margin = ga.margin;
  r.gutter_violations = ga.violations;
  r.chart = std::move(ga.chart);
  const UvRaster& raster = ga.raster;
  Timer tl;
  r.color = Image(N, N, 3, 0.f);
  r.height = Image(N, N, 1, 0.f);
  tbb::parallel_for(0, N, [&](int y) {
    for (int x = 0; x < N; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * N + x;
      if (raster.triangle[i] < 0) continue;
      const auto& b = raster.bary[i];
      const Vec3f c = material_space_color(sing, tile, static_cast<std::uint32_t>(raster.triangle[i]),
                                           {b[0], b[1], b[2]}, opt.fix_singularities);
      for (int k = 0; k < 3; ++k) r.color.data[3 * i + k] = c[k];
      r.height.data[i] = static_cast<float>(std::clamp(luminance(c), 0.0, 1.0));
    }
  });
  r.seconds_lookup = tl.seconds();
  std::size_t covered = 0;
  for (int c : r.chart) covered += c >= 0;
  r.coverage = static_cast<double>(covered) / (static_cast<double>(N) * N);
  Timer tg;
  r.owner = r.chart;  // the same labels as ga.owner, now with the colours
  std::vector<int> owner2 = r.chart;
  dilate_charts(r.color, r.owner);
  dilate_charts(r.height, owner2);
  r.seconds_gutter += tg.seconds();
  return r;
}

}  // namespace surftex
