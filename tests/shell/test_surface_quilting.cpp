// SPDX-License-Identifier: AGPL-3.0-or-later
// Mesh quilting over curved surfaces and its embedding (Zhou et al. 2006,
// sections 3.1 and 3.2): quilt_surface, surface_quilt_to_texture,
// surface_quilt_displaced, embed_surface_quilt.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <iostream>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "geometry/self_intersections.h"
#include "shell/element_mesh.h"
#include "shell/quilting/embed_surface_quilt.h"
#include "shell/quilting/surface_quilting.h"
#include "shell/swatch.h"
#include "shell/swatch_generators.h"
#include "shell_test_util.h"

namespace surftex {
namespace {

constexpr double kPi = 3.14159265358979323846;

Swatch tiny_chainmail(std::uint64_t seed = 1) { return test::small_chainmail_swatch(seed, 10, 5); }
Swatch tiny_scatter(std::uint64_t seed = 1) { return test::small_scatter_swatch(seed); }
using test::weave_4x4;

// Fraction of elements (connected components) of `m` that are closed and consistently oriented.
double closed_fraction(const Mesh& m, int* count = nullptr) {
  const ElementMesh em = element_mesh_from(m);
  std::vector<int> comp;
  const int n = triangle_components(em, comp);
  std::vector<std::vector<int>> tris(static_cast<std::size_t>(n));
  for (std::size_t t = 0; t < comp.size(); ++t) tris[comp[t]].push_back(static_cast<int>(t));
  int closed = 0;
  for (auto& ts : tris) closed += is_closed_oriented(extract_triangles(em, ts)) ? 1 : 0;
  if (count) *count = n;
  return n ? static_cast<double>(closed) / n : 0.0;
}

// A right-angle concave valley: a 2 x 1 grid folded up along x = 1.
void make_valley(Mesh& m, int nx, int ny, double angle) {
  make_grid(m, nx, ny, 2.0, 1.0);
  for (VertexIndex v : m.vertices()) {
    const Point3 p = m.point(v);
    if (p.x() > 1.0) {
      const double t = p.x() - 1.0;
      m.point(v) = Point3(1.0 + t * std::cos(angle), p.y(), t * std::sin(angle));
    }
  }
}

TEST(SurfaceQuilting, SphereChainmailCoversEveryFaceKeepsRingsClosedAndEmbedsWithLowerStretch) {
  Mesh base;
  make_icosphere(base, test::sanitized() ? 1 : 2);
  const Swatch sw = tiny_chainmail();
  SurfaceQuiltOptions o;
  o.relative_size = 0.45;
  SurfaceQuilt q;
  const SurfaceQuiltResult r = quilt_surface(base, sw, q, o);
  EXPECT_GT(r.steps, 1);
  EXPECT_GT(r.elements, 20);
  EXPECT_EQ(r.faces, q.tris.size());
  // Every base face got texture: some output vertex lies on or near each face's neighbourhood.
  std::vector<char> touched(base.number_of_faces(), 0);
  for (const SurfaceQuiltVertex& v : q.vertices) {
    ASSERT_GE(v.face, 0);
    ASSERT_LT(static_cast<std::size_t>(v.face), base.number_of_faces());
    touched[static_cast<std::size_t>(v.face)] = 1;
  }
  std::size_t n_touched = 0;
  for (char t : touched) n_touched += t;
  EXPECT_GT(n_touched, base.number_of_faces() * 8 / 10);

  // Elements closed where the swatch's were (all chain-mail rings are closed).
  for (const SwatchElement& e : sw.elements) ASSERT_TRUE(e.closed);
  Mesh displaced;
  surface_quilt_displaced(base, q, 0.05, displaced);
  int n_el = 0;
  const double frac = closed_fraction(displaced, &n_el);
  std::cout << "[ sphere ] steps " << r.steps << ", elements " << r.elements << " (" << n_el << " components, closed "
            << frac << "), faces " << r.faces << ", stitched " << r.stats.stitched << ", refused "
            << r.stats.stitch_refused << ", shrunk " << r.patches_shrunk << "\n";
  EXPECT_GE(frac, 0.9);

  EmbedSurfaceQuiltOptions eo;
  eo.stretch.iterations = 10;
  Mesh out;
  const EmbedSurfaceQuiltResult er = embed_surface_quilt(base, q, out, eo);
  // Every quilt face is embedded, less those of the elements that still
  // crossed after the embedding (removed: chain-mail rings are compact).
  if (er.crossing_elements == 0)
    EXPECT_EQ(out.number_of_faces(), q.tris.size());
  else
    EXPECT_LT(out.number_of_faces(), q.tris.size());
  EXPECT_LE(er.crossing_elements, static_cast<std::size_t>(q.elements) / 10);
  EXPECT_EQ(er.embed.self_intersecting_pairs, 0u);
  EXPECT_GE(er.stretch.stretch_before, 1.0 - 1e-9);
  EXPECT_GE(er.stretch.stretch_after, 1.0 - 1e-9);
  EXPECT_LE(er.stretch.stretch_after, er.stretch.stretch_before);
  EXPECT_TRUE(er.embed.checked);
  std::cout << "[ sphere ] stretch " << er.stretch.stretch_before << " -> " << er.stretch.stretch_after
            << ", outside " << er.embed.outside << ", self-intersecting pairs " << er.embed.self_intersecting_pairs
            << "\n";
  // The embedded rings hug the sphere: every vertex within the shell (radius 1 .. 1 + height).
  for (VertexIndex v : out.vertices()) {
    const double d = std::sqrt(CGAL::squared_distance(out.point(v), Point3(0, 0, 0)));
    EXPECT_GT(d, 0.9);
    EXPECT_LT(d, 1.0 + 1.2 * er.shell_height);
  }
}

TEST(SurfaceQuilting, SameSeedSameOutputOtherSeedDiffers) {
  Mesh base;
  make_icosphere(base, 1);
  const Swatch sw = tiny_scatter();
  SurfaceQuiltOptions o;
  o.relative_size = 0.5;
  o.seed = 7;
  SurfaceQuilt a, b, c;
  quilt_surface(base, sw, a, o);
  quilt_surface(base, sw, b, o);
  o.seed = 8;
  quilt_surface(base, sw, c, o);
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.tris, b.tris);
  for (std::size_t i = 0; i < a.vertices.size(); ++i) {
    EXPECT_EQ(a.vertices[i].face, b.vertices[i].face);
    EXPECT_EQ(a.vertices[i].b1, b.vertices[i].b1);
    EXPECT_EQ(a.vertices[i].b2, b.vertices[i].b2);
    EXPECT_EQ(a.vertices[i].z, b.vertices[i].z);
  }
  bool differs = a.vertices.size() != c.vertices.size();
  for (std::size_t i = 0; !differs && i < a.vertices.size(); ++i)
    differs = a.vertices[i].face != c.vertices[i].face || a.vertices[i].b1 != c.vertices[i].b1;
  EXPECT_TRUE(differs);
}

// Figure 8: in a concave valley the naive local-frame displacement makes
// elements of the two sides run into each other; the shell-map embedding of
// the same quilt (shell about one base edge thick) does not add intersections.
TEST(SurfaceQuilting, ConcaveValleyShellEmbeddingHasNoSelfIntersectionsNaiveHas) {
  Mesh base;
  make_valley(base, 24, 12, kPi / 2);
  const Swatch sw = tiny_scatter(3);
  SurfaceQuiltOptions o;
  o.relative_size = 0.5;
  o.up = {0, 1, 0};  // along the crease: one consistent grid direction on both sides
  SurfaceQuilt q;
  quilt_surface(base, sw, q, o);
  ASSERT_GT(q.elements, 10);
  EmbedSurfaceQuiltOptions eo;
  eo.shell_height = 1.0;  // about one base edge: the shell is embedded, the naive frames overlap at the crease
  eo.stretch.iterations = 5;
  Mesh out;
  const EmbedSurfaceQuiltResult er = embed_surface_quilt(base, q, out, eo);
  Mesh naive;
  surface_quilt_displaced(base, q, er.shell_height, naive);
  const std::size_t naive_hits = count_self_intersections(naive);
  // The same quilt on the unfolded valley (same faces, flat): overlaps the quilting itself made.
  Mesh flat;
  make_valley(flat, 24, 12, 0.0);
  Mesh unfolded;
  surface_quilt_displaced(flat, q, er.shell_height, unfolded);
  const std::size_t own_hits = count_self_intersections(unfolded);
  std::cout << "[ valley ] unfolded pairs " << own_hits << "\n";
  std::cout << "[ valley ] elements " << q.elements << ", shell height " << er.shell_height << ", clamped "
            << er.clamped_vertices << ", naive pairs " << naive_hits << ", shell-map pairs "
            << er.embed.self_intersecting_pairs << ", outside " << er.embed.outside << "\n";
  EXPECT_GT(naive_hits, 0u);
  EXPECT_TRUE(er.embed.checked);
  // The quilt is not yet overlap-free by itself (refused merges, see the
  // report), so 0 is not asserted here (the shell-level test in
  // test_shell_stretch_embed.cpp asserts 0 for disjoint elements): the shell
  // map adds no intersection beyond the quilt's own, and clearly fewer than
  // the naive embedding.
  EXPECT_LE(er.embed.self_intersecting_pairs, own_hits);
  // (Factor 3: with the sub-cell placement of issue #8 this quilt measures
  // 74 shell-map pairs against 296 naive ones, exactly the former factor 4.)
  EXPECT_LT(er.embed.self_intersecting_pairs * 3, naive_hits);
}

// The embedded quilt's self-intersections are split into pairs inside one
// element and pairs between two elements; the split is checked against a
// per-element count, and no embedded vertex leaves the shell (elements that
// reach far beyond a patch used to be projected onto a distant patch plane,
// moved there and come back as spikes). Torus: curvature of both signs.
TEST(SurfaceQuilting, TorusChainmailIntersectionsSplitByElementAndNoVertexLeavesTheShell) {
  Mesh base;
  const double R = 1.0, r = 0.45;
  make_torus(base, R, r, test::sanitized() ? 24 : 40, test::sanitized() ? 12 : 20);
  const Swatch sw = tiny_chainmail(2);
  std::size_t swatch_within = 0;  // the swatch's own intersections inside its elements
  {
    std::vector<std::vector<int>> tris(sw.elements.size());
    for (std::size_t f = 0; f < sw.face_element.size(); ++f) tris[sw.face_element[f]].push_back(static_cast<int>(f));
    for (auto& t : tris) {
      Mesh one;
      mesh_from_elements({extract_triangles(sw.mesh, t)}, one);
      swatch_within += count_self_intersections(one);
    }
  }
  SurfaceQuiltOptions o;
  o.relative_size = 0.3;
  SurfaceQuilt q;
  const SurfaceQuiltResult qr = quilt_surface(base, sw, q, o);
  EmbedSurfaceQuiltOptions eo;
  eo.stretch.iterations = 5;
  Mesh out;
  const EmbedSurfaceQuiltResult er = embed_surface_quilt(base, q, out, eo);
  ASSERT_TRUE(er.embed.checked);
  EXPECT_EQ(er.self_intersections_within + er.self_intersections_between, er.embed.self_intersecting_pairs);
  // Recount inside every element on its own.
  const ElementMesh all = element_mesh_from(out);
  auto el = out.property_map<FaceIndex, int>(kFaceElement.name).first;
  std::vector<std::vector<int>> by_el(static_cast<std::size_t>(q.elements));
  for (FaceIndex f : out.faces()) by_el[static_cast<std::size_t>(el[f])].push_back(static_cast<int>(f.idx()));
  std::size_t within = 0;
  for (const auto& t : by_el) {
    Mesh one;
    mesh_from_elements({extract_triangles(all, t)}, one);
    within += count_self_intersections(one);
  }
  EXPECT_EQ(within, er.self_intersections_within);
  std::cout << "[ torus ] elements " << q.elements << ", not expressible " << qr.elements_not_expressible
            << ", stitched " << qr.stats.stitched << ", refused " << qr.stats.stitch_refused << ", stretch "
            << er.stretch.stretch_before << " -> " << er.stretch.stretch_after << ", pairs within "
            << er.self_intersections_within << " (swatch " << swatch_within << "), between "
            << er.self_intersections_between << ", outside " << er.embed.outside << " (below " << er.outside_below
            << ", above " << er.outside_above << ", (u, v) " << er.outside_uv << "), z fitted " << qr.z_fitted_elements << "\n";
  // Every vertex lies in the shell: distance to the torus' core circle in [r - eps, r + shell height + eps].
  for (VertexIndex v : out.vertices()) {
    const Point3 p = out.point(v);
    const double rho = std::hypot(p.x(), p.y());
    const double d = std::hypot(rho - R, p.z());
    EXPECT_GT(d, r - 0.05);
    EXPECT_LT(d, r + 1.3 * er.shell_height + 0.05);
  }
}

TEST(SurfaceQuilting, RejectsBadInput) {
  Mesh base;
  make_icosphere(base, 1);
  const Swatch sw = tiny_scatter();
  SurfaceQuilt q;
  SurfaceQuiltOptions o;
  o.relative_size = 0;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.max_area_distortion = 1;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.up = {0, 0, 0};
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  for (int samples : {0, 5}) {
    o = {};
    o.scatter_bare_samples = samples;
    EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError) << samples;
  }
  Mesh empty;
  EXPECT_THROW(quilt_surface(empty, sw, q, {}), InvalidInputError);
  // No atlas on the base: texture coordinates cannot be made.
  quilt_surface(base, sw, q, {});
  Mesh out;
  EXPECT_THROW(surface_quilt_to_texture(base, q, out), InvalidInputError);
  EmbedSurfaceQuiltOptions eo;
  eo.shell_height = -1;
  EXPECT_THROW(embed_surface_quilt(base, q, out, eo), InvalidInputError);
}

}  // namespace
}  // namespace surftex

namespace surftex {
namespace {

// Issue #8 (curved-surface quilting was a tangle: on the bunny 816 of 888
// merges refused for their loop counts, ~183K face pairs intersecting between
// elements). A weave on a cylinder (curved one way, flattened without
// distortion, so every defect is the quilting's own): threads must continue
// across patch borders and be merged with the threads already there, not laid
// beside or across them. Measured (Release, this configuration): before the
// issue-8 fixes 52 elements, 64 of 144 merges stitched, 5031 of 25028 faces'
// pairs intersecting between elements (0.20 per face); after: 41 elements, 76
// of 193 stitched, 2523 of 23088 (0.11). The stitched fraction itself did not
// improve (more merges are tried, the merge of section 2.7 still refuses
// about half, as on the plane): it is bounded, not claimed.
TEST(SurfaceQuilting, CylinderWeaveThreadsAreStitchedAcrossPatchesAndStayClosed) {
  Mesh base;
  make_cylinder(base, 1.0, 2.0, test::sanitized() ? 20 : 30, test::sanitized() ? 8 : 12);
  const Swatch sw = weave_4x4(6, 6);
  SurfaceQuiltOptions o;
  o.relative_size = test::sanitized() ? 0.45 : 0.35;
  o.up = {0, 0, 1};  // along the axis: one consistent grid direction everywhere
  SurfaceQuilt q;
  const SurfaceQuiltResult r = quilt_surface(base, sw, q, o);
  const std::size_t tried = r.stats.stitched + r.stats.stitch_refused;
  std::cout << "[ cylinder weave ] steps " << r.steps << ", elements " << r.elements << ", stitched "
            << r.stats.stitched << ", refused " << r.stats.stitch_refused << " (loops " << r.stats.refused_loops
            << ", border " << r.stats.refused_border << "), partial " << r.elements_partial << ", seams broken "
            << r.seams_broken << "\n";
  ASSERT_GT(tried, 5u);
  // At least 12% stitched. (Before issue #8's stitch checks about half were;
  // the refused ones are zips that crossed their own element: with the checks
  // off, 76 stitched of 193, 552 intersecting pairs within elements; on,
  // 27 of 159 and 33, before elements past the open ends were removed.)
  EXPECT_GT(static_cast<double>(r.stats.stitched), 0.12 * static_cast<double>(tried));
  // Threads grow longer than the swatch's (they continue across patches).
  EXPECT_LT(r.elements, static_cast<int>(sw.elements.size()) * r.steps / 2);
  Mesh displaced;
  surface_quilt_displaced(base, q, (q.z_max - q.z_min) * q.scale, displaced);
  int n_el = 0;
  const double frac = closed_fraction(displaced, &n_el);
  auto el = displaced.property_map<FaceIndex, int>(kFaceElement.name).first;
  std::size_t between = 0, within = 0;
  for (const FacePair& fp : self_intersecting_faces(displaced))
    (el[FaceIndex(fp[0])] == el[FaceIndex(fp[1])] ? within : between) += 1;
  std::cout << "[ cylinder weave ] components " << n_el << ", closed " << frac << ", faces "
            << displaced.number_of_faces() << ", intersecting pairs within " << within << ", between " << between
            << "\n";
  EXPECT_GE(frac, 0.9);  // the swatch's threads are closed tubes
  // Overlapping threads of different elements (duplicates, misplaced patches).
  EXPECT_LT(static_cast<double>(between), 0.15 * static_cast<double>(displaced.number_of_faces()));
  // Regression (issue #8): threads hanging over the cylinder's open ends were
  // clamped onto the border line (flat ribbons): 7511 pairs within elements
  // of 20690 faces; now such elements are removed: 18 of 9324.
  EXPECT_LT(static_cast<double>(within), 0.02 * static_cast<double>(displaced.number_of_faces()));
}

}  // namespace
}  // namespace surftex

namespace surftex {
namespace {

// Issue #8, session 4: each patch's frame follows the guidance field at its
// seed, but on a curved surface the texture placed by the neighbouring
// patches runs in the field's direction at *their* seeds, seen through this
// patch's flattening: with a field that winds around a cylinder (up tilted
// against the axis: a helix field, whose projected direction turns with the
// angle around the axis) translated swatches meet the old threads at an angle
// and the loops of the cuts do not face each other. The placement search now
// also turns the frame (SurfaceQuiltOptions::rotation_max_deg). Measured
// (Release, seeds 1-4, relative size 0.35, with the trimmed cut ends of
// MergeOptions::trim_overlapping_ends): translations only 68 of 489 merges
// stitched (13.9%; seeds 1 and 2: 30 of 257, 11.7%; at most 16.4% for any two
// seeds), turned 110 of 546 (20.1%; seeds 1 and 2: 64 of 291, 22.0%), and
// between-element crossings 2627 -> 1842. Before the trimming: 5.8% -> 9.8%.
TEST(SurfaceQuilting, HelixFieldCylinderWeaveTurnedPlacementsStitchMoreThreads) {
  Mesh base;
  make_cylinder(base, 1.0, 2.0, 30, 12);
  const Swatch sw = weave_4x4(6, 6);
  SurfaceQuiltOptions o;
  o.relative_size = test::sanitized() ? 0.45 : 0.35;
  o.up = {0.0, 0.6, 0.8};
  // This test is about the turn search against the field's frame (the
  // figures above): the whole-overlap alignment of session 5 (tested in
  // HelixFieldCylinderWeaveOverlapAlignedPlacementsJumpLess) leaves little
  // to turn (turned 6 of 55 placements, 78 of 279 stitched, seeds 1 and 2).
  o.align_to_overlap = false;
  // The figures above were measured with refused inputs dropped whole; their
  // kept cut parts (issue #8, session 5) do not change what this test is
  // about and made it about 30% slower.
  o.step.keep_cut_refused_inputs = false;
  std::size_t stitched = 0, tried = 0;
  int turned = 0, steps = 0;
  // (Under the sanitizers at relative size 0.45, seeds 1 and 2: turned 40 of
  // 183 stitched, 21.9%; translations only 21 of 154, 13.6%.)
  const std::vector<std::uint64_t> seeds{1, 2};
  for (std::uint64_t seed : seeds) {
    o.seed = seed;
    SurfaceQuilt q;
    const SurfaceQuiltResult r = quilt_surface(base, sw, q, o);
    stitched += r.stats.stitched;
    tried += r.stats.stitched + r.stats.stitch_refused;
    turned += r.patches_turned;
    steps += r.steps;
    std::cout << "[ helix weave ] seed " << seed << ": steps " << r.steps << ", turned " << r.patches_turned
              << " (mean |turn| " << r.turn_deg_sum / std::max(1, r.steps) << " deg), stitched " << r.stats.stitched
              << ", refused " << r.stats.stitch_refused << " (geometry " << r.stats.refused_geometry << "), coincident "
              << r.stats.coincident << ", " << r.seconds << " s (turn search " << r.seconds_turn << " s)\n";
  }
  ASSERT_GT(tried, 20u);
  // Most placements find a better fit turned.
  EXPECT_GT(2 * turned, steps);
  // Translations only: at most 16.4% (see above).
  EXPECT_GT(static_cast<double>(stitched), 0.18 * static_cast<double>(tried));
}

TEST(SurfaceQuilting, RotationSearchOptionsAreChecked) {
  Mesh base;
  make_icosphere(base, 1);
  const Swatch sw = tiny_scatter();
  SurfaceQuilt q;
  SurfaceQuiltOptions o;
  o.rotation_max_deg = 91;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.rotation_step_deg = 0;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.rotation_match_vertices = 0;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  // 0 = translations only: no placement is turned.
  o = {};
  o.rotation_max_deg = 0;
  const SurfaceQuiltResult r = quilt_surface(base, sw, q, o);
  EXPECT_EQ(r.patches_turned, 0);
  EXPECT_EQ(r.turn_deg_sum, 0.0);
}

}  // namespace
}  // namespace surftex

namespace surftex {
namespace {

// Fraction of the base faces with no quilt vertex within `radius` (mesh
// units) of their centroid, distances measured between the centroid and the
// foot point of each quilt vertex on its base face (a bare spot of the base
// surface, wider than the gaps between a weave's threads when radius is
// about a thread spacing).
double bare_fraction(const Mesh& base, const SurfaceQuilt& q, double radius) {
  std::vector<std::array<Point3, 3>> fp(base.number_of_faces());
  for (FaceIndex f : base.faces()) {
    int k = 0;
    for (VertexIndex v : base.vertices_around_face(base.halfedge(f))) fp[f.idx()][static_cast<std::size_t>(k++)] = base.point(v);
  }
  std::vector<Point3> foot;
  foot.reserve(q.vertices.size());
  for (const SurfaceQuiltVertex& v : q.vertices) {
    const auto& t = fp[static_cast<std::size_t>(v.face)];
    const double b0 = 1 - v.b1 - v.b2;
    foot.emplace_back(b0 * t[0].x() + v.b1 * t[1].x() + v.b2 * t[2].x(), b0 * t[0].y() + v.b1 * t[1].y() + v.b2 * t[2].y(),
                      b0 * t[0].z() + v.b1 * t[1].z() + v.b2 * t[2].z());
  }
  std::size_t bare = 0;
  for (const auto& t : fp) {
    const Point3 c((t[0].x() + t[1].x() + t[2].x()) / 3, (t[0].y() + t[1].y() + t[2].y()) / 3,
                   (t[0].z() + t[1].z() + t[2].z()) / 3);
    bool covered = false;
    for (const Point3& p : foot)
      if (CGAL::squared_distance(c, p) <= radius * radius) {
        covered = true;
        break;
      }
    bare += covered ? 0 : 1;
  }
  return fp.empty() ? 0.0 : static_cast<double>(bare) / static_cast<double>(fp.size());
}

// Issue #8, session 5: an input thread whose stitch to the old thread was
// refused was dropped whole (on the 5K-face bunny 1,364 of 2,316 placed
// threads), and its patch was marked processed: bare strips of base surface
// where the old thread ended and the new one was missing. Now the refused
// input keeps its part beyond the cut, closed at the cut
// (QuiltStepOptions::keep_cut_refused_inputs), so that the two abut.
TEST(SurfaceQuilting, RefusedInputThreadsKeepTheirCutPartSoNoStripIsLeftBare) {
  Mesh base;
  make_cylinder(base, 1.0, 2.0, 20, 8);
  const Swatch sw = weave_4x4(6, 6);
  SurfaceQuiltOptions o;
  o.relative_size = 0.45;
  o.up = {0.0, 0.6, 0.8};  // a helix field: many refused stitches
  o.scatter_thread_parts = 0;  // (the scatter fill's thread pieces would cover the bare strips measured here)
  // Runs: refused inputs dropped whole (their cut parts not kept); the
  // defaults (cut parts kept, elements trimmed at the open ends); and the
  // elements past the open ends removed whole (trim_at_border off, the state
  // before session 6).
  double bare[3] = {0, 0, 0};
  int closed_ok[3] = {0, 0, 0};
  std::size_t z_fitted = 0;
  for (int run = 0; run < 3; ++run) {
    const int keep = run >= 1 ? 1 : 0;
    o.step.keep_cut_refused_inputs = keep == 1;
    o.trim_at_border = run <= 1;
    SurfaceQuilt q;
    const SurfaceQuiltResult r = quilt_surface(base, sw, q, o);
    // One thread spacing (swatch units) in mesh units: wider than any gap of an intact weave.
    bare[run] = bare_fraction(base, q, WeaveOptions{}.spacing * q.scale);
    Mesh displaced;
    surface_quilt_displaced(base, q, (q.z_max - q.z_min) * q.scale, displaced);
    closed_ok[run] = closed_fraction(displaced) >= 0.9;
    // Every height lies in the output's z range, which is the swatch's
    // (SurfaceQuiltOptions::max_z_growth 0): the deformations and stitches
    // moved some elements past it, and they are shifted back into it (before
    // issue #8's session 5 they were left there and mapped out of the shell).
    EXPECT_EQ(q.z_min, sw.bbox_min[2]);
    EXPECT_EQ(q.z_max, sw.bbox_max[2]);
    z_fitted += r.z_fitted_elements;
    for (const SurfaceQuiltVertex& v : q.vertices) {
      ASSERT_GE(v.z, q.z_min);
      ASSERT_LE(v.z, q.z_max);
    }
    std::cout << "[ refused inputs ] keep cut " << keep << ": stitched " << r.stats.stitched << ", refused "
              << r.stats.stitch_refused << ", dropped " << r.stats.in_dropped << ", kept cut " << r.stats.in_cut_added
              << " (" << r.stats.in_cut_components << " parts), faces " << r.faces << ", bare faces " << bare[run]
              << ", steps " << r.steps << ", aligned " << r.patches_aligned << " (" << r.align_deg_sum / std::max(1, r.patches_aligned) << " deg), dropped new " << r.dropped_new << ", coincident " << r.stats.coincident << " (cut kept " << r.stats.coincident_cut_added << ")" << ", past border " << r.elements_past_border << ", trimmed " << r.elements_trimmed << ", stretched " << r.elements_stretched << ", jump " << r.overlap_turn_sum / std::max(1e-30, r.overlap_area) << "\n";
    if (keep == 1) {
      EXPECT_GT(r.stats.in_cut_added, 0u);
    } else {
      EXPECT_EQ(r.stats.in_cut_added, 0u);
    }
  }
  // Some element was fitted (since the aligned patches are no longer turned,
  // issue #8 session 5, none in the run without the cut parts).
  EXPECT_GT(z_fitted, 0u);
  EXPECT_TRUE(closed_ok[0]);
  EXPECT_TRUE(closed_ok[1]);  // the kept parts and the pieces trimmed at the ends are closed
  // History (Release; 20 x 8 cylinder, relative size 0.45): 16.3% of the
  // faces bare with whole refused threads dropped, 5.6% with their cut parts
  // kept (session 5); with the patches aligned to the overlap 8.75%, all of
  // it along the two open ends (per ring of faces from the bottom: 9 4 3 0 0
  // 0 3 9 bare of 40): the aligned weave runs obliquely, so every long
  // stitched thread crossed an end and was removed whole. Session 6: with the
  // planar cut ends meeting (element_merging), threads stitch (80 stitched /
  // 12 refused, was 22 / 82) and grow long, and with trim_at_border off
  // nearly all of them cross an end: 280 faces are left, 87.5% bare. Trimmed
  // at the ends (the default): 0 bare, 12.8K faces.
  EXPECT_LT(bare[1], 0.03);
  EXPECT_LE(bare[1], bare[0]);
  EXPECT_GT(bare[2], 0.3);  // what trimming at the ends restores from
}

// The refused inputs' cut parts and the z fitting (issue #8, session 5) keep
// the quilt deterministic: same seed, same output on 1 and 2 threads; so do
// the groups of a step deformed and merged in parallel (issue 19 item 2).
TEST(SurfaceQuilting, WeaveCylinderWithCutPartsSameOutputOnOneAndTwoThreads) {
  Mesh base;
  make_cylinder(base, 1.0, 2.0, 16, 6);
  const Swatch sw = weave_4x4(4, 5);
  SurfaceQuiltOptions o;
  o.relative_size = 0.5;
  o.up = {0.0, 0.6, 0.8};
  o.rotation_max_deg = 0;  // (the turn search has its own determinism; keeps this test short)
  SurfaceQuilt q[2];
  SurfaceQuiltResult r[2];
  for (int k = 0; k < 2; ++k) {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(k + 1));
    r[k] = quilt_surface(base, sw, q[k], o);
  }
  EXPECT_GT(r[0].stats.in_cut_added, 0u);  // the new path is taken
  EXPECT_GT(r[0].stats.stitched, 10u);      // groups are merged (in parallel on 2 threads)
  EXPECT_EQ(r[0].stats.stitched, r[1].stats.stitched);
  EXPECT_EQ(r[0].stats.in_cut_added, r[1].stats.in_cut_added);
  EXPECT_EQ(r[0].z_fitted_elements, r[1].z_fitted_elements);
  ASSERT_EQ(q[0].tris, q[1].tris);
  ASSERT_EQ(q[0].vertices.size(), q[1].vertices.size());
  for (std::size_t i = 0; i < q[0].vertices.size(); ++i) {
    ASSERT_EQ(q[0].vertices[i].face, q[1].vertices[i].face);
    ASSERT_EQ(q[0].vertices[i].b1, q[1].vertices[i].b1);
    ASSERT_EQ(q[0].vertices[i].b2, q[1].vertices[i].b2);
    ASSERT_EQ(q[0].vertices[i].z, q[1].vertices[i].z);
  }
}

// The final removal of stretched elements (SurfaceQuiltOptions::max_edge_stretch):
// at 0 nothing is removed for it; at a fraction of the swatch's longest edge
// every element goes; with the default every remaining edge is within the
// limit (measured as the option states: feet on the base mesh and height).
TEST(SurfaceQuilting, StretchedElementsAreRemovedAtTheEnd) {
  Mesh base;
  make_icosphere(base, 2);
  const Swatch sw = tiny_scatter();
  SurfaceQuiltOptions o;
  o.relative_size = 0.5;
  o.refill_rounds = 0;  // (refilled or scattered elements would be counted again)
  o.scatter_attempts = 0;
  SurfaceQuilt q;
  o.max_edge_stretch = 0;
  const SurfaceQuiltResult keep = quilt_surface(base, sw, q, o);
  EXPECT_EQ(keep.elements_stretched, 0u);
  ASSERT_GT(keep.elements, 0);
  // A bound below the swatch's own longest edge: every blob (compact) goes.
  o.max_edge_stretch = 0.5;
  o.resolve_crossings = false;
  const SurfaceQuiltResult none = quilt_surface(base, sw, q, o);
  EXPECT_EQ(none.elements, 0);
  EXPECT_GE(static_cast<int>(none.elements_stretched), keep.elements);
  o.max_edge_stretch = -1;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.relative_size = 0.5;
  const SurfaceQuiltResult def = quilt_surface(base, sw, q, o);
  EXPECT_LE(def.edge_stretch_max, o.max_edge_stretch + 1e-9);
  EXPECT_GT(def.elements, keep.elements / 2);
}

}  // namespace
}  // namespace surftex

namespace surftex {
namespace {

// Issue #8, session 5: each patch's frame was aligned with the field at its
// own seed (and turned by at most +-15 degrees to match P_out), so on a
// curved surface a placement's threads met the earlier ones at an angle over
// most of the overlap (on the 5K-face bunny: mean 11.9 degrees, 40% of the
// overlap area over 10). The frame is now turned, before the turn search, by
// the quarter-turn circular mean of the angles between the earlier
// placements' +y (mapped through this patch's flattening) and +y over the
// whole overlap (SurfaceQuiltOptions::align_to_overlap).
TEST(SurfaceQuilting, HelixFieldCylinderWeaveOverlapAlignedPlacementsJumpLess) {
  Mesh base;
  make_cylinder(base, 1.0, 2.0, test::sanitized() ? 20 : 30, test::sanitized() ? 8 : 12);
  const Swatch sw = weave_4x4(6, 6);
  SurfaceQuiltOptions o;
  o.relative_size = test::sanitized() ? 0.45 : 0.35;
  o.up = {0.0, 0.6, 0.8};  // a helix field
  o.step.keep_cut_refused_inputs = false;
  auto run = [&](bool align, SurfaceQuiltResult& r) {
    o.align_to_overlap = align;
    SurfaceQuilt q;
    r = quilt_surface(base, sw, q, o);
    const double jump = r.overlap_area > 0 ? r.overlap_turn_sum / r.overlap_area : 0.0;
    const double over10 = r.overlap_area > 0 ? r.overlap_area_over10 / r.overlap_area : 0.0;
    std::cout << "[ helix align ] align " << align << ": steps " << r.steps << ", aligned " << r.patches_aligned
              << ", turned " << r.patches_turned << ", jump " << jump << " deg, over 10 deg " << over10
              << ", stitched " << r.stats.stitched << ", refused " << r.stats.stitch_refused << "\n";
    return jump;
  };
  SurfaceQuiltResult on, off;
  const double j_on = run(true, on), j_off = run(false, off);
  ASSERT_GT(on.overlap_area, 0.0);
  EXPECT_GT(on.patches_aligned, on.steps / 2);
  EXPECT_EQ(off.patches_aligned, 0);
  // Measured (Release): 12.7 degrees unaligned (45% of the overlap over 10),
  // under 0.01 aligned (the cylinder is developable: its flattenings differ
  // by rigid motions only).
  EXPECT_LT(j_on, 0.2 * j_off);
  EXPECT_LT(j_on, 2.0);
  // A sphere (not developable): what a rigid frame cannot remove stays
  // (SurfaceQuiltResult::align_residual_sum: 12.0 degrees here), but the
  // jump still drops. Measured (Release): 14.6 -> 11.5 degrees, 55% -> 40%
  // of the overlap over 10 (at relative size 0.15 on the 1,280-face sphere:
  // 12.4 -> 8.9; at 0.3 on 5,120 faces: 17.1 -> 16.8, residual 15.0: the
  // patches are too large for the sphere's curvature; translations only on
  // both sides: 13.6 -> 11.4). Skipped under the sanitizers (time).
  if (test::sanitized()) return;
  make_icosphere(base, 2);
  o.up = {0.0, 0.0, 1.0};
  o.relative_size = 0.2;
  const double s_on = run(true, on);
  std::cout << "[ sphere align ] residual " << on.align_residual_sum / std::max(1e-30, on.align_residual_weight) << " deg\n";
  EXPECT_GT(on.patches_aligned, on.steps / 2);
  EXPECT_LT(s_on, 13.0);  // unaligned: 14.6 (run only once here, for time)
}

TEST(SurfaceQuilting, AlignOptionsAreChecked) {
  Mesh base;
  make_icosphere(base, 1);
  const Swatch sw = tiny_scatter();
  SurfaceQuilt q;
  SurfaceQuiltOptions o;
  o.align_min_overlap = 1.5;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o.align_min_overlap = -0.1;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.aligned_rotation_max_deg = 91;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.align_sigma = 0;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
}

// SurfaceQuiltOptions::refill_rounds' default comes from the swatch: a
// swatch of threads (no compact element, no scatter fill after the rounds)
// gets 6 rounds, one of rings or pebbles 3; a given count is kept, and
// counts outside [-1, 8] are refused.
TEST(SurfaceQuilting, RefillRoundsDefaultToSixForThreadsAndThreeForCompactElements) {
  Mesh base;
  make_icosphere(base, 2);
  SurfaceQuilt q;
  SurfaceQuiltOptions o;
  o.relative_size = 0.5;
  const SurfaceQuiltResult threads = quilt_surface(base, weave_4x4(4, 5), q, o);
  EXPECT_EQ(threads.refill_rounds, 6);
  EXPECT_LE(threads.refill_rounds_run, 6);
  const SurfaceQuiltResult rings = quilt_surface(base, tiny_scatter(), q, o);
  EXPECT_EQ(rings.refill_rounds, 3);
  EXPECT_LE(rings.refill_rounds_run, 3);
  o.refill_rounds = 2;
  EXPECT_EQ(quilt_surface(base, weave_4x4(4, 5), q, o).refill_rounds, 2);
  for (int bad : {-2, 9}) {
    o.refill_rounds = bad;
    EXPECT_THROW(quilt_surface(base, tiny_scatter(), q, o), InvalidInputError);
  }
}

// Session 39: a chain-mail ring that crosses a neighbour when lifted is moved
// (along the normal, then aside) where that clears it, instead of removed, and
// the scatter fill tries its rings higher and lower where they would cross; on
// by default only for a swatch whose rings interlink (their boxes overlap),
// not for separate elements. The kept rings cross nothing: the quilt lifted as
// the finish tests it has no face pair intersecting between elements.
TEST(SurfaceQuilting, CrossingChainmailRingsAreMovedClearInsteadOfRemoved) {
  Mesh base;
  make_icosphere(base, 2);
  SurfaceQuiltOptions o;
  o.relative_size = 0.3;
  const Swatch sw = tiny_chainmail();
  auto between_pairs = [&](const SurfaceQuilt& q) {
    Mesh displaced;
    surface_quilt_lifted(base, q, sw.bbox_min[2], displaced);
    auto el = displaced.property_map<FaceIndex, int>(kFaceElement.name).first;
    std::size_t between = 0;
    for (const FacePair& fp : self_intersecting_faces(displaced)) between += el[FaceIndex(fp[0])] != el[FaceIndex(fp[1])];
    return between;
  };
  SurfaceQuilt on, off;
  const SurfaceQuiltResult r_on = quilt_surface(base, sw, on, o);
  o.lift_crossing_rings = 0;
  const SurfaceQuiltResult r_off = quilt_surface(base, sw, off, o);
  std::cout << "[ chain mail moves ] crossings " << r_on.crossings_resolved << ", moved clear "
            << r_on.crossings_lifted_clear << ", scattered " << r_on.scatter_placed << " (" << r_on.scatter_lifted
            << " lifted), elements " << r_on.elements << " (off: " << r_off.elements << ", scattered "
            << r_off.scatter_placed << ")\n";
  EXPECT_EQ(r_on.lift_crossing_rings, 1);
  EXPECT_EQ(r_off.lift_crossing_rings, 0);
  EXPECT_GT(r_on.crossings_lifted_clear, 0u);
  EXPECT_EQ(r_off.crossings_lifted_clear, 0u);
  // The scatter fill places rings a little higher or lower where they would cross.
  EXPECT_GT(r_on.scatter_lifted, 0u);
  EXPECT_EQ(r_off.scatter_lifted, 0u);
  EXPECT_GT(r_on.scatter_placed, r_off.scatter_placed);
  EXPECT_EQ(between_pairs(on), 0u);
  EXPECT_EQ(between_pairs(off), 0u);
  o.lift_crossing_rings = -1;
  ToriOptions to;  // separate tilted rings: no box reaches into another
  to.tori_x = to.tori_y = 3;
  to.segments = 12;
  to.sides = 6;
  Mesh tori;
  make_tori_swatch(tori, to);
  SurfaceQuilt sep;
  const SurfaceQuiltResult r_sep = quilt_surface(base, make_swatch(tori), sep, o);
  EXPECT_EQ(r_sep.lift_crossing_rings, 0);
  EXPECT_EQ(r_sep.crossings_lifted_clear, 0u);
  o.lift_crossing_rings = 2;
  EXPECT_THROW(quilt_surface(base, tiny_scatter(), sep, o), InvalidInputError);
}

}  // namespace
}  // namespace surftex

namespace surftex {
namespace {

// Issue #8, session 6: the whole-overlap alignment (align_to_overlap) carries
// the first patch's orientation over the surface and lets the texture drift
// away from the guidance field, whose role is to align the grid (section
// 3.1, "Using Guidance Vector Fields"). With a helix field on a cylinder
// (up tilted against the axis: the projected direction turns around it)
// the aligned placements ran at about 25 degrees to the field at their
// seeds. The alignment's turn is now bounded relative to the field
// (align_field_max_deg, here 10 degrees), and the guidance can be a smooth
// 4-symmetric field interpolated from the projected up (smooth_field; here
// constrained only where up lies nearly in the surface, |projection| >= 0.95,
// and smoothed strongly): it then turns little between seeds, so that
// following it and aligning to the neighbours no longer compete.
TEST(SurfaceQuilting, HelixFieldCylinderAlignedPlacementsDriftFromTheFieldBounded) {
  Mesh base;
  make_cylinder(base, 1.0, 2.0, 20, 8);
  const Swatch sw = weave_4x4(4, 5);
  SurfaceQuiltOptions o;
  o.relative_size = 0.45;
  o.up = {0.0, 0.6, 0.8};
  o.step.keep_cut_refused_inputs = false;
  o.field_min_projection = 0.95;
  o.field_smoothing = 1000;
  double jump = 0;
  auto run = [&](bool smooth, double bound) {
    o.smooth_field = smooth;
    o.align_field_max_deg = bound;
    SurfaceQuilt q;
    const SurfaceQuiltResult r = quilt_surface(base, sw, q, o);
    const double drift = r.drift_count ? r.drift_deg_sum / r.drift_count : 0.0;
    jump = r.overlap_area > 0 ? r.overlap_turn_sum / r.overlap_area : 0.0;
    std::cout << "[ helix drift ] smooth " << smooth << ", bound " << bound << ": drift " << drift << " deg ("
              << r.drift_count << " placements; against the projected up "
              << r.drift_up_deg_sum / std::max(1, r.drift_up_count) << "), aligned " << r.patches_aligned
              << ", bounded " << r.patches_align_bounded << ", jump " << r.overlap_turn_sum / std::max(1e-30, r.overlap_area)
              << " deg, " << r.seconds << " s\n";
    EXPECT_GT(r.drift_count, r.steps / 2);
    EXPECT_GT(r.patches_aligned, r.steps / 2);
    return drift;
  };
  // Measured (Release): the projected up, unbounded (the state before):
  // drift 24.5 degrees, jump 0 (the cylinder is developable); the projected
  // up, bounded to 10 degrees: drift 8.1 (the unaligned placements' turn
  // search goes to 15), jump 12.5 (the helix field turns between the seeds
  // and the texture now follows it; a smooth field constrained wherever
  // |projection| >= 0.3 and smoothed lightly: 6.3 and 14.7); the smooth
  // field here: drift 1.5, jump 0, no patch needed the bound.
  const double unbounded = run(false, 45);
  EXPECT_GT(unbounded, 15.0);
  // The bound alone (projected up): each aligned placement's turn away from
  // the field at its seed is at most 10 degrees (the flattening is conformal).
  const double up_bounded = run(false, 10);
  EXPECT_LT(up_bounded, 10.0);
  const double bounded = run(true, 10);
  EXPECT_LT(bounded, 5.0);
  EXPECT_LT(jump, 3.0);
}

// SurfaceQuiltOptions::trim_new_to_patch: new elements whose centroid falls
// off the patch keep their part on the patch, closed at the cut, instead of
// being dropped (their patch faces were marked processed all the same, so
// the thread was never placed there: the bunny's ear stayed bare).
TEST(SurfaceQuilting, NewElementsOffThePatchKeepTheirPartOnItClosed) {
  Mesh base;
  make_cylinder(base, 1.0, 2.0, 20, 8);
  const Swatch sw = weave_4x4(4, 5);
  SurfaceQuiltOptions o;
  o.relative_size = 0.45;
  o.up = {0.0, 0.6, 0.8};
  o.refill_rounds = 0;  // (the refill rounds trim new elements whatever the option says)
  o.scatter_thread_parts = 0;  // (nor would the scatter fill's thread pieces leave the dropped space alone)
  SurfaceQuiltResult r[2];
  std::size_t faces[2] = {0, 0};
  for (int trim = 0; trim < 2; ++trim) {
    o.trim_new_to_patch = trim == 1;
    SurfaceQuilt q;
    r[trim] = quilt_surface(base, sw, q, o);
    Mesh displaced;
    surface_quilt_displaced(base, q, (q.z_max - q.z_min) * q.scale, displaced);
    EXPECT_EQ(closed_fraction(displaced), 1.0);
    faces[trim] = displaced.number_of_faces();
    std::cout << "[ trim new ] " << trim << ": dropped new " << r[trim].dropped_new << ", kept trimmed "
              << r[trim].new_trimmed << ", faces " << faces[trim] << ", elements " << r[trim].elements << "\n";
  }
  EXPECT_GT(r[0].dropped_new, 0u);
  EXPECT_EQ(r[0].new_trimmed, 0u);
  EXPECT_GT(r[1].new_trimmed, 0u);
  EXPECT_GT(faces[1], faces[0]);
}

TEST(SurfaceQuilting, FieldOptionsAreChecked) {
  Mesh base;
  make_icosphere(base, 1);
  const Swatch sw = tiny_scatter();
  SurfaceQuilt q;
  SurfaceQuiltOptions o;
  o.align_field_max_deg = 46;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.field_smoothing = -1;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
  o = {};
  o.field_min_projection = 0;
  EXPECT_THROW(quilt_surface(base, sw, q, o), InvalidInputError);
}

}  // namespace
// The scale of 3.1 in one place (the CLI's size check uses it too): the
// swatch's longer side is relative_size times the base's bounding-box diagonal,
// and the placements are the base's area over the scaled swatch's.
TEST(SurfaceQuilting, ScaleAndPlacementsFollowTheBoundingBoxDiagonal) {
  Mesh base;
  make_grid(base, 4, 4, 3.0, 4.0);  // diagonal 5, area 12
  const Swatch sw = weave_4x4(6, 6);
  const double big = std::max(sw.length(), sw.width());
  EXPECT_NEAR(surface_quilt_scale(base, sw, 0.2), 0.2 * 5.0 / big, 1e-12);
  const double S = 0.2 * 5.0 / big;
  EXPECT_NEAR(surface_quilt_placements(base, sw, 0.2), 12.0 / (sw.length() * sw.width() * S * S), 1e-9);
  // Doubling the relative size quarters the placements; the quilt uses the same scale.
  EXPECT_NEAR(surface_quilt_placements(base, sw, 0.4) * 4, surface_quilt_placements(base, sw, 0.2), 1e-9);
  Mesh empty;
  EXPECT_EQ(surface_quilt_placements(empty, sw, 0.2), 0.0);
}

}  // namespace surftex
