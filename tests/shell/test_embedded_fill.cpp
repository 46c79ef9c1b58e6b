// SPDX-License-Identifier: AGPL-3.0-or-later
// The fill of the embedded quilt's bare faces (shell/quilting/embedded_fill.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "geometry/self_intersections.h"
#include "shell/element_clearance.h"
#include "shell/element_mesh.h"
#include "shell/quilting/embedded_fill.h"
#include "shell/quilting/quilt_coverage.h"
#include "shell/quilting/surface_quilting.h"
#include "shell/swatch.h"
#include "shell/triangle_distance.h"
#include "shell_test_util.h"

namespace surftex {
namespace {

// A weave's thread pieces, scaled so that one is `piece` mesh units long.
EmbeddedFillOptions weave_fill(double piece) {
  const Swatch s = test::weave_4x4(6, 5);
  EmbeddedFillOptions o;
  o.templates = thread_scatter_pieces(s, 4);
  double longest = 0;
  for (const ElementMesh& m : o.templates) {
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (const P3& q : m.points)
      for (int d = 0; d < 2; ++d) lo[d] = std::min(lo[d], q[d]), hi[d] = std::max(hi[d], q[d]);
    longest = std::max({longest, hi[0] - lo[0], hi[1] - lo[1]});
  }
  o.scale = piece / longest;
  o.z0 = s.bbox_min[2];
  o.radius = 0.5 * swatch_element_spacing(s) * o.scale;
  return o;
}

double bare(const Mesh& base, const std::vector<ElementMesh>& els, double radius) {
  Mesh out;
  mesh_from_elements(els, out);
  return output_bare_area(base, out, radius, {0, 0, 1}).overall;
}

// A fin: two flat faces meeting at a sharp rim, with nothing on it. The fill
// covers it with thread pieces that cross nothing, stay over the face they
// were placed on (none wraps the rim onto the other face) and stand within
// the shell's height above it.
TEST(EmbeddedFill, CoversABareFinWithoutCrossingsOrPiecesOverItsRim) {
  const Mesh base = test::flat_lens(3);
  const ElementMesh b = element_mesh_from(base);
  const EmbeddedFillOptions o = weave_fill(0.3);
  std::vector<ElementMesh> els;
  ASSERT_DOUBLE_EQ(bare(base, els, o.radius), 1.0);
  const EmbeddedFillResult r = fill_embedded_bare(b, els, o);
  EXPECT_GT(r.placed, 20u);
  EXPECT_EQ(els.size(), r.placed);
  EXPECT_LT(bare(base, els, o.radius), 0.2);
  Mesh out;
  mesh_from_elements(els, out);
  EXPECT_TRUE(self_intersecting_faces(out).empty());
  double zmax = 0;
  for (const ElementMesh& t : o.templates)
    for (const P3& q : t.points) zmax = std::max(zmax, (q[2] - o.z0) * o.scale);
  for (const ElementMesh& m : els) {
    std::size_t above = 0;
    for (const P3& p : m.points) above += p[2] > 0;
    EXPECT_TRUE(above == 0 || above == m.points.size()) << above << " of " << m.points.size() << " above the rim";
    EXPECT_TRUE(is_closed_oriented(m));
  }
  // Each vertex within the shell: no farther from the lens than its height.
  const TriangleDistance lens(b);
  for (const ElementMesh& m : els)
    for (const P3& p : m.points) EXPECT_LE(lens.closest(p).distance, 1.02 * zmax + 1e-9);
}

// What is covered gets nothing: with the fin's upper face covered by a
// sheet of elements, pieces go to the lower face only, crossing none of it;
// and the same seed places the same pieces.
TEST(EmbeddedFill, LeavesCoveredFacesAloneAndRepeatsForASeed) {
  const Mesh base = test::flat_lens(3);
  const ElementMesh b = element_mesh_from(base);
  const EmbeddedFillOptions o = weave_fill(0.3);
  ElementMesh sheet;  // the upper faces, lifted by half the radius
  std::vector<int> index(b.points.size(), -1);
  for (const Tri& t : b.tris) {
    if (b.points[static_cast<std::size_t>(t[0])][2] <= 0 || b.points[static_cast<std::size_t>(t[1])][2] <= 0 ||
        b.points[static_cast<std::size_t>(t[2])][2] <= 0)
      continue;
    Tri n{};
    for (int k = 0; k < 3; ++k) {
      int& i = index[static_cast<std::size_t>(t[k])];
      if (i < 0) {
        i = static_cast<int>(sheet.points.size());
        P3 p = b.points[static_cast<std::size_t>(t[k])];
        p[2] += 0.5 * o.radius;
        sheet.points.push_back(p);
      }
      n[k] = i;
    }
    sheet.tris.push_back(n);
  }
  std::vector<ElementMesh> els{sheet}, again{sheet};
  const EmbeddedFillResult r = fill_embedded_bare(b, els, o);
  EXPECT_GT(r.placed, 5u);
  for (std::size_t e = 1; e < els.size(); ++e)
    for (const P3& p : els[e].points) EXPECT_LT(p[2], 0.0);
  Mesh out;
  mesh_from_elements(els, out);
  EXPECT_TRUE(self_intersecting_faces(out).empty());
  fill_embedded_bare(b, again, o);
  ASSERT_EQ(again.size(), els.size());
  for (std::size_t e = 0; e < els.size(); ++e) EXPECT_EQ(again[e].points, els[e].points);
}

// An open mesh: a piece placed near the border would have its overhanging
// part projected onto the border (squashed into a line, its edges shorter,
// none stretched). On a flat square every piece kept is its template moved
// rigidly: the same area, scaled.
TEST(EmbeddedFill, PiecesOverAnOpenBorderAreNotSquashedOntoIt) {
  Mesh square;
  make_grid(square, 24, 24);
  const ElementMesh b = element_mesh_from(square);
  const EmbeddedFillOptions o = weave_fill(0.25);
  std::vector<ElementMesh> els;
  const EmbeddedFillResult r = fill_embedded_bare(b, els, o);
  EXPECT_GT(r.placed, 10u);
  auto area = [](const ElementMesh& m) {
    double a = 0;
    for (const Tri& t : m.tris) {
      const P3 &p = m.points[static_cast<std::size_t>(t[0])], &q = m.points[static_cast<std::size_t>(t[1])],
               &w = m.points[static_cast<std::size_t>(t[2])];
      const P3 u{q[0] - p[0], q[1] - p[1], q[2] - p[2]}, v{w[0] - p[0], w[1] - p[1], w[2] - p[2]};
      a += 0.5 * std::sqrt(std::pow(u[1] * v[2] - u[2] * v[1], 2) + std::pow(u[2] * v[0] - u[0] * v[2], 2) +
                           std::pow(u[0] * v[1] - u[1] * v[0], 2));
    }
    return a;
  };
  std::size_t squashed = 0;
  for (const ElementMesh& m : els) {
    bool rigid = false;
    for (const ElementMesh& t : o.templates)
      rigid = rigid || (t.tris == m.tris && std::abs(area(m) - o.scale * o.scale * area(t)) <= 1e-6 * area(m));
    squashed += !rigid;
  }
  EXPECT_EQ(squashed, 0u) << "of " << els.size();
}

// A ring (a torus lying flat, 0.2 across) as the one template of a rigid fill.
EmbeddedFillOptions ring_fill() {
  Mesh torus;
  make_torus(torus, 0.07, 0.03, 16, 8);
  EmbeddedFillOptions o;
  o.templates = {element_mesh_from(torus)};
  o.scale = 1;
  o.z0 = -0.03;
  o.radius = 0.1;
  o.rigid = true;
  o.max_float = 0.06;  // the ring's height
  o.clearance = 0.02;
  return o;
}

double distance(const P3& a, const P3& b) { return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

// A thin part (a horn: an ellipsoid 0.5 across, 3 long) and compact elements:
// each goes whole (the same distances between its vertices as the template),
// resting on the surface without crossing it, no vertex floating more than
// max_float over its height, and the clearance kept between copies. Bent
// over the horn, as thread pieces are, a ring would not keep its shape.
TEST(EmbeddedFill, CompactElementsGoWholeOntoAThinPart) {
  Mesh horn;
  make_ellipsoid(horn, 0.25, 0.25, 1.5, 4);
  const ElementMesh b = element_mesh_from(horn);
  const EmbeddedFillOptions o = ring_fill();
  std::vector<ElementMesh> els;
  const EmbeddedFillResult r = fill_embedded_bare(b, els, o);
  EXPECT_GT(r.placed, 20u);
  EXPECT_LT(bare(horn, els, o.radius), 0.25);
  const ElementMesh& t = o.templates[0];
  double worst = 0;
  for (const ElementMesh& m : els)
    for (std::size_t v = 1; v < t.points.size(); v += 7)
      for (std::size_t w = 0; w < v; w += 5)
        worst = std::max(worst, std::abs(distance(m.points[v], m.points[w]) - distance(t.points[v], t.points[w])));
  EXPECT_LT(worst, 1e-9) << "a copy is not rigid";
  Mesh scene = horn, ring;
  mesh_from_elements(els, ring);
  scene.join(ring);
  EXPECT_TRUE(self_intersecting_faces(scene).empty());
  const TriangleDistance surface(b);
  for (const ElementMesh& m : els)
    for (std::size_t v = 0; v < m.points.size(); ++v)
      EXPECT_LE(surface.closest(m.points[v]).distance, (t.points[v][2] - o.z0) + o.max_float + 1e-3 * o.radius);
  EXPECT_GE(smallest_element_gap(els, 1.0), o.clearance * (1 - 1e-9));
}

// A horn much narrower than the ring (0.04 across, the ring 0.2; on one 0.12
// across a ring still saddles within the cone): no full-size copy rests on
// it; copies at the smaller factors do, each whole (its vertex
// distances those of the template times one factor), crossing nothing.
TEST(EmbeddedFill, SmallerCopiesGoWhereTheFullSizeRestsNowhere) {
  Mesh horn;
  make_ellipsoid(horn, 0.02, 0.02, 1.5, 3);
  const ElementMesh b = element_mesh_from(horn);
  EmbeddedFillOptions o = ring_fill();
  o.attempts = 4;
  std::vector<ElementMesh> full;
  const EmbeddedFillResult r_full = fill_embedded_bare(b, full, o);
  EXPECT_EQ(r_full.placed_smaller, 0u);
  const double bare_full = bare(horn, full, o.radius);
  EXPECT_GT(bare_full, 0.5) << r_full.placed << " full-size copies rest on the thin horn";
  o.smaller = {0.7, 0.5, 0.35};
  std::vector<ElementMesh> els;
  const EmbeddedFillResult r = fill_embedded_bare(b, els, o);
  EXPECT_GT(r.placed_smaller, 5u);
  EXPECT_LT(bare(horn, els, o.radius), 0.5 * bare_full);
  const ElementMesh& t = o.templates[0];
  for (const ElementMesh& m : els) {
    const double f = distance(m.points[1], m.points[40]) / distance(t.points[1], t.points[40]);
    double worst = 1;
    for (const double k : {1.0, 0.7, 0.5, 0.35}) worst = std::min(worst, std::abs(f - k));
    EXPECT_LT(worst, 1e-9) << "a copy at " << f << " of the size";
    for (std::size_t v = 1; v < t.points.size(); v += 7)
      EXPECT_NEAR(distance(m.points[v], m.points[0]), f * distance(t.points[v], t.points[0]), 1e-9);
  }
  Mesh scene = horn, rings;
  mesh_from_elements(els, rings);
  scene.join(rings);
  EXPECT_TRUE(self_intersecting_faces(scene).empty());
}

// The rigid fill's own options: turns 1 or 4, no negative float or clearance,
// smaller factors in (0, 1).
TEST(EmbeddedFill, RefusesImpossibleRigidOptions) {
  const ElementMesh b = element_mesh_from(test::flat_lens(1));
  std::vector<ElementMesh> els;
  for (auto edit : {+[](EmbeddedFillOptions& o) { o.turns = 2; }, +[](EmbeddedFillOptions& o) { o.max_float = -1; },
                    +[](EmbeddedFillOptions& o) { o.clearance = std::nan(""); },
                    +[](EmbeddedFillOptions& o) { o.up = {0, std::nan(""), 0}; },
                    +[](EmbeddedFillOptions& o) { o.smaller = {0.5, 1.0}; },
                    +[](EmbeddedFillOptions& o) { o.smaller = {std::nan("")}; }}) {
    EmbeddedFillOptions o = ring_fill();
    edit(o);
    EXPECT_THROW(fill_embedded_bare(b, els, o), InvalidInputError);
  }
}

TEST(EmbeddedFill, RefusesImpossibleOptions) {
  const ElementMesh b = element_mesh_from(test::flat_lens(1));
  std::vector<ElementMesh> els;
  auto refused = [&](auto&& edit) {
    EmbeddedFillOptions o = weave_fill(0.3);
    edit(o);
    EXPECT_THROW(fill_embedded_bare(b, els, o), InvalidInputError);
  };
  refused([](EmbeddedFillOptions& o) { o.radius = 0; });
  refused([](EmbeddedFillOptions& o) { o.scale = -1; });
  refused([](EmbeddedFillOptions& o) { o.attempts = 0; });
  refused([](EmbeddedFillOptions& o) { o.max_stretch = 0.5; });
  refused([](EmbeddedFillOptions& o) { o.max_normal_angle_deg = std::nan(""); });
  EmbeddedFillOptions none;  // no templates: nothing to do, nothing checked
  EXPECT_EQ(fill_embedded_bare(b, els, none).placed, 0u);
  EXPECT_TRUE(els.empty());
}

}  // namespace
}  // namespace surftex
