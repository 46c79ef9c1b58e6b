// SPDX-License-Identifier: AGPL-3.0-or-later
// The mesh-quilting drivers (shell/quilting/quilt_driver.h) that the quilt
// command, the demo and bench_quilt call: size checks, element lengths, the
// plane and surface drivers and their reports.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"
#include "shell/element_colors.h"
#include "shell/quilting/quilt_driver.h"
#include "shell/quilting/quilt_json.h"
#include "shell/swatch_generators.h"

#include "shell_test_util.h"

namespace surftex {
namespace {

using test::small_chainmail_mesh;

void add_triangle(Mesh& m, Point3 a, Point3 b, Point3 c) {
  m.add_face(m.add_vertex(a), m.add_vertex(b), m.add_vertex(c));
}

// The message of the InvalidInputError `f` throws ("" if none).
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(QuiltDriver, ElementLengthsAreEachElementsLargerXySideOverTheUnit) {
  Mesh m;
  add_triangle(m, Point3(0, 0, 0), Point3(2, 0, 5), Point3(0, 1, 0));  // element 0: 2 x 1 (z ignored)
  add_triangle(m, Point3(5, 0, 0), Point3(6, 0, 0), Point3(5, 4, 0));  // element 1: 1 x 4
  add_triangle(m, Point3(5, 0, 1), Point3(5, 1, 1), Point3(5.5, 1, 1));  // element 1 too: its box grows to 1 x 4 still
  EXPECT_EQ(element_lengths(m, 2.0), std::make_pair(0.0, 0.0));  // no kFaceElement
  auto el = get_or_add(m, kFaceElement, 0);
  el[FaceIndex(1)] = el[FaceIndex(2)] = 1;
  const auto [mean, max] = element_lengths(m, 2.0);
  EXPECT_DOUBLE_EQ(mean, (1.0 + 2.0) / 2);
  EXPECT_DOUBLE_EQ(max, 2.0);
  EXPECT_EQ(element_lengths(m, 0.0), std::make_pair(0.0, 0.0));
}

TEST(QuiltDriver, SizeCheckRefusesTooManyFacesNamingTheRunAndTooFineCellsNamingCell) {
  Mesh sm;
  make_grid(sm, 2, 2, 1.0, 1.0);  // 8 faces, 1 x 1
  const Swatch s = make_swatch(sm);
  EXPECT_EQ(error_of([&] { check_quilt_size(s, 0, 1000, "--plane 30x30"); }), "");
  EXPECT_EQ(error_of([&] { check_quilt_size(s, 0.0078125, 1000, "--plane 30x30"); }), "");  // 128 cells across
  const std::string faces = error_of([&] { check_quilt_size(s, 0, 1e7, "--plane 4000x2500"); });
  EXPECT_TRUE(has(faces, "--plane 4000x2500 needs about 10000000 copies of the 8-face swatch")) << faces;
  const std::string cells = error_of([&] { check_quilt_size(s, 0.0009765625, 1, "--scale 0.25"); });
  EXPECT_TRUE(has(cells, "--cell 0.000977 cuts the swatch into 1024 cells across, more than 200")) << cells;
}

TEST(QuiltDriver, PlaneDriverScalesTheSwatchQuiltsColoursAndReports) {
  const Mesh sm = small_chainmail_mesh();
  QuiltSwatchOnPlaneOptions o;
  o.scale = 2;
  o.plane_name = "2x1.5";
  int checked = 0;
  o.check_work = [&](const WorkEstimate& e) {
    ++checked;
    EXPECT_GT(e.bytes, 0);
  };
  Mesh out;
  const QuiltSwatchOnPlaneResult r = quilt_swatch_on_plane(sm, 2, 1.5, out, o);
  EXPECT_EQ(checked, 1);
  EXPECT_NEAR(r.swatch.length(), 2 * make_swatch(sm).length(), 1e-12);
  EXPECT_GT(r.quilt.elements, 0);
  EXPECT_EQ(r.quilt.faces, out.number_of_faces());
  ASSERT_TRUE(find(out, kVertexColor).second);
  EXPECT_TRUE(find(out, kFaceElement).second);
  const auto [mean, max] = element_lengths(out, std::max(r.swatch.length(), r.swatch.width()));
  EXPECT_DOUBLE_EQ(r.element_length_mean, mean);
  EXPECT_DOUBLE_EQ(r.element_length_max, max);
  EXPECT_GT(mean, 0);
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["plane"], nlohmann::json({2.0, 1.5}));
  EXPECT_EQ(j["elements"], r.quilt.elements);
  EXPECT_EQ(j["swatch_faces"], r.swatch.mesh.tris.size());
  EXPECT_EQ(j["swatch_elements"], r.swatch.elements.size());
  EXPECT_DOUBLE_EQ(j["element_length_max"].get<double>(), max);
  for (const char* key : {"element_length_mean", "stitched", "faces", "vertices", "steps", "seconds"})
    EXPECT_TRUE(j.contains(key)) << key;

  // The same as quilt_plane on the scaled swatch, coloured with the seed.
  Mesh scaled = sm, by_hand;
  for (VertexIndex v : scaled.vertices()) scaled.point(v) = Point3(CGAL::ORIGIN + 2 * (scaled.point(v) - CGAL::ORIGIN));
  const Swatch s = make_swatch(scaled, SwatchAxis::kAuto);
  quilt_plane(s, 2 * s.length(), 1.5 * s.width(), by_hand);
  ASSERT_EQ(by_hand.number_of_vertices(), out.number_of_vertices());
  for (VertexIndex v : out.vertices()) EXPECT_EQ(out.point(v), by_hand.point(v));
  color_by_element(by_hand, 1);
  EXPECT_EQ(find(by_hand, kVertexColor).first[VertexIndex(0)], find(out, kVertexColor).first[VertexIndex(0)]);
}

TEST(QuiltDriver, PlaneDriverRefusesBeforeQuiltingWithTheRunsName) {
  const Mesh sm = small_chainmail_mesh();
  Mesh out;
  QuiltSwatchOnPlaneOptions o;
  o.plane_name = "9000x9000";
  std::string e = error_of([&] { quilt_swatch_on_plane(sm, 9000, 9000, out, o); });
  EXPECT_TRUE(has(e, "quilt: --plane 9000x9000 needs about 81000000 copies")) << e;
  // A cell so coarse that the swatch covers under 3 cells: named by its axes and --cell.
  o.plane_name = "1x1";
  o.quilt.cell_size = 0.6 * make_swatch(sm).length();
  e = error_of([&] { quilt_swatch_on_plane(sm, 1, 1, out, o); });
  EXPECT_TRUE(has(e, "along its x and y axes")) << e;
  EXPECT_TRUE(has(e, "--cell")) << e;
  // The work check runs before the quilt.
  o.quilt.cell_size = 0;
  o.check_work = [](const WorkEstimate&) { throw InvalidInputError("over budget"); };
  EXPECT_EQ(error_of([&] { quilt_swatch_on_plane(sm, 1, 1, out, o); }), "over budget");
  EXPECT_EQ(out.number_of_faces(), 0u);
}

TEST(QuiltDriver, SurfaceDriverIsTheQuiltThenTheEmbeddingColouredAndReportsItsOptions) {
  Mesh base;
  make_icosphere(base, 1);
  Mesh sm;  // irregular blobs: the seed changes the quilt
  ScatterOptions so;
  so.size = 6;
  so.subdivisions = 1;
  make_scatter_swatch(sm, so);
  QuiltSwatchOnSurfaceOptions o;
  o.quilt.relative_size = 0.5;
  o.quilt.field = SurfaceQuiltOptions::Field::kNone;
  o.quilt.rotation_max_deg = 10;
  o.quilt.up = {0, 0, 2};
  o.embed.stretch.iterations = 2;
  o.embed.check_self_intersections = false;
  o.seed = 7;
  o.fill_embedded = false;  // (the fill after the embedding has its own tests; by hand below it is left out)
  Mesh out;
  const QuiltSwatchOnSurfaceResult r = quilt_swatch_on_surface(base, sm, out, o);
  EXPECT_GT(r.quilt.elements, 0);
  EXPECT_EQ(r.local.elements, r.quilt.elements);
  EXPECT_EQ(r.faces, out.number_of_faces());
  EXPECT_EQ(r.base_faces, base.number_of_faces());
  ASSERT_TRUE(find(out, kVertexColor).second);

  // By hand, with the seed in every stage.
  const Swatch s = make_swatch(sm, SwatchAxis::kAuto);
  SurfaceQuiltOptions qo = o.quilt;
  qo.seed = 7;
  SurfaceQuilt q;
  quilt_surface(base, s, q, qo);
  EmbedSurfaceQuiltOptions eo = o.embed;
  eo.stretch.seed = 7;
  eo.whole_copy_sources = swatch_element_meshes(s);  // whole compact copies placed affinely
  Mesh by_hand;
  embed_surface_quilt(base, q, by_hand, eo);
  ASSERT_EQ(by_hand.number_of_vertices(), out.number_of_vertices());
  for (VertexIndex v : out.vertices()) EXPECT_EQ(out.point(v), by_hand.point(v));

  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["field"], "none");
  EXPECT_EQ(j["up"], nlohmann::json({0.0, 0.0, 2.0}));
  EXPECT_DOUBLE_EQ(j["scale"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["max_turn_deg"].get<double>(), 10.0);
  EXPECT_EQ(j["swatch_up"], axis_name(s.up_axis));
  EXPECT_EQ(j["faces"], out.number_of_faces());
  EXPECT_EQ(j["base_faces"], base.number_of_faces());
  EXPECT_TRUE(j["self_intersections"].is_null());  // not checked
  // The output's elements (the embedding may remove or cut some), beside the quilt's.
  std::set<int> ids;
  for (FaceIndex f : out.faces()) ids.insert(find(out, kFaceElement).first[f]);
  EXPECT_EQ(j["elements_embedded"], ids.size());
  for (const char* key : {"vertices", "swatch_faces", "swatch_elements", "stretch_after", "stitched", "seconds"})
    EXPECT_TRUE(j.contains(key)) << key;

  Mesh scene;
  surface_quilt_scene(base, out, scene);
  EXPECT_EQ(scene.number_of_faces(), base.number_of_faces() + out.number_of_faces());
  EXPECT_EQ(find(scene, kVertexColor).first[VertexIndex(0)], (Color3f{0.72f, 0.72f, 0.75f}));
}

// A CAD-like part: a thin disc, its caps fans of long radial edges (about 8
// of its median edges) around a finely segmented rim.
Mesh fan_capped_disc(int n = 64, double radius = 1.0, double height = 0.1) {
  Mesh m;
  std::vector<VertexIndex> top, bottom;
  const VertexIndex ct = m.add_vertex(Point3(0, 0, height)), cb = m.add_vertex(Point3(0, 0, 0));
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    top.push_back(m.add_vertex(Point3(radius * std::cos(a), radius * std::sin(a), height)));
    bottom.push_back(m.add_vertex(Point3(radius * std::cos(a), radius * std::sin(a), 0)));
  }
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.add_face(ct, top[i], top[j]);
    m.add_face(cb, bottom[j], bottom[i]);
    m.add_face(bottom[i], bottom[j], top[j]);
    m.add_face(bottom[i], top[j], top[i]);
  }
  return m;
}

// The longest over the median edge of a mesh.
double longest_over_median_edge(const Mesh& m) {
  std::vector<double> len;
  for (auto e : m.edges())
    len.push_back(std::sqrt(CGAL::squared_distance(m.point(m.source(m.halfedge(e))), m.point(m.target(m.halfedge(e))))));
  std::sort(len.begin(), len.end());
  return len.back() / len[len.size() / 2];
}

// Issue 17 item 2 on a real swatch's long edges: a swatch whose edges span
// many of its median edges is split (flat, the shape kept) before quilting,
// so the output's longest edge stays within 4 of its median edges; without
// the split its copies keep their 8-median radial edges.
TEST(QuiltDriver, LongSwatchEdgesAreSplitSoTheOutputKeepsTheShardBound) {
  Mesh base;
  make_icosphere(base, 2);
  const Mesh disc = fan_capped_disc();
  ASSERT_GT(longest_over_median_edge(disc), 6.0);
  auto run = [&](double split) {
    QuiltSwatchOnSurfaceOptions o;
    o.split_edges_over_median = split;
    o.quilt.relative_size = 0.3;
    o.embed.stretch.iterations = 2;
    o.embed.check_self_intersections = false;
    Mesh out;
    const QuiltSwatchOnSurfaceResult r = quilt_swatch_on_surface(base, disc, out, o);
    const double ratio = longest_over_median_edge(out);
    std::cout << "[ disc ] split at " << split << ": " << r.swatch_vertices_split << " vertices added, "
              << r.quilt.elements << " elements, output longest / median edge " << ratio << "\n";
    EXPECT_GT(r.quilt.elements, 5);
    return std::make_pair(r, ratio);
  };
  const auto [r0, ratio0] = run(0);
  EXPECT_EQ(r0.swatch_vertices_split, 0u);
  EXPECT_GT(ratio0, 4.0);
  const auto [r1, ratio1] = run(QuiltSwatchOnSurfaceOptions{}.split_edges_over_median);
  EXPECT_GT(r1.swatch_vertices_split, 0u);
  EXPECT_LE(ratio1, 4.0);
  EXPECT_EQ(to_json(r1)["swatch_vertices_split"], r1.swatch_vertices_split);
  // A swatch without long edges is left as it is.
  Mesh out;
  QuiltSwatchOnSurfaceOptions o;
  o.quilt.relative_size = 0.45;
  o.embed.stretch.iterations = 1;
  o.embed.check_self_intersections = false;
  EXPECT_EQ(quilt_swatch_on_surface(base, small_chainmail_mesh(), out, o).swatch_vertices_split, 0u);
  o.split_edges_over_median = 1.2;
  EXPECT_THROW(quilt_swatch_on_surface(base, disc, out, o), InvalidInputError);
}

TEST(QuiltDriver, SurfaceDriverRefusesAScaleAbove10AndOversizedRunsBeforeQuilting) {
  Mesh base;
  make_icosphere(base, 1);
  const Mesh sm = small_chainmail_mesh();
  Mesh out;
  QuiltSwatchOnSurfaceOptions o;
  o.quilt.relative_size = 12;
  EXPECT_EQ(error_of([&] { quilt_swatch_on_surface(base, sm, out, o); }),
            "quilt: --scale must be <= 10 on a mesh (got 12.000000)");
  o.quilt.relative_size = 0.001;  // millions of copies
  std::string e = error_of([&] { quilt_swatch_on_surface(base, sm, out, o); });
  EXPECT_TRUE(has(e, "quilt: --scale 0.001000 needs about")) << e;
  o.quilt.relative_size = 0.45;
  o.check_work = [](const WorkEstimate& w) { throw InvalidInputError("budget " + w.what); };
  e = error_of([&] { quilt_swatch_on_surface(base, sm, out, o); });
  EXPECT_TRUE(has(e, "budget ")) << e;
  EXPECT_EQ(out.number_of_faces(), 0u);
}

// A single pebble as the swatch (bench_quilt's rock case): at 0.25 of the
// base's diagonal every placement on a small sphere is stretched or crosses
// and nothing is left ("no element was placed"); the default size gives one
// element 1/16 of the diagonal, and the sphere gets covered with pebbles.
// Swatches of several small flat elements (tori) keep 0.25; threads
// (the weave's, which span the swatch) are capped at 1/8 of the diagonal in
// length, so the weave gets about half of 0.25.
TEST(QuiltDriver, DefaultSizeShrinksASwatchOfOneLargeElementOrOfLongThreads) {
  Mesh pebble;
  make_ellipsoid(pebble, 1.0, 0.8, 0.35, 2);
  const Swatch one = make_swatch(pebble);
  EXPECT_DOUBLE_EQ(default_surface_quilt_size(one), 0.0625);
  Mesh tori, chain, weave;
  make_tori_swatch(tori, ToriOptions{});
  make_chainmail_swatch(chain, ChainmailOptions{});
  make_weave_swatch(weave, WeaveOptions{});
  EXPECT_DOUBLE_EQ(default_surface_quilt_size(make_swatch(tori)), 0.25);
  EXPECT_LT(default_surface_quilt_size(make_swatch(chain)), 0.16);  // standing rings: the height cap below
  const Swatch ws = make_swatch(weave);
  double longest = 0;  // the longest thread's larger xy side (swatch units)
  for (std::size_t e = 0; e < ws.elements.size(); ++e) {
    const ElementMesh m = swatch_element(ws, static_cast<int>(e));
    double lo[2] = {m.points[0][0], m.points[0][1]}, hi[2] = {lo[0], lo[1]};
    for (const P3& q : m.points)
      for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], q[d]), hi[d] = std::max(hi[d], q[d]);
    longest = std::max({longest, hi[0] - lo[0], hi[1] - lo[1]});
  }
  const double size = default_surface_quilt_size(ws);
  EXPECT_LT(size, 0.13);
  // relative size x (thread / swatch side) = the thread's share of the diagonal.
  EXPECT_NEAR(size * longest / std::max(ws.length(), ws.width()), 1.0 / 8, 1e-12);

  Mesh base;
  make_icosphere(base, 3);
  QuiltSwatchOnSurfaceOptions o;
  o.embed.stretch.iterations = 2;
  o.embed.measure_outside_shell = false;
  o.quilt.relative_size = 0.25;
  Mesh out;
  const std::string err = error_of([&] { quilt_swatch_on_surface(base, pebble, out, o); });
  std::size_t at_quarter = 0;
  if (err.empty()) at_quarter = static_cast<std::size_t>(quilt_swatch_on_surface(base, pebble, out, o).quilt.elements);
  o.quilt.relative_size = 0;  // the default
  const QuiltSwatchOnSurfaceResult r = quilt_swatch_on_surface(base, pebble, out, o);
  std::cout << "[ sphere pebble ] 0.25: " << (err.empty() ? std::to_string(at_quarter) + " elements" : err)
            << "; default " << r.relative_size << ": " << r.quilt.elements << " elements, bare " << r.quilt.bare_fraction << "\n";
  EXPECT_DOUBLE_EQ(r.relative_size, 0.0625);
  EXPECT_GE(r.quilt.elements, 40);
  EXPECT_GT(r.quilt.elements, 4 * static_cast<int>(at_quarter) + 10);
  EXPECT_LT(r.quilt.bare_fraction, 0.05);
}

// The height cap: a pebble as tall as it is wide (splaying more when lifted
// over curved ground) gets a smaller default than a flat one of the same
// width: its height is at most 1/32 of the diagonal; so do standing
// chain-mail rings, which are neither compact nor long (session 30: bare
// area on the bunny 8.3% -> 5.3%); tilted tori keep 0.25.
TEST(QuiltDriver, DefaultSizeIsSmallerForATallElementThanForAFlatOne) {
  Mesh flat, tall, tori, mail;
  make_ellipsoid(flat, 1.0, 0.8, 0.35, 2);
  make_ellipsoid(tall, 1.0, 0.9, 0.8, 2);
  make_tori_swatch(tori, ToriOptions{});
  make_chainmail_swatch(mail, ChainmailOptions{});
  const Swatch sf = make_swatch(flat, SwatchAxis::kAuto), st = make_swatch(tall, SwatchAxis::kAuto);
  const double df = default_surface_quilt_size(sf), dt = default_surface_quilt_size(st);
  // (1/32) x larger side / height, the ellipsoid's 2.0 / 1.6 up to its tessellation.
  const double expect = (1.0 / 32) * std::max(st.length(), st.width()) / (st.bbox_max[2] - st.bbox_min[2]);
  std::cout << "[ default size ] flat " << df << ", tall " << dt << " (expected " << expect << ")\n";
  EXPECT_DOUBLE_EQ(df, 0.0625);
  EXPECT_NEAR(dt, expect, 1e-9);
  EXPECT_LT(dt, 0.045);
  EXPECT_DOUBLE_EQ(default_surface_quilt_size(make_swatch(tori, SwatchAxis::kAuto)), 0.25);
  const Swatch sm = make_swatch(mail, SwatchAxis::kAuto);
  std::vector<double> h;
  for (const SwatchElement& e : sm.elements) h.push_back(e.bbox_max[2] - e.bbox_min[2]);
  std::nth_element(h.begin(), h.begin() + static_cast<std::ptrdiff_t>(h.size() / 2), h.end());
  const double mail_expect = (1.0 / 32) * std::max(sm.length(), sm.width()) / h[h.size() / 2];
  EXPECT_LT(mail_expect, 0.2);
  EXPECT_NEAR(default_surface_quilt_size(sm), mail_expect, 1e-12);
}

TEST(QuiltDriver, GeneratedSwatchesByNameAndSeed) {
  EXPECT_TRUE(is_generated_swatch("weave"));
  EXPECT_TRUE(is_generated_swatch("tori"));
  EXPECT_FALSE(is_generated_swatch("weave.obj"));
  Mesh expected;
  ScatterOptions so;
  so.seed = 5;
  make_scatter_swatch(expected, so);
  const Mesh m = load_or_generate_swatch("scatter", 5);
  ASSERT_EQ(m.number_of_vertices(), expected.number_of_vertices());
  for (VertexIndex v : m.vertices()) EXPECT_EQ(m.point(v), expected.point(v));
  EXPECT_THROW(load_or_generate_swatch("/nonexistent/swatch.obj", 1), Error);
}

// The embedded fill off and on: nothing placed without it; with it, pieces
// placed, the bare area under half, and no crossing.
void expect_the_fill_covers(const QuiltSwatchOnSurfaceResult& off, const QuiltSwatchOnSurfaceResult& on) {
  EXPECT_EQ(off.embedding.fill.placed, 0u);
  EXPECT_GT(on.embedding.fill.placed, 0u);
  EXPECT_LT(on.bare.overall, 0.5 * off.bare.overall);
  EXPECT_TRUE(on.embedding.embed.checked);
  EXPECT_EQ(on.embedding.self_intersections_between, 0u);
  EXPECT_EQ(on.embedding.self_intersections_within, 0u);
}

// Issue 17 item 4 after the embedding: on a fin (a flat lens, sharp rim),
// the shell map folds threads over the rim and the embedding cuts them,
// leaving bare what the quilt covered. The fill puts thread pieces there
// (EmbedSurfaceQuiltOptions::fill), crossing nothing; fill_embedded off, the
// output keeps the bare spots. With the fill, the quilt's refill rounds for
// threads are three, not six.
TEST(QuiltDriver, ThreadPiecesFillWhatTheEmbeddingLeftBare) {
  const Mesh base = test::flat_lens(3);
  const Mesh weave = test::weave_4x4_mesh(6, 5);
  auto run = [&](bool fill) {
    QuiltSwatchOnSurfaceOptions o;
    o.quilt.relative_size = 0.6;
    o.embed.stretch.iterations = 2;
    o.fill_embedded = fill;
    Mesh out;
    return quilt_swatch_on_surface(base, weave, out, o);
  };
  const QuiltSwatchOnSurfaceResult off = run(false), on = run(true);
  expect_the_fill_covers(off, on);
  EXPECT_EQ(off.quilt.refill_rounds, 6);
  EXPECT_EQ(on.quilt.refill_rounds, kRefillRoundsBeforeEmbeddedFill);
  EXPECT_EQ(kRefillRoundsBeforeEmbeddedFill, 3);
}

// A swatch of compact elements (one ring, placed by the scatter alone) on a
// horn: what the quilt and the embedding leave bare gets whole rings, rigid,
// crossing nothing.
TEST(QuiltDriver, CompactElementsFillWhatTheEmbeddingLeftBare) {
  Mesh horn, ring;
  make_ellipsoid(horn, 0.25, 0.25, 1.5, 3);
  make_torus(ring, 0.35, 0.15, 16, 8);
  auto run = [&](bool fill) {
    QuiltSwatchOnSurfaceOptions o;
    o.quilt.up = {0, 0, 1};
    o.quilt.relative_size = 0.2;  // rings about as wide as the horn
    o.embed.stretch.iterations = 2;
    o.fill_embedded = fill;
    Mesh out;
    return quilt_swatch_on_surface(horn, ring, out, o);
  };
  const QuiltSwatchOnSurfaceResult off = run(false), on = run(true);
  EXPECT_TRUE(on.quilt.scatter_only);
  EXPECT_GT(off.bare.overall, 0.01);
  expect_the_fill_covers(off, on);
}

// A box of twelve triangles and a swatch scattered alone: the fills place
// one copy per base face, so without the base's long edges split most of each
// side stays bare; split (the surface unchanged) it is covered.
TEST(QuiltDriver, LongBaseEdgesAreSplitForASwatchScatteredAlone) {
  Mesh box, ring;
  make_cube(box, 1.0);
  make_torus(ring, 0.35, 0.15, 16, 8);
  auto run = [&](bool split) {
    QuiltSwatchOnSurfaceOptions o;
    o.quilt.relative_size = 0.08;
    o.embed.stretch.iterations = 2;
    o.split_base_edges = split;
    Mesh out;
    return quilt_swatch_on_surface(box, ring, out, o);
  };
  const QuiltSwatchOnSurfaceResult off = run(false), on = run(true);
  EXPECT_EQ(off.base_vertices_split, 0u);
  EXPECT_EQ(off.base_faces, 12u);
  EXPECT_GT(on.base_vertices_split, 20u);
  EXPECT_EQ(on.base_faces, box.number_of_faces() + 2 * on.base_vertices_split);  // closed: 2 faces per vertex
  EXPECT_GT(off.bare.overall, 0.2);
  EXPECT_LT(on.bare.overall, 0.05);
  EXPECT_EQ(on.embedding.self_intersections_between, 0u);
}

}  // namespace
}  // namespace surftex
