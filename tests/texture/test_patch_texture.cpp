// SPDX-License-Identifier: AGPL-3.0-or-later
// The patch texture driver (Gorla et al. 2003 plus atlas, maps, seam and
// fidelity figures): what it returns, what it skips, the report's keys.
#include <gtest/gtest.h>

#include "geometry/errors.h"
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
  o.synthesis.min_exemplar_widths = 0;  // the small resolution as given
  return o;
}

// The widths of the exemplar across the mesh's longest bounding-box side as
// the result's texel shows them.
double widths_shown(const Mesh& m, const PatchTextureResult& r, int exemplar_width) {
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (VertexIndex v : m.vertices()) {
    const double c[3] = {m.point(v).x(), m.point(v).y(), m.point(v).z()};
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], c[d]), hi[d] = std::max(hi[d], c[d]);
  }
  const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
  return longest / (r.synthesis.flat.texel * exemplar_width);
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
  EXPECT_FALSE(j.contains("patch_resolution_raised_from"));
  EXPECT_NEAR(j["exemplar_widths"]["across_longest_side"].get<double>(), widths_shown(m, r, ex.width), 1e-9);
  EXPECT_EQ(j["exemplar_widths"]["at_patch_resolution"], j["exemplar_widths"]["across_longest_side"]);
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

// The texture-scale floor (PatchSynthesisOptions::min_exemplar_widths,
// default 1): a patch resolution whose texel would show less than one width
// of the exemplar across the mesh (a 512 px exemplar on the coarse double
// torus showed 0.41, every texel magnified) is raised until it shows one, the
// same on a mesh 100 times larger; off, or with the resolution given
// (fit_resolution false), the resolution stays.
TEST(PatchTexture, TextureScaleFloorShowsAWholeExemplarAcrossAnyMesh) {
  const Image ex = make_stripes(64, 8, 0);
  for (double scale : {1.0, 100.0}) {
    Mesh m;
    make_icosphere(m, 1, scale);
    PatchTextureOptions o = small_options();
    o.fidelity = false;
    PatchTextureOptions off = o;
    o.synthesis.min_exemplar_widths = PatchSynthesisOptions{}.min_exemplar_widths;
    ASSERT_EQ(o.synthesis.min_exemplar_widths, 1.0);
    Mesh m_off = m, m_given = m;
    const PatchTextureResult r = synthesize_patch_texture(m, {ex}, {}, o);
    const PatchTextureResult r_off = synthesize_patch_texture(m_off, {ex}, {}, off);
    PatchTextureOptions given = o;
    given.synthesis.fit_resolution = false;
    const PatchTextureResult r_given = synthesize_patch_texture(m_given, {ex}, {}, given);
    EXPECT_LT(widths_shown(m_off, r_off, ex.width), 0.5) << "the test's resolution shows less than half a width";
    EXPECT_EQ(r_off.patch_resolution, 16);
    EXPECT_EQ(r_given.patch_resolution, 16);
    EXPECT_GE(widths_shown(m, r, ex.width), 1.0);
    EXPECT_LT(widths_shown(m, r, ex.width), 1.2);
    EXPECT_GT(r.patch_resolution, 32);
    EXPECT_EQ(r.synthesis.flat.patches.size(), r_off.synthesis.flat.patches.size()) << "the same patches";
    const nlohmann::json j = to_json(r);
    EXPECT_EQ(j["patch_resolution_raised_from"], 16);
    EXPECT_NEAR(j["exemplar_widths"]["at_patch_resolution"].get<double>(), widths_shown(m_off, r_off, ex.width), 1e-9);
    EXPECT_GE(j["exemplar_widths"]["across_longest_side"].get<double>(), 1.0);
    std::printf("scale %g: resolution 16 -> %d, widths %.3f -> %.3f\n", scale, r.patch_resolution,
                widths_shown(m_off, r_off, ex.width), widths_shown(m, r, ex.width));
  }
  // Raised past what one atlas holds: lowered again by eighths, not refused.
  Mesh small;
  make_icosphere(small, 1);
  PatchTextureOptions tight = small_options();
  tight.fidelity = false;
  tight.synthesis.min_exemplar_widths = 1;
  tight.synthesis.atlas.max_size = 128;
  const PatchTextureResult r_tight = synthesize_patch_texture(small, {ex}, {}, tight);
  EXPECT_GT(r_tight.synthesis.resolution_wanted, r_tight.patch_resolution);
  EXPECT_GT(r_tight.patch_resolution, 16);
  EXPECT_EQ(to_json(r_tight)["patch_resolution_requested"], r_tight.synthesis.resolution_wanted);
  PatchTextureOptions bad = small_options();
  bad.synthesis.min_exemplar_widths = -1;
  Mesh m;
  make_icosphere(m, 1);
  EXPECT_THROW(synthesize_patch_texture(m, {ex}, {}, bad), InvalidInputError);
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
