// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/render_material_space.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/render_mesh.h"
#include "geometry/errors.h"

namespace surftex {

namespace {

struct V3 {
  double x = 0, y = 0, z = 0;
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline V3 unit(V3 a) {
  const double l = std::sqrt(dot(a, a));
  return l > 0 ? (1.0 / l) * a : a;
}
inline V3 v3(const Vec3f& a) { return {a[0], a[1], a[2]}; }

double luminance(const Vec3f& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

}  // namespace

Vec3f light_direction_world(const Camera& camera, const Vec3f& l) {
  const V3 fwd = unit(v3(camera.target) - v3(camera.eye));
  const V3 right = unit(cross(fwd, v3(camera.up)));
  const V3 up = cross(right, fwd);
  const V3 w = unit(l[0] * right + l[1] * up + (-l[2]) * fwd);
  return {static_cast<float>(w.x), static_cast<float>(w.y), static_cast<float>(w.z)};
}

FragmentCallback material_space_fragment(const RenderMesh& mesh, const PgpSingularities& sing,
                                         const MaterialTile& tile, const MaterialRenderOptions& opt) {
  validate_material_tile(tile);
  if (mesh.triangle_face.size() != mesh.triangles.size())
    throw InvalidInputError("material_space_fragment: the render mesh has no triangle_face map (" +
                            std::to_string(mesh.triangle_face.size()) + " entries for " +
                            std::to_string(mesh.triangles.size()) + " triangles)");
  for (int f : mesh.triangle_face)
    if (f < 0 || static_cast<std::size_t>(f) >= sing.charts.size() || sing.charts.size() != sing.singular_face.size())
      throw InvalidInputError("material_space_fragment: triangle_face names face " + std::to_string(f) +
                              " but the singularities cover " + std::to_string(sing.charts.size()) + " faces");
  if (!(opt.bump_strength >= 0) || !std::isfinite(opt.bump_strength))
    throw InvalidInputError("material_space_fragment: bump_strength must be >= 0, got " +
                            std::to_string(opt.bump_strength));
  if (!(opt.ambient >= 0 && opt.ambient <= 1))
    throw InvalidInputError("material_space_fragment: ambient must be in [0,1], got " + std::to_string(opt.ambient));
  const bool blended = opt.lookup == MaterialRenderOptions::Lookup::Blended;

  if (opt.output == MaterialRenderOptions::Output::Color) {
    return [&mesh, &sing, &tile, blended](int tri, const Vec3f& b) -> Vec3f {
      const auto face = static_cast<std::uint32_t>(mesh.triangle_face[tri]);
      const std::array<double, 3> bary{b[0], b[1], b[2]};
      if (!blended || !sing.singular_face[face]) {
        const StmPoint p = plain_lookup_position(sing, face, bary);
        return sample_material_tile(tile, p[0], p[1], p[2]);
      }
      const auto p = singular_lookup_positions(sing, face, bary);
      Vec3f out{0.f, 0.f, 0.f};
      for (int k = 0; k < 3; ++k) {
        const Vec3f c = sample_material_tile(tile, p[k][0], p[k][1], p[k][2]);
        for (int d = 0; d < 3; ++d) out[d] += b[k] * c[d];
      }
      return out;
    };
  }

  const V3 light = unit(v3(opt.light_world));
  const double strength = opt.bump_strength;
  const double h = 1.0 / tile.size;
  const Vec3f albedo = opt.base_color;
  const float ambient = opt.ambient;
  return [&mesh, &sing, &tile, blended, light, strength, h, albedo, ambient](int tri, const Vec3f& b) -> Vec3f {
    const auto face = static_cast<std::uint32_t>(mesh.triangle_face[tri]);
    const auto& t = mesh.triangles[tri];
    const V3 P[3] = {v3(mesh.positions[t[0]]), v3(mesh.positions[t[1]]), v3(mesh.positions[t[2]])};
    const V3 fn = cross(P[1] - P[0], P[2] - P[0]);
    const double A2 = std::sqrt(dot(fn, fn));
    const V3 nf = unit(fn);
    V3 n = nf;
    if (mesh.vertex_normals.size() == mesh.positions.size()) {
      n = unit(b[0] * v3(mesh.vertex_normals[t[0]]) + b[1] * v3(mesh.vertex_normals[t[1]]) +
               b[2] * v3(mesh.vertex_normals[t[2]]));
      if (dot(n, n) == 0) n = nf;
    }
    // Perturbed normal for one chart (three corner (s,t,m)).
    auto perturbed = [&](const std::array<StmPoint, 3>& c) -> V3 {
      V3 gs{}, gt{};
      if (A2 > 0) {
        for (int k = 0; k < 3; ++k) {
          const V3 e = P[(k + 2) % 3] - P[(k + 1) % 3];
          const V3 r = (1.0 / A2) * cross(nf, e);
          gs = gs + c[k][0] * r;
          gt = gt + c[k][1] * r;
        }
      }
      StmPoint p{};
      for (int d = 0; d < 3; ++d) p[d] = b[0] * c[0][d] + b[1] * c[1][d] + b[2] * c[2][d];
      const double dhds = (luminance(sample_material_tile(tile, p[0] + h, p[1], p[2])) -
                           luminance(sample_material_tile(tile, p[0] - h, p[1], p[2]))) / (2 * h);
      const double dhdt = (luminance(sample_material_tile(tile, p[0], p[1] + h, p[2])) -
                           luminance(sample_material_tile(tile, p[0], p[1] - h, p[2]))) / (2 * h);
      return n - strength * (dhds * unit(gs) + dhdt * unit(gt));
    };
    V3 np;
    if (!blended || !sing.singular_face[face]) {
      np = perturbed(sing.corners[face]);
    } else {
      const FaceCharts& ch = sing.charts[face];
      for (int k = 0; k < 3; ++k) np = np + b[k] * unit(perturbed(ch[k]));
    }
    np = unit(np);
    const float lambert = static_cast<float>(std::abs(dot(np, light)));
    const float s = ambient + (1 - ambient) * lambert;
    return {albedo[0] * s, albedo[1] * s, albedo[2] * s};
  };
}


MaterialViews render_material_views(const Mesh& mesh, const PgpSingularities& sing, const MaterialTile& tile,
                                    int size, float azimuth_deg, float elevation_deg, double bump) {
  RenderMesh rm = make_render_mesh(mesh);
  const Camera cam = fit_camera(bounding_box(rm), azimuth_deg, elevation_deg);
  RenderOptions ro;
  ro.width = ro.height = size;
  ro.color_source = RenderOptions::ColorSource::Callback;
  MaterialViews o;
  MaterialRenderOptions mo;
  mo.lookup = MaterialRenderOptions::Lookup::Plain;
  ro.callback = material_space_fragment(rm, sing, tile, mo);
  o.plain = render(rm, cam, ro).color;
  mo.lookup = MaterialRenderOptions::Lookup::Blended;
  ro.callback = material_space_fragment(rm, sing, tile, mo);
  o.fixed = render(rm, cam, ro).color;
  mo.output = MaterialRenderOptions::Output::NormalMap;
  mo.bump_strength = bump;
  mo.light_world = light_direction_world(cam, ro.light_direction);
  ro.callback = material_space_fragment(rm, sing, tile, mo);
  ro.shade = false;
  o.normal = render(rm, cam, ro).color;
  return o;
}

}  // namespace surftex
