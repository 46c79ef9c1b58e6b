// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>

#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "test_support.h"
#include "texture/graphcut_synthesis.h"
#include "texture/image_ops.h"
#include "texture/material_space/material_tile.h"
#include "texture/tileable_tile.h"
#include "texture/wrap_seam_ratio.h"

using namespace surftex;

namespace {
using surftex::test::sanitized;

Image crop_corner(const Image& img, int x0, int y0, int w, int h) {
  Image out(w, h, img.channels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < img.channels; ++c) out.at(x, y, c) = img.at(x0 + x, y0 + y, c);
  return out;
}
}  // namespace

TEST(WrapSeamRatio, PeriodicImageNearOneRampFarAbove) {
  const double pi = std::acos(-1.0);
  Image periodic(48, 40, 1), ramp(48, 40, 1);
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 48; ++x) {
      // A plane wave crossing the wrap at every phase: statistically the wrap
      // pairs look like any other pair.
      periodic.at(x, y) = static_cast<float>(0.5 + 0.4 * std::sin(2 * pi * (2.0 * x / 48 + 3.0 * y / 40)));
      ramp.at(x, y) = static_cast<float>((x + y) / 100.0);
    }
  EXPECT_NEAR(wrap_seam_ratio(periodic), 1.0, 0.1);
  EXPECT_GT(wrap_seam_ratio(ramp), 10.0);
  EXPECT_DOUBLE_EQ(wrap_seam_ratio(Image(8, 8, 3, 0.2f)), 1.0);
  EXPECT_THROW(wrap_seam_ratio(Image(1, 8, 1)), InvalidInputError);
}

TEST(TileableTile, RealTexturesTileSeamlessly) {
  // 64x64 crops of real, non-tileable textures -> 96x96 tiles.
  std::vector<std::string> names = {"pebbles_256.png", "rock_512.png", "wood_512.png",
                                    "tree_bark_512.png", "fabric_brown_256.png"};
  if (sanitized()) names.resize(2);
  const int size = sanitized() ? 64 : 96;
  for (const auto& name : names) {
    Image full = read_image(test::shared_data("textures/" + name));
    Image ex = crop_corner(full, 0, 0, 64, 64);
    const double crop_ratio = wrap_seam_ratio(ex);
    TileOptions o;
    TileResult t = make_tileable_detailed(ex, size, o);
    ASSERT_EQ(t.tile.width, size);
    ASSERT_EQ(t.tile.height, size);
    EXPECT_NEAR(t.wrap_seam_ratio, wrap_seam_ratio(t.tile), 1e-12);
    EXPECT_LE(t.wrap_seam_ratio, 1.3) << name;
    EXPECT_GT(crop_ratio, t.wrap_seam_ratio + 0.2) << name << " crop " << crop_ratio;
  }
}

// Regression: with 64-pixel patches (the former automatic size) 128-pixel
// tiles of wood_512 (long horizontal grain) and red_checked_384 (a check
// pattern whose period does not divide 128) kept visible seams at the wrap
// (ratios 1.34 and 1.68). Larger patches (7/8 of the tile) fix both.
TEST(TileableTile, AnisotropicAndRegularTexturesTileAt128) {
  if (sanitized()) GTEST_SKIP() << "real-size case, Release only";
  for (const char* name : {"wood_512.png", "red_checked_384.png"}) {
    Image ex = crop_corner(read_image(test::shared_data(std::string("textures/") + name)), 0, 0, 256, 256);
    TileResult t = make_tileable_detailed(ex, 128, TileOptions{});
    EXPECT_LE(t.wrap_seam_ratio, 1.3) << name;
    TileOptions small;
    small.patch_size = 64;
    small.refinement_passes = 2;
    EXPECT_LT(t.seam_cost, make_tileable_detailed(ex, 128, small).seam_cost) << name;
  }
}

TEST(TileableTile, DeterministicAndValidated) {
  Image ex = crop_corner(read_image(test::shared_data("textures/cracked_mud_100.png")), 0, 0, 48, 48);
  TileOptions o;
  o.seed = 9;
  Image a = make_tileable(ex, 40, o), b = make_tileable(ex, 40, o);
  EXPECT_EQ(a.data, b.data);
  EXPECT_THROW(make_tileable(ex, 4, o), InvalidInputError);
  o.patch_size = 3;
  EXPECT_THROW(make_tileable(ex, 40, o), InvalidInputError);
  o.patch_size = 16;
  o.overlap = 16;
  EXPECT_THROW(make_tileable(ex, 40, o), InvalidInputError);
  o.overlap = 0;
  o.k = -1;
  EXPECT_THROW(make_tileable(ex, 40, o), InvalidInputError);
}

// Small tiles (the 32-px key tiles of material_tile under the sanitizers).
// The mud key tile's wrap ratio of 1.64 at 32 px was blamed on a lack of
// overlap; measured, its wrap column holds no graph-cut seam at all (every
// wrap pair is a pair of exemplar neighbours, copied verbatim): a crack of the
// exemplar runs along that column (texture/wrap_seam_ratio.h, limitation).
// What must hold is that the cut is optimised across the wrap like anywhere
// else: over several seeds, the seam cost (Kwatra eq. 1) of the wrap lines
// is no higher than that of an average line of the torus. A tile whose wrap
// were pasted straight would carry a seam on all 32 pairs of each wrap line.
TEST(TileableTile, At32PxTheWrapLinesCarryNoMoreSeamThanOtherLines) {
  const int s = 32;
  std::vector<std::string> names = {"cracked_mud_100.png", "brick_small_96.png", "leather_64.png"};
  // Six seeds also under the sanitizers: 32-px tiles are cheap, and with two
  // seeds the wrap lines are too few a sample (1.71x the mean line, seen).
  const int seeds = 6;
  double wrap_cost = 0.0, line_cost = 0.0;
  for (const auto& name : names) {
    Image ex = square_resample(read_image(test::shared_data("textures/" + name)), s);
    for (int seed = 1; seed <= seeds; ++seed) {
      TileOptions to;  // make_tileable's defaults, but for the seed and the cut
      to.seed = static_cast<std::uint64_t>(seed);
      to.choose_cut = false;  // the wrap lines where the synthesis put them
      // What make_tileable runs (for the source maps): no defaults copied here.
      const GraphcutOptions g = tileable_graphcut_options(ex, s, to);
      GraphcutResult r = graphcut_synthesize_detailed(ex, s, s, g);
      ASSERT_EQ(make_tileable(ex, s, to).data, r.image.data) << "the test mirrors make_tileable";
      // Seam cost of one line: each neighbour pair across it pasted into a
      // 2x1 (column line) or 1x2 (row line) canvas from its two sources.
      auto line = [&](bool column, int k) {
        double c = 0.0;
        for (int t = 0; t < s; ++t) {
          const int x = column ? k : t, y = column ? t : k;
          const int nx = column ? (k + 1) % s : t, ny = column ? t : (k + 1) % s;
          const std::size_t a = static_cast<std::size_t>(y) * s + x, b = static_cast<std::size_t>(ny) * s + nx;
          GraphcutCanvas pair(ex, column ? 2 : 1, column ? 1 : 2, false);
          pair.place_straight({0, 0, r.source_x[a], r.source_y[a], 1, 1});
          pair.place_straight({column ? 1 : 0, column ? 0 : 1, r.source_x[b], r.source_y[b], 1, 1});
          c += pair.seam_cost();
        }
        return c;
      };
      for (int k = 0; k < s; ++k) {
        const double c = line(true, k) + line(false, k);
        line_cost += c / s;
        if (k == s - 1) wrap_cost += c;
      }
    }
  }
  EXPECT_GT(line_cost, 0.0);  // guard: these tiles do have seams
  EXPECT_LE(wrap_cost, 1.5 * line_cost) << "wrap " << wrap_cost << " mean line " << line_cost;
}

TEST(TileableTile, TorusCutFindsTheSmoothestRowAndColumn) {
  // Noise with one pair of equal columns (5, 6) and one pair of equal rows
  // (13, 14): the only zero-jump lines of the torus.
  Image img(24, 20, 3);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (float& v : img.data) v = u(rng);
  for (int y = 0; y < img.height; ++y)
    for (int c = 0; c < 3; ++c) img.at(6, y, c) = img.at(5, y, c);
  for (int x = 0; x < img.width; ++x)
    for (int c = 0; c < 3; ++c) img.at(x, 14, c) = img.at(x, 13, c);
  TorusCut cut = choose_torus_cut(img);
  EXPECT_EQ(cut.shift_x, 6);
  EXPECT_EQ(cut.shift_y, 14);
  EXPECT_EQ(cut.column_jump, 0.0);
  EXPECT_EQ(cut.row_jump, 0.0);
  EXPECT_GT(wrap_seam_ratio(img), 0.5);  // guard: the noise's own wrap is not smooth
  EXPECT_EQ(wrap_seam_stats(crop(img, cut.shift_x, cut.shift_y, 24, 20, true)).wrap_mean, 0.0);
  // Ties keep the current cut.
  TorusCut flat = choose_torus_cut(Image(8, 8, 1, 0.5f));
  EXPECT_EQ(flat.shift_x, 0);
  EXPECT_EQ(flat.shift_y, 0);
  EXPECT_THROW(choose_torus_cut(Image(1, 8, 1)), InvalidInputError);
}

// Issue #3 (G2): the two textures whose 128-px tiles had a wrap-seam ratio
// above 1.3 at the synthesis cut (dots_large 1.60 with seam cost 0,
// water_caustics 1.71): the wrap line ran along texture features. The chosen
// cut is the same tiling (a roll, bit for bit), its wrap lines are the
// smoothest of the torus, and its ratio is at most the one at the synthesis
// cut.
TEST(TileableTile, ChosenCutIsARollOfTheSynthesisedTileOnItsSmoothestLines) {
  const int size = sanitized() ? 64 : 128;
  for (const char* name : {"dots_large_208x168.png", "water_caustics_300.png"}) {
    Image ex = read_image(test::shared_data(std::string("textures/") + name));
    TileOptions keep;
    keep.choose_cut = false;
    const TileResult a = make_tileable_detailed(ex, size, keep);
    const TileResult b = make_tileable_detailed(ex, size, TileOptions{});
    EXPECT_EQ(a.shift_x, 0);
    EXPECT_EQ(a.shift_y, 0);
    EXPECT_DOUBLE_EQ(a.wrap_seam_ratio, a.wrap_seam_ratio_at_synthesis_cut);
    EXPECT_DOUBLE_EQ(b.wrap_seam_ratio_at_synthesis_cut, a.wrap_seam_ratio);
    EXPECT_EQ(b.seam_cost, a.seam_cost) << name;
    ASSERT_EQ(b.tile.data, crop(a.tile, b.shift_x, b.shift_y, size, size, true).data) << name;
    EXPECT_LE(b.wrap_seam_ratio, a.wrap_seam_ratio) << name;
    EXPECT_NEAR(b.wrap_seam_ratio, wrap_seam_ratio(b.tile), 1e-12);
    if (!sanitized()) {
      EXPECT_GT(a.wrap_seam_ratio, 1.3) << name << ": the case this test is about";
      EXPECT_LE(b.wrap_seam_ratio, 1.3) << name;
      // ... yet the synthesis cut carries no seam: its jumps are those of the
      // exemplar at the same sources (measured 1.000 and 1.029).
      EXPECT_LE(a.source_matched_wrap_ratio_at_synthesis_cut, 1.1) << name;
    }
    EXPECT_EQ(b.source_matched_worst_line_ratio, a.source_matched_worst_line_ratio) << name;
    // No other roll gives smoother wrap lines: vary one shift, keep the other.
    const double best = wrap_seam_stats(b.tile).wrap_mean;
    for (int s = 0; s < size; ++s) {
      EXPECT_GE(wrap_seam_stats(crop(a.tile, s, b.shift_y, size, size, true)).wrap_mean, best - 1e-12) << s;
      EXPECT_GE(wrap_seam_stats(crop(a.tile, b.shift_x, s, size, size, true)).wrap_mean, best - 1e-12) << s;
    }
  }
}

// A straight seam anywhere on the torus, not only at the wrap: a smooth
// periodic image (plane waves) with a step of 0.3 at column line 17 that
// fades out linearly towards the wrap (so the wrap itself stays smooth).
// The wrap-seam ratio does not see it; the worst-line ratio does, at the same
// value for every roll; rolled_wrap_seam_ratio is the ratio of the rolled
// image, and rolling onto the seam shows it.
TEST(WrapSeamRatio, WorstLineFindsAStraightSeamAnywhereForEveryRoll) {
  const double pi = std::acos(-1.0);
  const int W = 48, H = 40;
  Image img(W, H, 3);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) {
        double v = 0.5 + 0.2 * std::sin(2 * pi * (2.0 * x / W + 3.0 * y / H + 0.3 * c)) +
                   0.1 * std::cos(2 * pi * (5.0 * x / W - 1.0 * y / H));
        if (x >= 17) v += 0.3 * (1.0 - static_cast<double>(x - 17) / (W - 17));
        img.at(x, y, c) = static_cast<float>(v);
      }
  const LineJumpProfile p = line_jump_profile(img, true);
  ASSERT_EQ(p.column.size(), static_cast<std::size_t>(W));
  ASSERT_EQ(p.row.size(), static_cast<std::size_t>(H));
  EXPECT_TRUE(p.worst_is_column);
  EXPECT_EQ(p.worst_index, 17);
  EXPECT_GT(p.worst_ratio, 2.5);
  EXPECT_EQ(p.worst_column_ratio, p.worst_ratio);
  EXPECT_LT(p.worst_row_ratio, 1.5);  // no seam across rows
  EXPECT_LT(wrap_seam_ratio(img), 1.2);  // the seam is not at the wrap
  EXPECT_LT(p.wrap_column_ratio, 1.2);
  for (const auto& roll : {std::pair<int, int>{5, 9}, {17, 0}, {30, 33}}) {
    const Image r = crop(img, roll.first, roll.second, W, H, true);
    const LineJumpProfile pr = line_jump_profile(r, true);
    EXPECT_NEAR(pr.worst_ratio, p.worst_ratio, 1e-9);
    EXPECT_EQ(pr.worst_index, (17 - roll.first + W) % W);
    EXPECT_NEAR(rolled_wrap_seam_ratio(p, roll.first, roll.second), wrap_seam_ratio(r), 1e-9);
  }
  EXPECT_GT(rolled_wrap_seam_ratio(p, 17, 0), 1.5);  // rolled onto the seam
  // Non-periodic: only interior lines; the seam is still the worst.
  const LineJumpProfile q = line_jump_profile(img, false);
  EXPECT_EQ(q.column[0], 0.0);
  EXPECT_EQ(q.worst_index, 17);
  EXPECT_THROW(rolled_wrap_seam_ratio(q, 0, 0), InvalidInputError);
  EXPECT_THROW(rolled_wrap_seam_ratio(p, W, 0), InvalidInputError);
  EXPECT_THROW(line_jump_profile(Image(2, 8, 1), false), InvalidInputError);
  EXPECT_DOUBLE_EQ(worst_line_ratio(Image(8, 8, 3, 0.2f)), 1.0);
}

// Issue #3 (G2): is the synthesis cut (line 0 of the fill grid) a special
// line of the torus? Measured on the 29 shared textures (128 px, seeds 1-6,
// 336 line samples): line 0's jump ranks at percentile 0.48 among the 128
// lines of its orientation on average (uniform: 0.5), its mean ratio to the
// mean line is 0.97, and 9.5% of line-0 samples are above 1.3 against 13% of
// all lines; the seed-1 failures (dots_large 1.60, ink_a 1.51,
// water_caustics 1.74) are draws from the textures' own line spread (the
// same three measure 0.72-1.16, 0.90-1.31 and 0.74-1.45 with seeds 2-6).
// This test checks that property on the three textures plus two stochastic
// ones: the mean percentile of the synthesis-cut lines is that of a random
// line. Guard: the same figure for non-periodic graph-cut outputs of the
// same size, whose line 0 (left edge against right edge) is a real seam.
TEST(TileableTile, SynthesisCutIsAnOrdinaryLineOfTheTorus) {
  std::vector<std::string> names = {"dots_large_208x168.png", "ink_a_400.png", "water_caustics_300.png",
                                    "rock_512.png", "pebbles_256.png"};
  const int size = sanitized() ? 48 : 64;
  const int seeds = sanitized() ? 2 : 4;
  if (sanitized()) names.resize(3);
  double tile_pct = 0.0, plain_pct = 0.0;
  int n = 0;
  auto percentile = [](const std::vector<double>& v) {
    double below = 0.0;
    for (double e : v) below += e < v[0] ? 1.0 : 0.0;
    return below / static_cast<double>(v.size() - 1);
  };
  for (const auto& name : names) {
    // The top-left 128x128 of the exemplar keeps the matching cheap.
    const Image full = read_image(test::shared_data("textures/" + name));
    const Image ex = crop_corner(full, 0, 0, std::min(128, full.width), std::min(128, full.height));
    for (int seed = 1; seed <= seeds; ++seed) {
      TileOptions to;
      to.seed = static_cast<std::uint64_t>(seed);
      to.choose_cut = false;
      const TileResult t = make_tileable_detailed(ex, size, to);
      const LineJumpProfile p = line_jump_profile(t.tile, true);
      EXPECT_DOUBLE_EQ(t.synthesis_column_percentile, percentile(p.column));
      EXPECT_DOUBLE_EQ(t.synthesis_row_percentile, percentile(p.row));
      EXPECT_DOUBLE_EQ(t.worst_line_ratio, p.worst_ratio);
      tile_pct += t.synthesis_column_percentile + t.synthesis_row_percentile;
      GraphcutOptions g;  // non-periodic, fill only: the guard needs no refinement
      g.seed = to.seed;
      g.refinement_passes = 0;
      const LineJumpProfile q = line_jump_profile(graphcut_synthesize(ex, size, size, g), true);
      plain_pct += percentile(q.column) + percentile(q.row);
      n += 2;
    }
  }
  tile_pct /= n;
  plain_pct /= n;
  // Uniform percentiles: mean 0.5, standard deviation 0.29 / sqrt(n) (0.046
  // here, 0.084 sanitized). Measured: 0.46 (sanitized 0.39-0.47); the plain
  // outputs 0.997 (sanitized 0.91).
  EXPECT_LT(tile_pct, 0.7) << "plain outputs " << plain_pct;
  EXPECT_GT(plain_pct, 0.85) << "guard: a non-periodic output's wrap is a seam";
}

// The source-matched line profile on a hand-made torus: a smooth exemplar
// with one sharp vertical edge (exemplar column 12 vs 13). The 16x16 tile
// copies the exemplar verbatim except at column line 10 (sources jump by 15
// columns) and the two wrap lines (the torus must close somewhere). The
// exemplar's edge lands on tile column line 7: a big jump, copied verbatim.
TEST(WrapSeamRatio, SourceMatchedLinesSeeSeamsNotContent) {
  const double pi = std::acos(-1.0);
  Image ex(48, 40, 3);
  for (int y = 0; y < ex.height; ++y)
    for (int x = 0; x < ex.width; ++x)
      for (int c = 0; c < 3; ++c)
        ex.at(x, y, c) = static_cast<float>(0.4 + 0.2 * std::sin(2 * pi * (x / 23.0 + y / 31.0 + 0.2 * c)) +
                                            (x > 12 ? 0.3 : 0.0));
  const int S = 16;
  std::vector<int> sx(S * S), sy(S * S);
  Image tile(S, S, 3);
  for (int y = 0; y < S; ++y)
    for (int x = 0; x < S; ++x) {
      const int i = y * S + x;
      sx[i] = x < 10 ? x + 6 : x + 21;  // pixel 6 <- exemplar 12, pixel 7 <- 13: the edge
      sy[i] = y + 5;
      for (int c = 0; c < 3; ++c) tile.at(x, y, c) = ex.at(sx[i], sy[i], c);
    }
  const SourceMatchedLineProfile p = source_matched_line_profile(tile, ex, sx, sy);
  ASSERT_EQ(p.column.size(), static_cast<std::size_t>(S));
  for (int k = 1; k < S; ++k) {
    EXPECT_DOUBLE_EQ(p.row[static_cast<std::size_t>(k)], 1.0) << k;
    if (k != 10) {
      EXPECT_DOUBLE_EQ(p.column[static_cast<std::size_t>(k)], 1.0) << k;
    }
  }
  EXPECT_GT(p.column[10], 2.0);
  EXPECT_TRUE(p.worst_is_column);
  EXPECT_EQ(p.seam_pairs, 3 * S);  // column lines 10 and 0, row line 0
  EXPECT_GT(p.wrap_ratio, 1.5);
  // The jump profile, blind to sources, sees the verbatim edge as a line
  // well above the mean.
  const LineJumpProfile j = line_jump_profile(tile, true);
  EXPECT_GT(j.column[7] / j.column_mean, 2.0);
  EXPECT_DOUBLE_EQ(p.column[7], 1.0);
  // Validation.
  EXPECT_THROW(source_matched_line_profile(tile, ex, std::vector<int>(5, 0), sy), InvalidInputError);
  std::vector<int> bad = sx;
  bad[3] = ex.width;
  EXPECT_THROW(source_matched_line_profile(tile, ex, bad, sy), InvalidInputError);
  EXPECT_THROW(source_matched_line_profile(tile, Image(48, 40, 1), sx, sy), InvalidInputError);
}

// Regression (issue 3, session 5): the eq.-1 graph cut left straight seams
// inside periodic tiles -- two large patches meeting along a straight overlap
// edge, optimal under eq. 1, so the error-region refinement kept them.
// wood_512's 128-px tile (seed 1) showed one on column line 86 (source-matched
// ratio 3.18). The straight-seam repair (GraphcutOptions::straight_seam_steps)
// must bring the worst line of the torus to <= 1.3 against the exemplar's own
// jumps, at a bounded eq.-1 cost, without a seam across the wrap.
TEST(TileableTile, StraightSeamRepairBreaksTheStraightSeamInsideTheWoodTile) {
  // Sanitized: a 64-px tile of the exemplar's 256-px corner (FFT matching
  // over the whole 512-px exemplar dominates the run time).
  const int size = sanitized() ? 64 : 128;
  Image ex = read_image(test::shared_data("textures/wood_512.png"));
  if (sanitized()) ex = crop_corner(ex, 0, 0, 256, 256);
  TileOptions off;
  off.straight_seam_steps = 0;
  const TileResult a = make_tileable_detailed(ex, size, off);
  EXPECT_GT(a.source_matched_worst_line_ratio, 1.3) << "the case this test is about";
  const TileOptions on;
  const GraphcutResult g = graphcut_synthesize_detailed(ex, size, size, tileable_graphcut_options(ex, size, on));
  EXPECT_EQ(g.seam_cost_before_straight, a.seam_cost);  // the repair starts from the unrepaired tile
  EXPECT_GE(g.straight_seam_accepted, 1);
  EXPECT_LE(g.seam_cost_final, g.seam_cost_before_straight * (1.0 + on.straight_seam_cost_tolerance) + 1e-9);
  // Recomputed from the result's own sources: no line of the torus is a seam
  // any more, and the wrap still carries none.
  const SourceMatchedLineProfile p = source_matched_line_profile(g.image, ex, g.source_x, g.source_y);
  EXPECT_LE(p.worst_ratio, 1.3);
  EXPECT_LE(p.wrap_ratio, 1.1);
}

// The repair is deterministic for any thread count (the FFT matching runs
// in parallel), only acts on periodic outputs, and validates its options.
TEST(TileableTile, StraightSeamRepairIsDeterministicAndPeriodicOnly) {
  const Image ex = crop_corner(read_image(test::shared_data("textures/wood_512.png")), 0, 0, 96, 96);
  TileOptions o;
  o.seed = 3;
  Image one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = make_tileable(ex, 48, o);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = make_tileable(ex, 48, o);
  }
  EXPECT_EQ(one.data, two.data);
  GraphcutOptions g;
  g.seed = 3;
  const GraphcutResult plain = graphcut_synthesize_detailed(ex, 64, 64, g);
  g.straight_seam_steps = 16;
  const GraphcutResult with = graphcut_synthesize_detailed(ex, 64, 64, g);
  EXPECT_EQ(plain.image.data, with.image.data);
  EXPECT_EQ(with.straight_seam_tried, 0);
  g.straight_seam_steps = -1;
  EXPECT_THROW(graphcut_synthesize(ex, 64, 64, g), InvalidInputError);
  o.straight_seam_ratio = 1.0;
  EXPECT_THROW(make_tileable(ex, 48, o), InvalidInputError);
  o.straight_seam_ratio = 1.3;
  o.straight_seam_cost_tolerance = -0.5;
  EXPECT_THROW(make_tileable(ex, 48, o), InvalidInputError);
}
