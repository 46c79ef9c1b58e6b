// SPDX-License-Identifier: AGPL-3.0-or-later
// The patch texture driver (Gorla et al. 2003 plus atlas, maps, seam and
// fidelity figures): what it returns, what it skips, the report's keys.
#include <gtest/gtest.h>

#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "texture/patches/patch_texture.h"
#include "texture/procedural_texture.h"

namespace surftex {
namespace {

PatchTextureOptions small_options() {
  PatchTextureOptions o;
  o.synthesis.flatten.resolution = 16;
  o.synthesis.flatten.margin = 2;
  o.synthesis.partition.max_faces = 40;
  o.synthesis.el.window = 5;
  o.synthesis.el.rotations = 4;
  return o;
}

TEST(PatchTexture, AtlasMapsAndReport) {
  Mesh m;
  make_icosphere(m, 1);
  const Image ex = make_stripes(32, 6, 0);
  const PatchTextureResult r = synthesize_patch_texture(m, {ex}, {}, small_options());
  ASSERT_FALSE(r.atlas.image.empty());
  EXPECT_EQ(r.height.width, r.atlas.image.width);
  EXPECT_EQ(r.normal.width, r.atlas.image.width);
  EXPECT_EQ(r.normal.channels, 3);
  EXPECT_TRUE(r.metallic_roughness.empty());
  EXPECT_FALSE(r.height_from_exemplar);
  EXPECT_TRUE(find(m, kCornerUV).second) << "the colour atlas's uvs stay on the mesh";
  EXPECT_GT(r.seam.pairs_within, 0u);
  EXPECT_FALSE(r.fidelity.is_null());
  const nlohmann::json j = to_json(r);
  for (const char* k : {"patches", "greedy_patches", "split_patches", "merged_patches", "reassigned_faces",
                        "max_normal_deviation_deg", "patch_resolution", "texel_size", "dropped_boundary_triangles",
                        "texels_synthesized", "texels_seeded", "known_boundary_pixels", "texels_per_second",
                        "seconds", "synthesis_share", "seam", "atlas", "fidelity", "pass1"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["patch_resolution"], 16);
  EXPECT_EQ(j["patches"], r.synthesis.flat.patches.size());
  EXPECT_EQ(j["atlas"]["width"], r.atlas.image.width);
  EXPECT_EQ(j["atlas"]["normal_source"], "height");
  EXPECT_EQ(j["atlas"]["roughness"], false);
  EXPECT_EQ(j["seam"]["ratio"], r.seam.ratio);
  // The approximate first pass's work, summed over the patches: every
  // synthesised texel ranked at least one candidate.
  EXPECT_GE(j["pass1"]["candidates"].get<std::size_t>(), r.synthesis.texels - r.synthesis.seeded);
  EXPECT_EQ(j["pass1"]["candidates"], r.synthesis.pass1_candidates);
  EXPECT_EQ(j["pass1"]["widened_pixels"], r.synthesis.pass1_widened);
  for (const char* k : {"partition", "field", "flatten", "synthesis", "atlas", "seam_metric", "total"})
    EXPECT_TRUE(j["seconds"].contains(k)) << k;
}

// Exemplar maps go through the same synthesis into atlases of the colour's size.
TEST(PatchTexture, ExemplarMapsGiveTheMaps) {
  Mesh m;
  make_icosphere(m, 1);
  const Image ex = make_stripes(32, 6, 0);
  PatchExemplarMaps maps;
  maps.height = Image(32, 32, 1);
  for (float& v : maps.height.data) v = 0.5f;
  maps.roughness = maps.height;
  const PatchTextureResult r = synthesize_patch_texture(m, {ex}, maps, small_options());
  EXPECT_TRUE(r.height_from_exemplar);
  EXPECT_FALSE(r.normal_from_exemplar);
  ASSERT_FALSE(r.metallic_roughness.empty());
  EXPECT_EQ(r.metallic_roughness.width, r.atlas.image.width);
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["atlas"]["height_source"], "exemplar_height");
  EXPECT_EQ(j["atlas"]["roughness"], true);
}

// The benchmark's setting: colour atlas and seam figure only.
TEST(PatchTexture, WithoutMapsAndFidelity) {
  Mesh m;
  make_icosphere(m, 1);
  PatchTextureOptions o = small_options();
  o.pbr_maps = false;
  o.fidelity = false;
  const PatchTextureResult r = synthesize_patch_texture(m, {make_stripes(32, 6, 0)}, {}, o);
  EXPECT_FALSE(r.atlas.image.empty());
  EXPECT_TRUE(r.height.empty());
  EXPECT_TRUE(r.normal.empty());
  EXPECT_TRUE(r.fidelity.is_null());
  EXPECT_GT(r.seam.pairs_within, 0u);
}

}  // namespace
}  // namespace surftex
