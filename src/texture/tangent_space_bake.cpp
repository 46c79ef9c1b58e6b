// SPDX-License-Identifier: AGPL-3.0-or-later
// Object-space normals -> tangent-space normal atlas (see tangent_space_bake.h).
#include "texture/tangent_space_bake.h"
#include "geometry/vec3.h"

#include <cmath>
#include <string>

#include "geometry/atlas_gutter.h"
#include "geometry/bake_vertex_colors.h"
#include "geometry/errors.h"
#include "geometry/gltf_vertex_frames.h"
#include "geometry/mesh.h"

namespace surftex {

namespace {
using D3 = std::array<double, 3>;
using vec3::dot;
D3 unit(const D3& a) {
  const double l = std::sqrt(dot(a, a));
  return l > 0 ? D3{a[0] / l, a[1] / l, a[2] / l} : D3{0, 0, 0};
}
}  // namespace

Image tangent_space_normal_map(const Mesh& mesh, const std::vector<std::array<float, 3>>& object_normals, int size) {
  if (object_normals.size() != mesh.num_vertices())
    throw InvalidInputError("tangent_space_normal_map: " + std::to_string(object_normals.size()) + " normals for " +
                            std::to_string(mesh.num_vertices()) + " vertices");
  const AtlasTexels at = rasterize_atlas(mesh, size);
  const GltfVertexFrames fr = gltf_vertex_frames(mesh);
  Image out(size, size, 3);
  std::vector<int> label = at.chart;
  for (std::size_t i = 0; i < label.size(); ++i) {
    const int t = at.raster.triangle[i];
    if (t < 0) continue;
    D3 n{0, 0, 0}, N{0, 0, 0}, T{0, 0, 0};
    double w = 0;
    for (int c = 0; c < 3; ++c) {
      const double b = at.raster.bary[i][c];
      const std::size_t h = at.corner[t][c];
      const std::size_t v = mesh.target(HalfedgeIndex(static_cast<Mesh::size_type>(h))).idx();
      const std::uint32_t g = fr.corner[h];
      for (int k = 0; k < 3; ++k) {
        n[k] += b * object_normals[v][k];
        N[k] += b * fr.normal[g][k];
        T[k] += b * fr.tangent[g][k];
      }
      w += b * fr.tangent[g][3];
    }
    N = unit(N);
    const double tn = dot(T, N);
    T = unit({T[0] - tn * N[0], T[1] - tn * N[1], T[2] - tn * N[2]});
    const double s = w < 0 ? -1.0 : 1.0;
    const D3 B{s * (N[1] * T[2] - N[2] * T[1]), s * (N[2] * T[0] - N[0] * T[2]), s * (N[0] * T[1] - N[1] * T[0])};
    D3 ts = unit({dot(n, T), dot(n, B), dot(n, N)});
    if (dot(ts, ts) == 0) ts = {0, 0, 1};
    for (int k = 0; k < 3; ++k) out.data[3 * i + k] = static_cast<float>(0.5 * ts[k] + 0.5);
  }
  if (at.covered > 0) dilate_charts(out, label);
  return out;
}

}  // namespace surftex
