// SPDX-License-Identifier: AGPL-3.0-or-later
// The quilt report's figures come from the results' to_json (shell/quilting/quilt_json.h).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "shell/quilting/quilt_json.h"

namespace surftex {
namespace {

// The surface report's bare area is the output's (after the embedding removed
// and cut elements); the quilt's own figure before it is reported beside it.
TEST(QuiltJson, SurfaceBareAreaIsTheOutputs) {
  QuiltSwatchOnSurfaceResult r;
  r.quilt.bare_fraction = 0.01;
  r.bare.overall = 0.03;
  r.bare.by_height = {0.01, 0.02, 0.05, 0.04};
  const nlohmann::json j = to_json(r);
  EXPECT_DOUBLE_EQ(j["bare_fraction"].get<double>(), 0.03);
  EXPECT_DOUBLE_EQ(j["bare_fraction_quilt"].get<double>(), 0.01);
  EXPECT_DOUBLE_EQ(j["bare_by_height"][2].get<double>(), 0.05);
}

TEST(QuiltJson, PlanarAndSurfaceQuiltsShareTheMergeKeys) {
  QuiltResult plane;
  plane.elements = 7;
  plane.stats.stitched = 3;
  plane.stats.crossing_pushed = 2;
  plane.stats.seconds_match = 0.5;
  SurfaceQuiltResult surf;
  surf.stats.stitched = 5;
  EmbedSurfaceQuiltResult emb;
  const nlohmann::json p = to_json(plane), s = to_json(surf, emb);
  EXPECT_EQ(p["elements"], 7);
  EXPECT_EQ(p["stitched"], 3);
  EXPECT_EQ(p["crossing_pushed"], 2);
  EXPECT_EQ(p["seconds"]["match"], 0.5);
  EXPECT_EQ(s["stitched"], 5);
  const nlohmann::json merge = to_json(QuiltStepStats{});
  EXPECT_GE(merge.size(), 19u);
  for (const auto& [key, value] : merge.items()) {
    EXPECT_TRUE(p.contains(key)) << key;
    EXPECT_TRUE(s.contains(key)) << key;
  }
}

TEST(QuiltJson, SurfaceQuiltSaysWhatWasNotChecked) {
  SurfaceQuiltResult r;
  r.overlap_turn_sum = 30;
  r.overlap_area = 2;
  r.bare_fraction = 0.25;
  EmbedSurfaceQuiltResult e;
  e.stretch.stretch_after = 1.04;
  nlohmann::json j = to_json(r, e);
  EXPECT_DOUBLE_EQ(j["overlap_jump_deg"].get<double>(), 15.0);  // turn per overlap area
  EXPECT_DOUBLE_EQ(j["bare_fraction"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["stretch_after"].get<double>(), 1.04);
  EXPECT_TRUE(j["self_intersections"].is_null());  // the exact check did not run
  EXPECT_FALSE(j.contains("outside_shell"));        // not measured
  e.embed.checked = true;
  e.embed.self_intersecting_pairs = 4;
  e.self_intersections_between = 3;
  e.outside_shell_measured = true;
  j = to_json(r, e);
  EXPECT_EQ(j["self_intersections"], 4);
  EXPECT_EQ(j["self_intersections_between_elements"], 3);
  EXPECT_TRUE(j.contains("outside_shell"));
  for (const char* stage : {"quilt", "patches", "resolve", "finish", "shell", "stretch", "shell_map", "embed"})
    EXPECT_TRUE(j["seconds"].contains(stage)) << stage;
}

}  // namespace
}  // namespace surftex
