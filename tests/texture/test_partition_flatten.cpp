// SPDX-License-Identifier: AGPL-3.0-or-later
// Gorla et al. 2003 sections 3.1-3.2: near-planar partitioning (every face in
// exactly one connected patch within the normal cone) and flattening (exact
// 2D overlap test, no overlapping patch triangles, rotated boundary
// triangles, split of self-overlapping projections, rasters).
#include <gtest/gtest.h>

#include <cmath>
#include <deque>

#include "geometry/errors.h"
#include "texture/patches/flatten_patch.h"
#include "geometry/mesh_util.h"
#include "texture/patches/partition_near_planar.h"
#include "geometry/primitive_meshes.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

// Every face has a patch id in range, patches are edge-connected, and each
// face is within `max_angle` of its patch's seed normal (recomputed here).
void check_partition(const Mesh& mesh, const PartitionResult& r, double max_angle) {
  auto pm = find(mesh, kFacePatch).first;
  std::vector<int> count(r.patches, 0);
  for (FaceIndex f : mesh.faces()) {
    ASSERT_GE(pm[f], 0);
    ASSERT_LT(pm[f], r.patches);
    ++count[pm[f]];
    const Vector3 n = robust_face_normal(mesh, f);
    const Vector3 s = robust_face_normal(mesh, FaceIndex(r.seed_face[pm[f]]));
    EXPECT_LE(std::acos(std::min(1.0, n * s)) * 180 / M_PI, max_angle + 1e-9) << "face " << f;
  }
  for (int p = 0; p < r.patches; ++p) {
    EXPECT_EQ(count[p], r.faces[p]);
    EXPECT_GT(count[p], 0);
    EXPECT_EQ(pm[FaceIndex(r.seed_face[p])], p);
    // connected: BFS from the seed reaches all faces of the patch
    std::vector<char> seen(mesh.num_faces(), 0);
    std::deque<FaceIndex> q{FaceIndex(r.seed_face[p])};
    seen[r.seed_face[p]] = 1;
    int reached = 1;
    while (!q.empty()) {
      FaceIndex f = q.front();
      q.pop_front();
      for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
        FaceIndex g = mesh.face(mesh.opposite(h));
        if (g == Mesh::null_face() || seen[g.idx()] || pm[g] != p) continue;
        seen[g.idx()] = 1;
        ++reached;
        q.push_back(g);
      }
    }
    EXPECT_EQ(reached, count[p]) << "patch " << p << " is not connected";
  }
}

TEST(PartitionNearPlanar, IcosphereFacesInOnePatchWithinCone) {
  Mesh m;
  make_icosphere(m, 3);
  PartitionOptions o;
  o.max_angle_deg = 25;
  o.max_faces = 40;
  const PartitionResult r = partition_near_planar(m, o);
  check_partition(m, r, 25);
  EXPECT_LE(r.max_deviation_deg, 25 + 1e-9);
  // 1280 faces, <= 40 per patch: at least 32 patches; refinement merged some.
  EXPECT_GE(r.patches, 32);
  EXPECT_LE(r.patches, r.greedy_patches);
  for (int c : r.faces) EXPECT_LE(c, 40);
}

TEST(PartitionNearPlanar, TorusAndTightCone) {
  Mesh m;
  make_torus(m, 1.0, 0.35, 40, 20);
  PartitionOptions o;
  o.max_angle_deg = 12;
  o.max_faces = 200;
  const PartitionResult r = partition_near_planar(m, o);
  check_partition(m, r, 12);
  PartitionOptions loose = o;
  loose.max_angle_deg = 45;
  Mesh m2;
  make_torus(m2, 1.0, 0.35, 40, 20);
  const PartitionResult r2 = partition_near_planar(m2, loose);
  check_partition(m2, r2, 45);
  EXPECT_LT(r2.patches, r.patches);  // a wider cone makes fewer, larger patches
}

TEST(PartitionNearPlanar, BadOptionsThrow) {
  Mesh m;
  make_icosphere(m, 1);
  PartitionOptions o;
  o.max_angle_deg = 0;
  EXPECT_THROW(partition_near_planar(m, o), InvalidInputError);
  o = {};
  o.max_faces = 0;
  EXPECT_THROW(partition_near_planar(m, o), InvalidInputError);
  o = {};
  o.max_distance = -1;
  EXPECT_THROW(partition_near_planar(m, o), InvalidInputError);
  Mesh empty;
  EXPECT_THROW(partition_near_planar(empty, {}), InvalidInputError);
}

TEST(TrianglesOverlap2d, ExactCases) {
  using T = std::array<Uv2, 3>;
  const T a{{{0, 0}, {1, 0}, {0, 1}}};
  EXPECT_TRUE(triangles_overlap_2d(a, a));
  EXPECT_FALSE(triangles_overlap_2d(a, T{{{1, 0}, {1, 1}, {0, 1}}}));      // shared edge
  EXPECT_FALSE(triangles_overlap_2d(a, T{{{1, 0}, {2, 0}, {2, 1}}}));      // shared vertex
  EXPECT_FALSE(triangles_overlap_2d(a, T{{{2, 2}, {3, 2}, {2, 3}}}));      // apart
  EXPECT_TRUE(triangles_overlap_2d(a, T{{{0.2, 0.2}, {2, 0.2}, {0.2, 2}}}));  // corner inside
  EXPECT_TRUE(triangles_overlap_2d(a, T{{{-1, 0.3}, {2, 0.3}, {0.5, -1}}}));  // edges cross, no vertex inside
  // Shared edge but the third vertex folds back over: overlap.
  EXPECT_TRUE(triangles_overlap_2d(a, T{{{1, 0}, {0.2, 0.2}, {0, 1}}}));
  // Touching edge-to-edge along a line, offset by the smallest double step: apart.
  const double eps = std::nextafter(1.0, 2.0) - 1.0;
  EXPECT_FALSE(triangles_overlap_2d(a, T{{{1 + eps, 0}, {1, 1}, {0, 1 + eps}}}));
  EXPECT_FALSE(triangles_overlap_2d(a, T{{{0, 0}, {1, 0}, {2, 0}}}));  // degenerate
}

// Each patch stores only the window of its raster holding its Inside and
// Boundary pixels: tight (every edge row and column has one), covering every
// patch triangle, and much smaller than the raster for small patches.
TEST(FlattenPatches, WindowIsTheBoxOfTheChartedPixels) {
  // A unit sphere and one of radius 0.2 beside it: the small sphere's patches
  // cover about a fifth of the raster's side.
  Mesh m, small;
  make_icosphere(m, 3);
  make_icosphere(small, 3);
  const int big_faces = static_cast<int>(m.number_of_faces());
  std::vector<VertexIndex> vmap(small.number_of_vertices());
  for (VertexIndex v : small.vertices()) {
    const Point3& p = small.point(v);
    vmap[v.idx()] = m.add_vertex(Point3(3 + 0.2 * p.x(), 0.2 * p.y(), 0.2 * p.z()));
  }
  for (FaceIndex f : small.faces()) {
    const auto v = face_vertices(small, f);
    m.add_face(vmap[v[0].idx()], vmap[v[1].idx()], vmap[v[2].idx()]);
  }
  PartitionOptions po;
  po.max_faces = 30;
  const PartitionResult pr = partition_near_planar(m, po);
  std::vector<int> seeds = pr.seed_face;
  split_overlapping_patches(m, seeds, 30.0);
  FlattenOptions fo;
  fo.resolution = 64;
  const FlattenResult fr = flatten_patches(m, seeds, fo);
  std::size_t stored_small = 0, small_patches = 0;
  for (const FlatPatch& fp : fr.patches) {
    ASSERT_EQ(fp.pixel.size(), static_cast<std::size_t>(fp.bw) * fp.bh);
    ASSERT_EQ(fp.pixel_face.size(), fp.pixel.size());
    ASSERT_EQ(fp.pixel_bary.size(), fp.pixel.size());
    ASSERT_TRUE(fp.bx >= 0 && fp.by >= 0 && fp.bx + fp.bw <= fp.res && fp.by + fp.bh <= fp.res);
    auto charted = [&](int x, int y) { return fp.state(x, y) != PatchPixel::Outside; };
    bool top = false, bottom = false, left = false, right = false;
    for (int x = fp.bx; x < fp.bx + fp.bw; ++x) top |= charted(x, fp.by), bottom |= charted(x, fp.by + fp.bh - 1);
    for (int y = fp.by; y < fp.by + fp.bh; ++y) left |= charted(fp.bx, y), right |= charted(fp.bx + fp.bw - 1, y);
    EXPECT_TRUE(top && bottom && left && right) << "patch " << fp.id << ": window not tight";
    for (const FlatTriangle& t : fp.triangles) {
      double cx = 0, cy = 0;
      for (const Uv2& c : t.corner) {
        const auto px = fp.to_pixel(c[0], c[1]);
        cx += px[0] / 3, cy += px[1] / 3;
      }
      EXPECT_EQ(fp.state(static_cast<int>(cx), static_cast<int>(cy)), PatchPixel::Inside)
          << "patch " << fp.id << " face " << t.face;
    }
    EXPECT_EQ(fp.state(-1, 0), PatchPixel::Outside);
    EXPECT_EQ(fp.state(fp.res, fp.res - 1), PatchPixel::Outside);
    if (fp.triangles.front().face >= big_faces) stored_small += fp.pixel.size(), ++small_patches;
  }
  ASSERT_GT(small_patches, 10u);
  EXPECT_LT(stored_small, small_patches * 64u * 64u / 8) << "the small sphere's patches keep large windows";
}

// Issue 18: each raster's rows run along the texture's +x at its seed
// (kFaceDirection), and on a plane under a steady field every patch's pixel
// centres lie on one world lattice of the texel, so the patches share one
// pixel grid and a neighbour's pixels are read at their centres (the flat
// square's gingham: fidelity ratio 1.53 -> 1.04, decision 505). Before, the
// rows ran along the seed's first edge and each raster was centred on its
// patch's box, half a texel off its neighbours on average.
TEST(FlattenPatches, RastersFollowTheFieldAndShareOneGridOnAPlane) {
  Mesh m;
  make_grid(m, 12, 12);
  const Vector3 dir(std::cos(0.5), std::sin(0.5), 0.0);  // 28.6 degrees: along no edge of the grid
  auto fd = get_or_add(m, kFaceDirection);
  for (FaceIndex f : m.faces()) fd[f] = dir;
  PartitionOptions po;
  po.max_faces = 20;
  const PartitionResult pr = partition_near_planar(m, po);
  std::vector<int> seeds = pr.seed_face;
  split_overlapping_patches(m, seeds, 30.0);
  FlattenOptions fo;
  fo.resolution = 48;
  const FlattenResult fr = flatten_patches(m, seeds, fo);
  ASSERT_GT(fr.patches.size(), 5u);
  const auto on_lattice = [&](double w) { return std::abs(w / fr.texel - std::round(w / fr.texel)) < 1e-6; };
  for (const FlatPatch& fp : fr.patches) {
    EXPECT_NEAR(fp.e1[0] * dir.x() + fp.e1[1] * dir.y() + fp.e1[2] * dir.z(), 1.0, 1e-12) << "patch " << fp.id;
    const double wu = fp.origin[0] * fp.e1[0] + fp.origin[1] * fp.e1[1] + fp.origin[2] * fp.e1[2];
    const double wv = fp.origin[0] * fp.e2[0] + fp.origin[1] * fp.e2[1] + fp.origin[2] * fp.e2[2];
    EXPECT_TRUE(on_lattice(wu + fp.u0) && on_lattice(wv + fp.v0)) << "patch " << fp.id << " is off the common grid";
    for (const FlatTriangle& t : fp.triangles)  // the shift kept every patch triangle on the raster
      for (const Uv2& c : t.corner) {
        const auto px = fp.to_pixel(c[0], c[1]);
        EXPECT_TRUE(px[0] > 0 && px[1] > 0 && px[0] < fp.res && px[1] < fp.res) << "patch " << fp.id;
      }
  }
}

TEST(FlattenPatches, NoOverlapsAndRasterStates) {
  for (int shape = 0; shape < 2; ++shape) {
    Mesh m;
    if (shape == 0) {
      make_icosphere(m, 3);
    } else {
      make_torus(m, 1.0, 0.4, 36, 18);
    }
    PartitionOptions po;
    po.max_faces = 50;
    const PartitionResult pr = partition_near_planar(m, po);
    std::vector<int> seeds = pr.seed_face;
    EXPECT_EQ(split_overlapping_patches(m, seeds, 30.0), 0);
    FlattenOptions fo;
    fo.resolution = 40;
    const FlattenResult fr = flatten_patches(m, seeds, fo);
    ASSERT_EQ(static_cast<int>(fr.patches.size()), pr.patches);
    std::size_t faces = 0, boundary = 0;
    for (const FlatPatch& fp : fr.patches) {
      faces += fp.triangles.size();
      boundary += fp.boundary.size();
      EXPECT_TRUE(patch_overlaps(fp).empty()) << "patch " << fp.id;
      // Kept boundary triangles overlap neither the patch nor each other.
      std::vector<FlatTriangle> all = fp.triangles;
      all.insert(all.end(), fp.boundary.begin(), fp.boundary.end());
      for (std::size_t i = fp.triangles.size(); i < all.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
          EXPECT_FALSE(triangles_overlap_2d(all[i].corner, all[j].corner));
      std::size_t inside = 0;
      for (std::size_t i = 0; i < fp.pixel.size(); ++i) {
        if (fp.pixel[i] == PatchPixel::Inside) {
          ++inside;
          EXPECT_GE(fp.pixel_face[i], 0);
          EXPECT_EQ(find(m, kFacePatch).first[FaceIndex(fp.pixel_face[i])], fp.id);
        }
        if (fp.pixel[i] == PatchPixel::Boundary) {
          EXPECT_NE(find(m, kFacePatch).first[FaceIndex(fp.pixel_face[i])], fp.id);
        }
      }
      EXPECT_GT(inside, 0u);
      // Patch triangles stay inside the raster (margin).
      for (const FlatTriangle& t : fp.triangles)
        for (const Uv2& c : t.corner) {
          const auto px = fp.to_pixel(c[0], c[1]);
          EXPECT_GE(px[0], fo.margin - 1e-6);
          EXPECT_LE(px[0], fo.resolution - fo.margin + 1e-6);
          EXPECT_GE(px[1], fo.margin - 1e-6);
          EXPECT_LE(px[1], fo.resolution - fo.margin + 1e-6);
        }
    }
    EXPECT_EQ(faces, m.number_of_faces());
    EXPECT_GT(boundary, 0u);
  }
}

TEST(FlattenPatches, RingOneTrianglesAreRotatedNotProjected) {
  // A cube: two patches meeting at 90 degrees. The neighbour triangle rotated
  // into the plane keeps its true shape (a projection would collapse it).
  Mesh m;
  make_cube(m, 2.0);
  PartitionOptions po;
  po.max_angle_deg = 10;
  const PartitionResult pr = partition_near_planar(m, po);
  ASSERT_EQ(pr.patches, 6);
  const FlatPatch fp = flatten_patch_geometry(m, 0, pr.seed_face[0], 1);
  ASSERT_FALSE(fp.boundary.empty());
  for (const FlatTriangle& t : fp.boundary) {
    const auto v = face_vertices(m, FaceIndex(t.face));
    for (int k = 0; k < 3; ++k) {
      const double l3 = std::sqrt((m.point(v[k]) - m.point(v[(k + 1) % 3])).squared_length());
      const double l2 = std::hypot(t.corner[k][0] - t.corner[(k + 1) % 3][0],
                                   t.corner[k][1] - t.corner[(k + 1) % 3][1]);
      EXPECT_NEAR(l2, l3, 1e-9);
    }
  }
}

TEST(FlattenPatches, SelfOverlappingProjectionIsSplit) {
  // A helicoidal ramp (1.3 turns) with gentle slope: all normals within 30
  // degrees of +z, but its projection onto the plane overlaps itself.
  Mesh m;
  const int nu = 80, nv = 4;
  std::vector<VertexIndex> vs;
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j) {
      const double th = 2.6 * M_PI * i / nu, r = 1.0 + 1.0 * j / nv;
      vs.push_back(m.add_vertex(Point3(r * std::cos(th), r * std::sin(th), 0.25 * th)));
    }
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      auto a = vs[i * (nv + 1) + j], b = vs[(i + 1) * (nv + 1) + j], c = vs[(i + 1) * (nv + 1) + j + 1],
           d = vs[i * (nv + 1) + j + 1];
      m.add_face(a, c, b);  // normals towards +z
      m.add_face(a, d, c);
    }
  auto pm = get_or_add(m, kFacePatch, 0);
  for (FaceIndex f : m.faces()) {
    pm[f] = 0;
    ASSERT_GT(robust_face_normal(m, f).z(), std::cos(30 * M_PI / 180));
  }
  std::vector<int> seeds{0};
  EXPECT_FALSE(patch_overlaps(flatten_patch_geometry(m, 0, 0, 0)).empty());
  EXPECT_GE(split_overlapping_patches(m, seeds, 30.0), 1);
  ASSERT_GE(seeds.size(), 2u);
  for (int p = 0; p < static_cast<int>(seeds.size()); ++p)
    EXPECT_TRUE(patch_overlaps(flatten_patch_geometry(m, p, seeds[p], 0)).empty()) << p;
  std::size_t total = 0;
  for (int p = 0; p < static_cast<int>(seeds.size()); ++p)
    total += flatten_patch_geometry(m, p, seeds[p], 0).triangles.size();
  EXPECT_EQ(total, m.number_of_faces());  // every face in exactly one patch
}

TEST(FlattenPatches, BadInputThrows) {
  Mesh m;
  make_icosphere(m, 1);
  EXPECT_THROW(flatten_patches(m, {}), InvalidInputError);  // no f:patch
  const PartitionResult pr = partition_near_planar(m, {});
  FlattenOptions fo;
  fo.resolution = 4;
  EXPECT_THROW(flatten_patches(m, pr.seed_face, fo), InvalidInputError);
  EXPECT_THROW(flatten_patches(m, {}, {}), InvalidInputError);  // seed count
}

}  // namespace
}  // namespace surftex
