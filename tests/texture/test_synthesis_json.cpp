// SPDX-License-Identifier: AGPL-3.0-or-later
// The `synth` and `material-tile` report figures come from the results'
// to_json (texture/synthesis_json.h, texture/material_space/material_tile_json.h):
// every field under its name with its value, and no key dropped.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <set>
#include <string>

#include "texture/material_space/material_tile_json.h"
#include "texture/synthesis_json.h"

namespace surftex {
namespace {

std::set<std::string> keys(const nlohmann::json& j) {
  std::set<std::string> k;
  for (const auto& [key, value] : j.items()) k.insert(key);
  return k;
}

TEST(SynthesisJson, EfrosLeungResultKeepsEveryReportedField) {
  ElResult r;
  r.window = 11;
  r.first_pass_window = 5;
  r.rotations_used = 64;
  r.search_images = 16;
  r.seeded = 9;
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(keys(j), (std::set<std::string>{"window", "first_pass_window", "orientations_searched", "search_images",
                                            "seeded_pixels"}));
  EXPECT_EQ(j["search_images"], 16);
  EXPECT_EQ(j["window"], 11);
  EXPECT_EQ(j["first_pass_window"], 5);
  EXPECT_EQ(j["orientations_searched"], 64);
  EXPECT_EQ(j["seeded_pixels"], 9);
}

TEST(SynthesisJson, BidirectionalSimilarityCarriesItsSettings) {
  BidirectionalResult r;
  r.coherence = 0.25;
  r.completeness = 0.5;
  r.total = 0.75;
  BidirectionalOptions o;
  o.patch = 5;
  o.stride = 2;
  o.exemplar_stride = 3;
  o.max_candidates = 256;
  o.search_eps = 3.f;
  const nlohmann::json j = to_json(r, o);
  EXPECT_EQ(keys(j), (std::set<std::string>{"patch", "stride", "exemplar_stride", "approximate_max_candidates",
                                            "approximate_search_eps", "coherence", "completeness", "total"}));
  EXPECT_EQ(j["approximate_search_eps"], 3.0);
  EXPECT_EQ(j["patch"], 5);
  EXPECT_EQ(j["stride"], 2);
  EXPECT_EQ(j["exemplar_stride"], 3);
  EXPECT_EQ(j["approximate_max_candidates"], 256);
  EXPECT_DOUBLE_EQ(j["coherence"].get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j["completeness"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["total"].get<double>(), 0.75);
}

TEST(MaterialTileJson, ResultKeepsEveryReportedField) {
  MaterialTileResult r;
  r.layers.resize(3);
  r.sign_changes = {0, 12, 7};
  r.mask_agreement = {1.0, 0.9, 0.8};
  r.seconds_keys = 1.5;
  r.seconds_morph = 2.5;
  r.seconds_synthesis = 3.5;
  r.seconds_total = 9.0;  // the report's total is set by the CLI, not here
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(keys(j), (std::set<std::string>{"layers", "sign_changes", "mask_agreement", "seconds"}));
  EXPECT_EQ(j["layers"], 3);
  EXPECT_EQ(j["sign_changes"], nlohmann::json({0, 12, 7}));
  EXPECT_EQ(j["mask_agreement"].size(), 3u);
  EXPECT_DOUBLE_EQ(j["mask_agreement"][1].get<double>(), 0.9);
  EXPECT_EQ(keys(j["seconds"]), (std::set<std::string>{"keys", "morph", "synthesis"}));
  EXPECT_DOUBLE_EQ(j["seconds"]["keys"].get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(j["seconds"]["morph"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(j["seconds"]["synthesis"].get<double>(), 3.5);
}

}  // namespace
}  // namespace surftex
