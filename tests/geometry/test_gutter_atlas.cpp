// SPDX-License-Identifier: AGPL-3.0-or-later
// The base-mesh atlas repacked in texels with mip gutters (issue 16 item 3,
// decision 302): many-chart meshes keep the full 2^K gutter.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <map>
#include <random>
#include <vector>

#include "atlas_checks.h"
#include "geometry/atlas_gutter.h"
#include "geometry/gutter_atlas.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "test_support.h"

using namespace surftex;

// Regression: armadillo_52k's 818 charts at 2048 px left a quarter of the
// one-texel density only at a 16-texel gutter (mips clean to 128 px, not 64).
// Merged charts keep the full gutter, and neither flip nor overlap.
TEST(GutterAtlas, ManySmallChartsKeepTheFullGutter) {
  Mesh m;
  read_mesh(test::shared_data("meshes/armadillo_52k.off"), m);
  const int N = 2048, full = atlas_gutter_texels(N, 64);
  const GutterAtlas g = compute_gutter_atlas(m, N);
  std::cout << "[ atlas ] armadillo_52k at " << N << ": " << g.atlas.num_charts << " charts, gutter "
            << g.gutter << ", texels per length " << g.atlas.uv_per_length * N << ", area distortion "
            << g.atlas.mean_area_distortion << "\n";
  EXPECT_EQ(g.gutter, full);
  EXPECT_EQ(g.protected_mip_size, 64);
  EXPECT_EQ(g.violations, 0u);
  // The gaps (2 g + 3 texels around each chart's box) take at most a quarter of the atlas.
  EXPECT_LE(static_cast<double>(g.atlas.num_charts) * (2 * full + 3) * (2 * full + 3), 0.25 * N * N);
  EXPECT_EQ(g.atlas.flipped_faces, 0u);
  EXPECT_EQ(test::uv_flipped_faces(m), 0u);
  EXPECT_EQ(test::uv_overlap_texels(m, N), 0u);
}

// The subdiv asset's case (decision 210): a fine mesh at 1024 texels with
// charts of up to 8000 faces, whose flattenings and merges run in parallel,
// gives the same atlas bytes on one and two threads.
TEST(GutterAtlas, SameAtlasOnOneAndTwoThreads) {
  auto run = [](std::size_t threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    Mesh m;
    read_mesh(test::shared_data("meshes/bunny_75k.off"), m);
    const GutterAtlas g = compute_gutter_atlas(m, 1024, 64, 8000);
    auto uv = find(m, kCornerUV).first;
    std::vector<UV> uvs;
    for (HalfedgeIndex h : m.halfedges()) uvs.push_back(uv[h]);
    return std::make_pair(uvs, g.chart);
  };
  const auto one = run(1), two = run(2);
  EXPECT_TRUE(one.first == two.first);
  EXPECT_TRUE(one.second == two.second);
}

namespace surftex {
namespace {

// The count by its definition: a texel with a chart within Chebyshev
// distance g is a violation unless exactly one chart is that near and the
// texel carries its label.
std::size_t gutter_violations_by_definition(const std::vector<int>& chart, const std::vector<int>& fin, int W, int H,
                                            int g) {
  std::size_t bad = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      int lo = -1, hi = -1;
      for (int qy = std::max(0, y - g); qy <= std::min(H - 1, y + g); ++qy)
        for (int qx = std::max(0, x - g); qx <= std::min(W - 1, x + g); ++qx) {
          const int c = chart[static_cast<std::size_t>(qy) * W + qx];
          if (c < 0) continue;
          lo = lo < 0 ? c : std::min(lo, c);
          hi = std::max(hi, c);
        }
      if (hi < 0) continue;
      bad += lo != hi || fin[static_cast<std::size_t>(y) * W + x] != lo;
    }
  return bad;
}

TEST(AtlasGutter, ViolationsMatchTheirDefinitionForEveryGutterWidth) {
  const int W = 37, H = 23;
  std::mt19937 rng(5);
  std::vector<int> chart(static_cast<std::size_t>(W) * H, -1), fin(chart.size());
  // A few rectangles of charts on empty ground, then labels dilated with some wrong.
  for (int k = 0; k < 6; ++k) {
    const int x0 = static_cast<int>(rng() % W), y0 = static_cast<int>(rng() % H);
    for (int y = y0; y < std::min(H, y0 + 4); ++y)
      for (int x = x0; x < std::min(W, x0 + 5); ++x) chart[static_cast<std::size_t>(y) * W + x] = k % 4;
  }
  for (std::size_t i = 0; i < fin.size(); ++i) fin[i] = rng() % 5 == 0 ? static_cast<int>(rng() % 4) : chart[i];
  std::size_t nonzero = 0;
  for (int g : {0, 1, 2, 3, 5, 8, 30, 100}) {
    const std::size_t want = gutter_violations_by_definition(chart, fin, W, H, g);
    EXPECT_EQ(gutter_violations(chart, fin, W, H, g), want) << "g " << g;
    nonzero += want > 0;
  }
  EXPECT_GE(nonzero, 6u);
}


// dilate_charts by its header's words, ring by ring: the empty texels with a
// labelled 8-neighbour take the majority label (ties: lower) of their labelled
// neighbours and those neighbours' mean; then the next ring.
int dilate_by_definition(Image& img, std::vector<int>& label) {
  const int W = img.width, H = img.height, C = img.channels;
  int rings = 0;
  for (;;) {
    std::vector<int> lab = label;
    std::vector<float> val = img.data;
    bool any = false;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * W + x;
        if (label[i] >= 0) continue;
        std::map<int, int> count;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
            const int l = label[static_cast<std::size_t>(qy) * W + qx];
            if (l >= 0) ++count[l];
          }
        if (count.empty()) continue;
        int best = count.begin()->first;
        for (const auto& [l, c] : count)
          if (c > count[best]) best = l;
        lab[i] = best;
        for (int c = 0; c < C; ++c) {
          float sum = 0.f;
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int qx = x + dx, qy = y + dy;
              if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
              const std::size_t j = static_cast<std::size_t>(qy) * W + qx;
              if (label[j] == best) sum += img.data[j * C + c];
            }
          val[i * C + c] = sum / static_cast<float>(count[best]);
        }
        any = true;
      }
    if (!any) return rings;
    label.swap(lab);
    img.data.swap(val);
    ++rings;
  }
}

TEST(AtlasGutter, DilationMatchesItsDefinitionForAnyThreadCount) {
  const int W = 61, H = 44, C = 3;
  std::mt19937 rng(9);
  std::vector<int> label(static_cast<std::size_t>(W) * H, -1);
  Image img(W, H, C, 0.f);
  for (int k = 0; k < 7; ++k) {  // scattered charts with random values
    const int x0 = static_cast<int>(rng() % W), y0 = static_cast<int>(rng() % H);
    for (int y = y0; y < std::min(H, y0 + 1 + static_cast<int>(rng() % 6)); ++y)
      for (int x = x0; x < std::min(W, x0 + 1 + static_cast<int>(rng() % 9)); ++x) {
        label[static_cast<std::size_t>(y) * W + x] = k % 5;
        for (int c = 0; c < C; ++c) img.at(x, y, c) = static_cast<float>(rng() % 1000) / 1000.f;
      }
  }
  Image want = img;
  std::vector<int> want_label = label;
  const int want_rings = dilate_by_definition(want, want_label);
  EXPECT_GT(want_rings, 3);
  for (int threads : {1, 2}) {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, threads);
    Image got = img;
    std::vector<int> got_label = label;
    EXPECT_EQ(dilate_charts(got, got_label), want_rings);
    EXPECT_EQ(got_label, want_label) << threads << " threads";
    EXPECT_EQ(got.data, want.data) << threads << " threads";
  }
}

}  // namespace
}  // namespace surftex
