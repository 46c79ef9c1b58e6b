// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/patches/patch_texture.h"

#include <algorithm>
#include <array>
#include <ctime>

#include "geometry/mesh.h"
#include "geometry/timer.h"
#include "texture/patches/patch_exemplar_maps.h"
#include "texture/pbr_maps.h"
#include "texture/surface_fidelity.h"

namespace surftex {
namespace {

// Steps 2-3: the exemplar maps' atlases first, the colour atlas last (its
// kCornerUV stay on the mesh), then the maps' fallbacks.
void pack_atlases(Mesh& mesh, const std::vector<Image>& exemplars, const PatchExemplarMaps& maps,
                  const PatchTextureOptions& o, PatchTextureResult& r) {
  const PatchSynthesisResult& s = r.synthesis;
  const std::array<int, 2> ex_size{exemplars[0].width, exemplars[0].height};
  auto map_atlas = [&](const Image& m, bool normal) {
    return pack_patch_atlas(mesh, s.flat, resample_patch_map(s, m, ex_size, o.synthesis.el, normal), o.synthesis.atlas).image;
  };
  if (o.pbr_maps) {
    if (!maps.height.empty()) {
      r.height = map_atlas(maps.height, false);
      if (r.height.channels != 1) r.height = height_from_luminance(r.height);
    }
    if (!maps.normal.empty()) r.normal = map_atlas(maps.normal, true);
    if (!maps.roughness.empty())
      r.metallic_roughness = metallic_roughness_from_roughness(height_from_luminance(map_atlas(maps.roughness, false)));
  }
  r.atlas = pack_patch_atlas(mesh, s.flat, s.images, o.synthesis.atlas);
  if (!o.pbr_maps) return;
  r.height_from_exemplar = !r.height.empty();
  r.normal_from_exemplar = !r.normal.empty();
  if (r.height.empty()) r.height = height_from_luminance(r.atlas.image);
  if (r.normal.empty()) r.normal = normal_map_from_height(r.height, r.atlas.chart, o.bump);
}

}  // namespace

PatchTextureResult synthesize_patch_texture(Mesh& mesh, const std::vector<Image>& exemplars,
                                            const PatchExemplarMaps& maps, const PatchTextureOptions& o) {
  Timer total;
  PatchTextureResult r;
  r.bump = o.bump;
  r.synthesis_options_resolution = o.synthesis.flatten.resolution;
  const std::clock_t c0 = std::clock();
  r.synthesis = synthesize_patches(mesh, exemplars, o.synthesis);  // step 1
  r.patch_resolution = r.synthesis.resolution;
  r.requested_resolution = r.synthesis.resolution_wanted;
  r.cpu_seconds_synthesis = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  Timer t;
  pack_atlases(mesh, exemplars, maps, o, r);  // steps 2-3
  r.seconds_atlas = t.seconds();
  t.reset();
  SeamRatioOptions so;  // step 4
  so.seed = o.synthesis.seed;
  r.seam = patch_seam_ratio(mesh, r.synthesis.flat, r.atlas.image, so);
  r.seam_step_texels = so.step_texels;
  r.seconds_seam = t.seconds();
  r.seconds_total = total.seconds();
  if (o.fidelity)  // step 5
    r.fidelity = atlas_fidelity_report(mesh, exemplars[0], r.atlas.image, r.synthesis.flat.texel,
                                       o.synthesis.field != PatchField::None, o.synthesis.seed);
  return r;
}

nlohmann::json to_json(const PatchTextureResult& t) {
  const PatchSynthesisResult& r = t.synthesis;
  nlohmann::json j;
  j["patches"] = r.flat.patches.size();
  j["greedy_patches"] = r.partition.greedy_patches;
  j["split_patches"] = r.split_patches;
  j["merged_patches"] = r.partition.merged_patches;
  j["reassigned_faces"] = r.partition.reassigned_faces;
  j["max_normal_deviation_deg"] = r.partition.max_deviation_deg;
  j["patch_resolution"] = t.patch_resolution;
  if (t.patch_resolution != t.requested_resolution)  // lowered to fit one atlas
    j["patch_resolution_requested"] = t.requested_resolution;
  if (r.resolution_wanted != t.synthesis_options_resolution)  // raised for the texture-scale floor
    j["patch_resolution_raised_from"] = t.synthesis_options_resolution;
  j["exemplar_widths"] = {{"across_longest_side", r.exemplar_widths},
                          {"at_patch_resolution", r.exemplar_widths_partition}};
  j["texel_size"] = r.flat.texel;
  j["dropped_boundary_triangles"] = r.flat.dropped_boundary;
  j["texels_synthesized"] = r.texels;
  j["texels_seeded"] = r.seeded;
  j["known_boundary_pixels"] = r.known_boundary;
  j["pass1"] = {{"candidates", r.pass1_candidates}, {"widened_pixels", r.pass1_widened}};
  j["texels_per_second"] = r.texels / std::max(r.seconds_synthesis, 1e-9);
  j["seconds"] = {{"partition", r.seconds_partition}, {"field", r.seconds_field},
                  {"flatten", r.seconds_flatten},     {"synthesis", r.seconds_synthesis},
                  {"atlas", t.seconds_atlas},         {"seam_metric", t.seconds_seam},
                  {"total", t.seconds_total}};
  j["cpu_seconds_synthesis"] = t.cpu_seconds_synthesis;  // all threads: steadier than wall on a shared machine
  j["synthesis_share"] = r.seconds_synthesis / std::max(r.seconds_total, 1e-9);
  j["seam"] = {{"ratio", t.seam.ratio},
               {"mean_jump_across", t.seam.mean_across},
               {"mean_jump_within", t.seam.mean_within},
               {"pairs_across", t.seam.pairs_across},
               {"pairs_within", t.seam.pairs_within},
               {"step_texels", t.seam_step_texels}};
  j["atlas"] = {{"width", t.atlas.image.width}, {"height", t.atlas.image.height}, {"gutter", t.atlas.gutter},
                {"protected_mip_size", t.atlas.protected_mip_size}, {"bump", t.bump},
                {"normal_source", t.normal_from_exemplar ? "exemplar_normal" : "height"},
                {"height_source", t.height_from_exemplar ? "exemplar_height" : "luminance"},
                {"roughness", !t.metallic_roughness.empty()}};
  j["fidelity"] = t.fidelity;
  return j;
}

}  // namespace surftex
