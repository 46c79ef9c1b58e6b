// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/subdivision/subdivision_asset.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/timer.h"
#include "geometry/triangulated_copy.h"
#include "texture/pbr_maps.h"
#include "texture/subdivision/subdivision_exemplar_maps.h"
#include "texture/tangent_space_bake.h"

namespace surftex {

SubdivisionAsset::SubdivisionAsset() = default;
SubdivisionAsset::~SubdivisionAsset() = default;
SubdivisionAsset::SubdivisionAsset(SubdivisionAsset&&) noexcept = default;
SubdivisionAsset& SubdivisionAsset::operator=(SubdivisionAsset&&) noexcept = default;

SubdivisionVertexMaps exemplar_maps_at_vertices(const Mesh& mesh, const SubdivisionSynthesisResult& r,
                                                const SubdivisionExemplarMaps& maps, int w, int h) {
  SubdivisionVertexMaps vm;
  if (!maps.height.empty()) {
    const VertexMapValues v = read_map_at_vertices(mesh, r, maps.height, w, h);
    vm.height = vertex_luminance(v);
    vm.filled = v.filled;
  }
  if (!maps.roughness.empty()) {
    const VertexMapValues v = read_map_at_vertices(mesh, r, maps.roughness, w, h);
    vm.roughness = vertex_luminance(v);
    vm.filled = v.filled;
  }
  if (!maps.normal.empty()) {
    const VertexMapValues v = read_map_at_vertices(mesh, r, maps.normal, w, h);
    vm.normal = object_normals_from_map(mesh, v);
    vm.filled = v.filled;
  }
  return vm;
}

namespace {

std::vector<std::array<float, 3>> vertex_colors(const Mesh& mesh) {
  auto col = find(mesh, kVertexColor);
  if (!col.second) throw InvalidInputError("subdivision: the mesh has no vertex colours (kVertexColor)");
  std::vector<std::array<float, 3>> c(mesh.number_of_vertices());
  for (VertexIndex v : mesh.vertices()) c[v.idx()] = {col.first[v][0], col.first[v][1], col.first[v][2]};
  return c;
}

constexpr int kSourceLevels = 4;  // prefiltered reads down to an atlas 8x sparser than the map

// Reads at the input's own resolution where the synthesis reduced the exemplar
// (stacks only), else the map as synthesised.
bool at_input_resolution(const SubdivisionSynthesisResult& r, int w, int h) {
  return !r.pyramid && (w != r.exemplar.width || h != r.exemplar.height);
}

ExemplarReadOptions read_options(const SubdivisionSynthesisResult& r, int w, int h) {
  ExemplarReadOptions o;
  o.levels = kSourceLevels;
  if (at_input_resolution(r, w, h)) {
    o.scale_x = double(w) / r.exemplar.width;
    o.scale_y = double(h) / r.exemplar.height;
  }
  return o;
}

// A grey map's vertex values (the fallback of its source), repeated in RGB.
std::optional<SurfaceExemplarSource> grey_source(const Mesh& mesh, const SubdivisionSynthesisResult& r,
                                                 const Image& map, int w, int h) {
  if (map.empty()) return std::nullopt;
  const std::vector<float> g = vertex_luminance(read_map_at_vertices(mesh, r, map, w, h));
  std::vector<std::array<float, 3>> rgb(g.size());
  for (std::size_t i = 0; i < g.size(); ++i) rgb[i] = {g[i], g[i], g[i]};
  if (at_input_resolution(r, w, h)) return SurfaceExemplarSource(mesh, r, map, std::move(rgb), read_options(r, w, h));
  return SurfaceExemplarSource(mesh, r, resample_as_synthesised(map, r.scale, r.periodic), std::move(rgb),
                               read_options(r, w, h));
}

// The stack level a bake reads: the atlas's texels per map pixel d, level
// round(log2(1 / d)) below one (each level doubles the blur radius).
int bake_level(const SurfaceExemplarSource& src, const SubdivisionAsset& a) {
  const SubdivisionAssetOptions& o = a.options;
  if (!(o.texel_size > 0)) return 0;
  const double atlas_per_unit = a.atlas.atlas.uv_per_length * o.atlas_size;
  const double map_per_unit = src.scale() / o.texel_size;
  const double d = atlas_per_unit / map_per_unit;
  return d >= 1 || !(d > 0) ? 0 : static_cast<int>(std::lround(std::log2(1.0 / d)));
}

}  // namespace

SubdivisionSurfaceSources subdivision_surface_sources(const Mesh& mesh, const SubdivisionSynthesisResult& r,
                                                      const SubdivisionExemplarMaps& maps, int w, int h,
                                                      const Image* input_exemplar) {
  SubdivisionSurfaceSources s;
  if (input_exemplar && (input_exemplar->width != w || input_exemplar->height != h))
    throw InvalidInputError("subdivision_surface_sources: the input exemplar is " +
                            std::to_string(input_exemplar->width) + " x " + std::to_string(input_exemplar->height) +
                            ", not " + std::to_string(w) + " x " + std::to_string(h));
  if (input_exemplar && at_input_resolution(r, w, h))
    s.color.emplace(mesh, r, *input_exemplar, vertex_colors(mesh), read_options(r, w, h));
  else
    s.color.emplace(mesh, r, r.exemplar, vertex_colors(mesh), read_options(r, r.exemplar.width, r.exemplar.height));
  s.height = grey_source(mesh, r, maps.height, w, h);
  s.roughness = grey_source(mesh, r, maps.roughness, w, h);
  return s;
}

nlohmann::json subdivision_fidelity_report(const Mesh& mesh, const SubdivisionSynthesisResult& r,
                                           std::uint64_t seed) {
  SurfaceFidelityOptions fo;
  fo.texel_size = r.scale.texel_size;
  fo.periodic_exemplar = r.periodic;
  fo.seed = seed;
  fo.source = vertex_source_coordinates(r.source);
  try {
    const SurfaceExemplarSource between(mesh, r, r.exemplar, vertex_colors(mesh));
    const SurfaceColorFn color = [between](const SurfacePoint& p) { return between(p.vertex, p.bary); };
    return to_json(surface_fidelity(mesh, r.exemplar, color, frames_from_vertex_directions(mesh), fo));
  } catch (const InvalidInputError& e) {  // e.g. no chart fits a tiny or very thin mesh
    return {{"error", e.what()}};
  }
}

namespace {

// Values of the synthesised mesh -> vertices of the triangle copy.
template <class T>
std::vector<T> on_copy(const std::vector<T>& per_vertex, const std::vector<std::uint32_t>& from) {
  std::vector<T> t(from.size());
  for (std::size_t v = 0; v < from.size(); ++v) t[v] = per_vertex[from[v]];
  return t;
}

// A source read at the copy's texels (corners mapped to the synthesised mesh's
// vertices); grey = its clamped luminance.
BakeResult bake_between(const Mesh& tri, const std::vector<std::uint32_t>& from, const SurfaceExemplarSource& src,
                        int channels, const BakeOptions& bo) {
  const auto value = [&](const std::array<std::size_t, 3>& corner, const std::array<float, 3>& bary, float* out) {
    std::array<std::size_t, 3> v;
    for (int k = 0; k < 3; ++k) v[k] = from[tri.target(HalfedgeIndex(static_cast<Mesh::size_type>(corner[k]))).idx()];
    const auto c = src(v, {bary[0], bary[1], bary[2]});
    if (channels == 3) {
      for (int k = 0; k < 3; ++k) out[k] = c[k];
    } else {
      out[0] = clamped_luminance(c);
    }
  };
  return bake_texel_values(tri, channels, value, bo);
}

// The PBR maps of the baked atlas (file comment).
void bake_maps(SubdivisionAsset& a, const SubdivisionVertexMaps& maps, const std::vector<std::uint32_t>& from) {
  const Mesh& tri = *a.mesh;
  const SubdivisionAssetOptions& o = a.options;
  BakeOptions bo;
  bo.size = o.atlas_size;
  a.height_from_exemplar = !maps.height.empty() || maps.between.height.has_value();
  a.normal_from_exemplar = !maps.normal.empty();
  if (maps.between.height)
    a.height = bake_between(tri, from, maps.between.height->at_level(bake_level(*maps.between.height, a)), 1, bo).image;
  else
    a.height = maps.height.empty() ? height_from_luminance(a.color.image)
                                   : bake_vertex_values(tri, on_copy(maps.height, from), 1, bo).image;
  a.atlas_texels_per_exemplar_texel = a.atlas.atlas.uv_per_length * o.atlas_size / o.texels_per_length;
  a.normal = maps.normal.empty()
                 ? normal_map_from_height(a.height, a.color.chart, o.bump * a.atlas_texels_per_exemplar_texel)
                 : tangent_space_normal_map(tri, on_copy(maps.normal, from), o.atlas_size);
  if (maps.between.roughness)
    a.metallic_roughness = metallic_roughness_from_roughness(
        bake_between(tri, from, maps.between.roughness->at_level(bake_level(*maps.between.roughness, a)), 1, bo).image);
  else if (!maps.roughness.empty())
    a.metallic_roughness =
        metallic_roughness_from_roughness(bake_vertex_values(tri, on_copy(maps.roughness, from), 1, bo).image);
}

}  // namespace

int default_subdivision_atlas_size(std::size_t vertices) {
  constexpr double kCoverage = 0.15;
  int n = 1024;
  while (n < 4096 && kCoverage * n * n < static_cast<double>(vertices)) n *= 2;
  return n;
}

SubdivisionAsset bake_subdivision_asset(const Mesh& mesh, const SubdivisionVertexMaps& maps,
                                        const SubdivisionAssetOptions& options) {
  if (!(options.texels_per_length > 0))
    throw InvalidInputError("bake_subdivision_asset: texels_per_length " + std::to_string(options.texels_per_length) +
                            " must be > 0");
  Timer t;
  SubdivisionAsset a;
  a.options = options;
  a.mesh = std::make_unique<Mesh>();
  const std::vector<std::uint32_t> from = triangulated_copy(mesh, *a.mesh);
  Mesh& tri = *a.mesh;
  a.atlas = compute_gutter_atlas(tri, options.atlas_size, 64, options.max_chart_faces);
  BakeOptions bo;
  bo.size = options.atlas_size;
  a.color_between_vertices = maps.between.color.has_value();
  if (maps.between.color) {
    const SurfaceExemplarSource src = maps.between.color->at_level(bake_level(*maps.between.color, a));
    a.color_stack_level = src.level();
    a.color_map_scale = src.scale();
    a.color = bake_between(tri, from, src, 3, bo);
  } else {
    a.color = bake_vertex_colors(tri, bo);
  }
  bake_maps(a, maps, from);
  if (options.texel_size > 0) {
    a.seam = surface_seam_ratio(tri, atlas_color_source(tri, a.color.image), seam_edges_from_corner_uv(tri),
                                options.texel_size);
    a.seam_measured = true;
  }
  a.seconds = t.seconds();
  return a;
}

nlohmann::json to_json(const SubdivisionAsset& a) {
  const int size = a.options.atlas_size;
  const double N2 = double(size) * size;
  const GutterAtlas& ga = a.atlas;
  nlohmann::json j = {{"charts", ga.atlas.num_charts}, {"max_chart_faces", a.options.max_chart_faces},
                      {"size", size},
                      {"coverage", double(a.color.covered) / N2},
                      {"gutter", ga.gutter},
                      {"gutter_violations", ga.violations},
                      {"margin", ga.margin},
                      {"protected_mip_size", ga.protected_mip_size},
                      {"mean_area_distortion", ga.atlas.mean_area_distortion},
                      {"flipped_faces", ga.atlas.flipped_faces},
                      {"bump", a.options.bump},
                      {"atlas_texels_per_exemplar_texel", a.atlas_texels_per_exemplar_texel},
                      {"normal_source", a.normal_from_exemplar ? "exemplar_normal" : "height"},
                      {"height_source", a.height_from_exemplar ? "exemplar_height" : "luminance"},
                      {"color_source", a.color_between_vertices ? "exemplar_between_vertices" : "vertex_colors"},
                      {"color_stack_level", a.color_stack_level},
                      {"color_map_texels_per_synthesis_texel", a.color_map_scale},
                      {"roughness", !a.metallic_roughness.empty()},
                      {"seconds", {{"bake", a.seconds}, {"charts", a.atlas.seconds}}}};
  if (a.seam_measured) j["seam"] = to_json(a.seam);
  return j;
}

}  // namespace surftex
