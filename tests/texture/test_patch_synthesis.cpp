// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch-based oriented surface synthesis (Gorla et al. 2003, 3-5): seams
// measured on the surface, stripes following the requested field, multi-
// texturing by height, re-synthesis keeps the other patches, determinism
// (also across thread counts), bad input.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <CGAL/Polygon_mesh_processing/remesh.h>

#include <cmath>
#include <cstdlib>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "texture/patches/patch_atlas.h"
#include "texture/patches/patch_seam_ratio.h"
#include "texture/patches/patch_synthesis.h"
#include "texture/procedural_texture.h"
#include "test_support.h"

namespace surftex {
namespace {

using surftex::test::sanitized;

PatchSynthesisOptions small_options(int res) {
  PatchSynthesisOptions o;
  o.flatten.resolution = res;
  o.flatten.margin = 2;
  o.partition.max_faces = 40;
  o.el.window = 9;
  o.el.rotations = 32;
  return o;
}

// More patches than one atlas holds (fandisk at 116K faces made 1,955 patches
// of 128 texels, which failed in the atlas packer after the whole synthesis):
// the resolution is lowered before synthesis, or refused up front when given.
TEST(PatchSynthesis, ResolutionIsLoweredBeforeSynthesisWhenOneAtlasCannotHoldThePatches) {
  Mesh m;
  make_icosphere(m, 3);
  const Image ex = make_noise(32, 4, 7);
  PatchSynthesisOptions o = small_options(64);
  o.field = PatchField::None;
  o.atlas.max_size = 256;
  PatchSynthesisResult r = synthesize_patches(m, {ex}, o);
  EXPECT_LT(r.resolution, 64);
  EXPECT_GE(r.resolution, 16);
  EXPECT_EQ(r.flat.patches[0].res, r.resolution);
  EXPECT_GT(r.flat.patches.size(), 16u);
  const PatchAtlas at = pack_patch_atlas(m, r.flat, r.images, o.atlas);  // throws if it did not fit
  EXPECT_LE(at.image.width, 256);
  o.fit_resolution = false;
  Mesh m2;
  make_icosphere(m2, 3);
  try {
    synthesize_patches(m2, {ex}, o);
    ADD_FAILURE() << "a given resolution that does not fit must be refused";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("--patch-res"), std::string::npos) << e.what();
  }
  // When one atlas holds them, the resolution is the one asked for.
  o.atlas.max_size = 4096;
  o.flatten.resolution = 24;
  Mesh m3;
  make_icosphere(m3, 3);
  EXPECT_EQ(synthesize_patches(m3, {ex}, o).resolution, 24);
}

TEST(PatchSynthesis, SeamRatioOnSphereWithNoiseIsLow) {
  Mesh m;
  make_icosphere(m, 3);
  const Image ex = make_noise(64, 4, 7);
  PatchSynthesisOptions o = small_options(sanitized() ? 24 : 40);
  o.field = PatchField::None;
  PatchSynthesisResult r = synthesize_patches(m, {ex}, o);
  EXPECT_GT(r.known_boundary, 0u);
  EXPECT_LE(r.seeded, 18u) << "only the first patch needs a seed";
  PatchAtlas at = pack_patch_atlas(m, r.flat, r.images);
  const SeamRatioResult s = patch_seam_ratio(m, r.flat, at.image);
  EXPECT_GT(s.pairs_across, 500u);
  EXPECT_GT(s.pairs_within, 5000u);
  EXPECT_LT(s.ratio, 1.5) << "across " << s.mean_across << " within " << s.mean_within;
  // The metric can fail: patches synthesised independently (shifted copies
  // of different noise) show their seams.
  std::vector<Image> broken = r.images;
  for (std::size_t p = 0; p < broken.size(); ++p)
    for (float& v : broken[p].data) v = (p % 2) ? v : 1.f - v;
  PatchAtlas at2 = pack_patch_atlas(m, r.flat, broken);
  EXPECT_GT(patch_seam_ratio(m, r.flat, at2.image).ratio, 1.5);
}

// Stripe direction per patch from the structure tensor of the patch image
// (interior Inside pixels), compared in the patch plane with `expected`
// (a function of the 3D point); returns the mean absolute angle error
// (degrees, as lines: modulo 180), weighted by pixels.
template <class F>
double stripe_error_deg(const Mesh& m, const PatchSynthesisResult& r, F expected) {
  double err = 0, wsum = 0;
  for (std::size_t p = 0; p < r.images.size(); ++p) {
    const FlatPatch& fp = r.flat.patches[p];
    const Image& img = r.images[p];
    double jxx = 0, jxy = 0, jyy = 0, ex = 0, ey = 0;
    int n = 0;
    for (int y = 1; y + 1 < fp.res; ++y)
      for (int x = 1; x + 1 < fp.res; ++x) {
        bool ok = true;
        for (int dy = -1; dy <= 1 && ok; ++dy)
          for (int dx = -1; dx <= 1 && ok; ++dx)
            ok = fp.state(x + dx, y + dy) == PatchPixel::Inside;
        if (!ok) continue;
        auto lum = [&](int xx, int yy) {
          const float* v = img.data.data() + fp.index(xx, yy) * 3;
          return v[0] + v[1] + v[2];
        };
        const double gx = lum(x + 1, y) - lum(x - 1, y), gy = lum(x, y + 1) - lum(x, y - 1);
        jxx += gx * gx;
        jxy += gx * gy;
        jyy += gy * gy;
        // expected direction at the pixel's 3D point, in the plane
        const std::size_t i = fp.index(x, y);
        const auto v = face_vertices(m, FaceIndex(fp.pixel_face[i]));
        const auto& b = fp.pixel_bary[i];
        Vector3 pt = b[0] * (m.point(v[0]) - CGAL::ORIGIN) + b[1] * (m.point(v[1]) - CGAL::ORIGIN) +
                     b[2] * (m.point(v[2]) - CGAL::ORIGIN);
        const Vector3 d = expected(pt);
        const double du = d * Vector3(fp.e1[0], fp.e1[1], fp.e1[2]);
        const double dv = d * Vector3(fp.e2[0], fp.e2[1], fp.e2[2]);
        const double a = std::atan2(dv, du);
        ex += std::cos(2 * a);
        ey += std::sin(2 * a);
        ++n;
      }
    if (n < 30) continue;
    // gradient orientation in pixel coords (y down) -> plane coords (v up)
    const double grad = 0.5 * std::atan2(2 * jxy, jxx - jyy);
    const double stripe_plane = -grad + M_PI / 2;  // flip y, then perpendicular
    const double want = 0.5 * std::atan2(ey, ex);
    double d = std::fmod(std::abs(stripe_plane - want), M_PI);
    if (d > M_PI / 2) d = M_PI - d;
    err += n * d * 180 / M_PI;
    wsum += n;
  }
  return wsum > 0 ? err / wsum : 180;
}

TEST(PatchSynthesis, StripesFollowTheField) {
  const Image ex = make_stripes(48, 8, 0);  // stripe lines along the exemplar's +x
  const int res = sanitized() ? 24 : 40;
  {
    Mesh m;
    make_cylinder(m, 1.0, 3.0, 32, 12);
    PatchSynthesisOptions o = small_options(res);
    o.field = PatchField::Constant;
    o.constant_vector = {0, 0, 1};  // the exemplar's top along the axis: its rows around it
    const PatchSynthesisResult r = synthesize_patches(m, {ex}, o);
    const double e = stripe_error_deg(m, r, [](const Vector3& p) { return Vector3(-p.y(), p.x(), 0); });
    EXPECT_LT(e, 12.0) << "constant field";
    const double wrong = stripe_error_deg(m, r, [](const Vector3&) { return Vector3(0, 0, 1); });
    EXPECT_GT(wrong, 60.0) << "rows must run across the constant vector, not along it";
  }
  {
    Mesh m;
    make_cylinder(m, 1.0, 3.0, 32, 12);
    PatchSynthesisOptions o = small_options(res);
    o.field = PatchField::Kmax;  // around the cylinder
    const PatchSynthesisResult r = synthesize_patches(m, {ex}, o);
    const double e = stripe_error_deg(m, r, [](const Vector3& p) { return Vector3(-p.y(), p.x(), 0); });
    EXPECT_LT(e, 12.0) << "kmax field";
    // and the same texture is clearly NOT along the axis
    const double wrong = stripe_error_deg(m, r, [](const Vector3&) { return Vector3(0, 0, 1); });
    EXPECT_GT(wrong, 60.0);
  }
}

// Share of the steps between neighbouring Inside pixels along which the
// texture gets brighter while going along `axis` (steps weighted by their
// component along it; steep jumps and flat steps left out).
double brighter_along(const PatchSynthesisResult& r, const Vector3& axis) {
  double agree = 0, total = 0;
  for (std::size_t p = 0; p < r.images.size(); ++p) {
    const FlatPatch& fp = r.flat.patches[p];
    const Image& img = r.images[p];
    const Vector3 e1(fp.e1[0], fp.e1[1], fp.e1[2]), e2(fp.e2[0], fp.e2[1], fp.e2[2]);
    // pixel x right = +e1, pixel y down = -e2
    const std::array<std::array<int, 2>, 2> steps{{{1, 0}, {0, -1}}};
    const std::array<double, 2> along{e1 * axis, e2 * axis};
    for (int y = 1; y < fp.res; ++y)
      for (int x = 0; x + 1 < fp.res; ++x)
        for (int k = 0; k < 2; ++k) {
          const int x2 = x + steps[k][0], y2 = y + steps[k][1];
          if (fp.state(x, y) != PatchPixel::Inside || fp.state(x2, y2) != PatchPixel::Inside) continue;
          const double di = img.data[fp.index(x2, y2) * 3] - img.data[fp.index(x, y) * 3];
          if (std::abs(di) < 0.02 || std::abs(di) > 0.3) continue;
          total += std::abs(along[k]);
          if (di * along[k] > 0) agree += std::abs(along[k]);
        }
  }
  return total > 0 ? agree / total : 0.5;
}

// A photograph held upright: with the constant field the exemplar's top edge
// points along the vector (a texture's up side stays up on an upright model),
// not merely its rows across it. The exemplar: bands bright at their top,
// fading towards their bottom, so going up inside a band gets brighter.
TEST(PatchSynthesis, TheConstantFieldStandsTheExemplarUpright) {
  Image ex(48, 48, 3);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x)
      for (int c = 0; c < 3; ++c) ex.at(x, y, c) = 1.f - static_cast<float>(y % 8) / 8.f;
  auto run = [&](double up_z) {
    Mesh m;
    make_cylinder(m, 1.0, 3.0, 32, 12);
    PatchSynthesisOptions o = small_options(sanitized() ? 24 : 40);
    o.field = PatchField::Constant;
    o.constant_vector = {0, 0, up_z};
    return brighter_along(synthesize_patches(m, {ex}, o), Vector3(0, 0, 1));
  };
  EXPECT_GT(run(1.0), 0.95) << "up +z: the bands' bright tops must face +z";
  EXPECT_LT(run(-1.0), 0.05) << "up -z: turned over";
}

// A flat top facing the constant vector (a CAD part's, a table's) gets the
// floor direction (floor_constraints), not the singularity that its walls'
// rows meet in when interpolated over it: its rows are parallel, along +x
// for the default +y (the exemplar's top along floor_vector = -z).
TEST(PatchSynthesis, TheConstantFieldLaysParallelRowsOnFlatTops) {
  Mesh m;
  make_cube(m, 2.0);
  CGAL::Polygon_mesh_processing::split_long_edges(edges(m), 0.25, m);
  PatchSynthesisOptions o = small_options(sanitized() ? 16 : 24);
  o.field = PatchField::Constant;
  synthesize_patches(m, {make_stripes(48, 8, 0)}, o);
  auto dir = find(m, kFaceDirection);
  ASSERT_TRUE(dir.second);
  int top = 0;
  for (FaceIndex f : m.faces()) {
    bool inner = robust_face_normal(m, f).y() > 0.99;  // the rim's faces turn to the walls
    for (HalfedgeIndex h : CGAL::halfedges_around_face(m.halfedge(f), m))
      inner = inner && robust_face_normal(m, m.face(m.opposite(h))).y() > 0.99;
    if (!inner) continue;
    ++top;
    EXPECT_GT(dir.first[f] * Vector3(1, 0, 0), std::cos(M_PI / 180)) << "face " << f;
  }
  EXPECT_GE(top, 8);
}

TEST(PatchSynthesis, MultiTexturingByHeight) {
  Mesh m;
  make_icosphere(m, 2);
  const Image dark(16, 16, 3, 0.1f), bright(16, 16, 3, 0.9f);
  PatchSynthesisOptions o = small_options(24);
  o.el.window = 5;
  o.field = PatchField::None;
  o.multi = MultiTexture::Height;
  o.height_axis = {0, 1, 0};
  const PatchSynthesisResult r = synthesize_patches(m, {dark, bright}, o);
  std::size_t agree = 0, total = 0;
  for (std::size_t p = 0; p < r.images.size(); ++p) {
    const FlatPatch& fp = r.flat.patches[p];
    for (std::size_t i = 0; i < fp.pixel.size(); ++i) {
      if (fp.pixel[i] != PatchPixel::Inside) continue;
      const auto v = face_vertices(m, FaceIndex(fp.pixel_face[i]));
      const auto& b = fp.pixel_bary[i];
      const double y = b[0] * m.point(v[0]).y() + b[1] * m.point(v[1]).y() + b[2] * m.point(v[2]).y();
      if (std::abs(y) < 0.1) continue;  // near the switch height
      const bool want_bright = y > 0;
      const bool is_bright = r.images[p].data[i * 3] > 0.5f;
      agree += want_bright == is_bright;
      ++total;
    }
  }
  ASSERT_GT(total, 1000u);
  EXPECT_GT(static_cast<double>(agree) / total, 0.97);
}

TEST(PatchSynthesis, DeterministicAndResynthesisKeepsOthers) {
  // Smooth noise, not flat cells: on piecewise-constant cells the coherent
  // candidates of the approximate search match exactly, so a re-synthesis
  // with another seed may legitimately give the same pixels.
  const Image ex = make_noise(48, 4, 3);
  auto run = [&](std::uint64_t seed, std::vector<int> resynth) {
    Mesh m;
    make_icosphere(m, 2);
    PatchSynthesisOptions o = small_options(24);
    o.field = PatchField::Constant;
    o.seed = seed;
    o.resynthesize = resynth;
    PatchSynthesisResult r = synthesize_patches(m, {ex}, o);
    PatchAtlas at = pack_patch_atlas(m, r.flat, r.images);
    return std::make_pair(std::move(r), std::move(at));
  };
  const auto a = run(5, {});
  const auto b = run(5, {});
  EXPECT_EQ(a.second.image.data, b.second.image.data) << "same seed, same atlas";
  const auto c = run(6, {});
  EXPECT_NE(a.second.image.data, c.second.image.data);
  const int k = a.first.order[a.first.order.size() / 2];
  const auto d = run(5, {k});
  ASSERT_EQ(d.first.images.size(), a.first.images.size());
  for (std::size_t p = 0; p < a.first.images.size(); ++p) {
    // Inside pixels: patch k changes, every other patch is kept bit for bit.
    const FlatPatch& fp = a.first.flat.patches[p];
    bool same = true;
    for (std::size_t i = 0; i < fp.pixel.size(); ++i)
      if (fp.pixel[i] == PatchPixel::Inside)
        for (int ch = 0; ch < 3; ++ch)
          same = same && a.first.images[p].data[i * 3 + ch] == d.first.images[p].data[i * 3 + ch];
    if (static_cast<int>(p) == k) {
      EXPECT_FALSE(same) << "patch " << p;
    } else {
      EXPECT_TRUE(same) << "patch " << p;
    }
  }
}

TEST(PatchSynthesis, SameBytesForOneThreadAndTwoThreads) {
  // Patches run as parallel tasks once the neighbours they read are done
  // (their rotations' search indexes built concurrently on first use), and
  // the final boundary fill runs over the patches in parallel; the result
  // must not depend on the schedule or the thread count.
  const Image ex = make_noise(40, 4, 3);
  auto run = [&](ElSearch search) {
    Mesh m;
    make_icosphere(m, 2);
    PatchSynthesisOptions o = small_options(sanitized() ? 16 : 24);
    o.partition.max_faces = 12;  // many patches, so several are ready at once
    o.field = PatchField::Constant;
    o.el.search = search;
    o.seed = 9;
    return synthesize_patches(m, {ex}, o);
  };
  for (ElSearch search : {ElSearch::Approximate, ElSearch::Exhaustive}) {
    PatchSynthesisResult all;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
      all = run(search);
    }
    PatchSynthesisResult one;
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
      one = run(search);
    }
    ASSERT_GT(all.images.size(), 8u);
    ASSERT_EQ(all.images.size(), one.images.size());
    EXPECT_EQ(all.order, one.order);
    EXPECT_EQ(all.texels, one.texels);
    EXPECT_EQ(all.known_boundary, one.known_boundary);
    EXPECT_GT(all.known_boundary, 0u);
    for (std::size_t p = 0; p < all.images.size(); ++p)
      EXPECT_EQ(all.images[p].data, one.images[p].data) << "patch " << p;
  }
}

TEST(PatchSynthesis, BadInputThrows) {
  Mesh m;
  make_icosphere(m, 1);
  const Image ex = make_noise(32, 4, 1);
  PatchSynthesisOptions o = small_options(16);
  EXPECT_THROW(synthesize_patches(m, {}, o), InvalidInputError);
  EXPECT_THROW(synthesize_patches(m, {ex, Image(32, 32, 1)}, o), InvalidInputError);
  PatchSynthesisOptions multi = o;
  multi.multi = MultiTexture::Illumination;
  EXPECT_THROW(synthesize_patches(m, {ex}, multi), InvalidInputError);
  PatchSynthesisOptions vs = o;
  vs.multi = MultiTexture::VertexScalar;
  vs.vertex_scalar = {1.0, 2.0};
  EXPECT_THROW(synthesize_patches(m, {ex, ex}, vs), InvalidInputError);
  PatchSynthesisOptions rs = o;
  rs.resynthesize = {100000};
  EXPECT_THROW(synthesize_patches(m, {ex}, rs), InvalidInputError);
  PatchSynthesisOptions cv = o;
  cv.constant_vector = {0, 0, 0};
  EXPECT_THROW(synthesize_patches(m, {ex}, cv), InvalidInputError);
  // A 9x9 window fits a 10x10 exemplar unrotated, but no rotation by 45
  // degrees of it: thrown inside a patch task, it must reach the caller.
  const Image tiny = make_noise(10, 2, 1);
  PatchSynthesisOptions rot = o;
  rot.field = PatchField::Constant;
  rot.el.rotations = 8;
  try {
    synthesize_patches(m, {tiny}, rot);
    ADD_FAILURE() << "no exception";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("rotated"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace surftex
