// SPDX-License-Identifier: AGPL-3.0-or-later
// Surface fields of Ray et al. 2009 section 2: normals, principal curvatures,
// N-symmetry direction fields, scalar fields, effect areas.
#include <gtest/gtest.h>

#include <CGAL/Polygon_mesh_processing/remesh.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "geometry/direction_field.h"
#include "geometry/errors.h"
#include "geometry/direction_field_singularities.h"
#include "geometry/effect_area.h"
#include "geometry/mesh_util.h"
#include "geometry/primitive_meshes.h"
#include "geometry/principal_curvatures.h"
#include "geometry/properties.h"
#include "geometry/scalar_field_interpolation.h"
#include "geometry/surface_normals.h"

namespace surftex {
namespace {

double angle_deg_line(const Vector3& a, const Vector3& b) {  // angle between lines
  const double c = std::abs(a * b) / (norm(a) * norm(b));
  return std::acos(std::min(1.0, c)) * 180 / M_PI;
}

bool finite(const Vector3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

TEST(SurfaceNormals, IcosphereNormalsAreRadialForBothWeightings) {
  Mesh m;
  make_icosphere(m, 3);
  for (auto w : {NormalWeighting::kArea, NormalWeighting::kAngle}) {
    compute_vertex_normals(m, {w});
    auto vn = find(m, kVertexNormal).first;
    for (VertexIndex v : m.vertices()) {
      const Vector3 r = m.point(v) - CGAL::ORIGIN;
      EXPECT_GT(vn[v] * r / norm(r), 0.999);
    }
  }
  compute_face_normals(m);
  auto fn = find(m, kFaceNormal).first;
  for (FaceIndex f : m.faces()) {
    const auto vs = face_vertices(m, f);
    const Vector3 c = ((m.point(vs[0]) - CGAL::ORIGIN) + (m.point(vs[1]) - CGAL::ORIGIN) +
                       (m.point(vs[2]) - CGAL::ORIGIN)) / 3;
    EXPECT_GT(fn[f] * c, 0);
  }
}

/// A grid with slivers and a collapsed triangle: the third column of vertices
/// is squeezed onto the second, one vertex duplicated onto its neighbour.
Mesh skinny_grid() {
  Mesh m;
  make_grid(m, 8, 8, 1.0, 1.0);
  for (VertexIndex v : m.vertices()) {
    Point3 p = m.point(v);
    if (std::abs(p.x() - 0.25) < 1e-9) p = Point3(0.125 + 1e-9, p.y(), 0.01 * p.y() * p.y());
    m.point(v) = p;
  }
  m.point(VertexIndex(40)) = m.point(VertexIndex(41));
  return m;
}

TEST(PrincipalCurvatures, NoNanOnFlatAndSkinnyMeshesAndFlatFallsBackToReference) {
  Mesh flat;
  make_grid(flat, 10, 10);
  compute_principal_curvatures(flat);
  auto kmax = find(flat, kVertexKmax).first;
  auto dmax = find(flat, kVertexDmax).first;
  for (VertexIndex v : flat.vertices()) {
    EXPECT_NEAR(kmax[v], 0, 1e-8);
    EXPECT_LT(angle_deg_line(dmax[v], Vector3(1, 0, 0)), 1e-6);
  }
  Mesh sk = skinny_grid();
  compute_principal_curvatures(sk);
  auto k1 = find(sk, kVertexKmax).first, k2 = find(sk, kVertexKmin).first;
  auto d1 = find(sk, kVertexDmax).first, d2 = find(sk, kVertexDmin).first;
  for (VertexIndex v : sk.vertices()) {
    ASSERT_TRUE(std::isfinite(k1[v]) && std::isfinite(k2[v])) << v;
    ASSERT_TRUE(finite(d1[v]) && finite(d2[v])) << v;
    EXPECT_NEAR(norm(d1[v]), 1, 1e-9);
    EXPECT_GE(k1[v], k2[v]);
  }
}

TEST(PrincipalCurvatures, SphereIsUmbilicWithPositiveCurvature) {
  Mesh m;
  make_icosphere(m, 3, 2.0);
  const auto r = compute_principal_curvatures(m);
  auto k1 = find(m, kVertexKmax).first, k2 = find(m, kVertexKmin).first;
  for (VertexIndex v : m.vertices()) {
    EXPECT_NEAR(k1[v], 0.5, 0.03);
    EXPECT_NEAR(k2[v], 0.5, 0.03);
  }
  EXPECT_GT(r.umbilic_vertices, m.number_of_vertices() / 2);
}

// Analytic principal curvatures/directions of x^2/a^2+y^2/b^2+z^2/c^2 = 1 at p:
// eigen-decomposition of the shape operator P H P / |grad F| on the tangent plane.
void ellipsoid_principal(const Point3& p, double a, double b, double c, double& k1, double& k2,
                         Vector3& d1) {
  const Eigen::Vector3d g(2 * p.x() / (a * a), 2 * p.y() / (b * b), 2 * p.z() / (c * c));
  const Eigen::Vector3d n = g.normalized();
  Eigen::Vector3d t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  const Eigen::Matrix3d H = Eigen::Vector3d(2 / (a * a), 2 / (b * b), 2 / (c * c)).asDiagonal();
  Eigen::Matrix2d S;
  S << t1.dot(H * t1), t1.dot(H * t2), t2.dot(H * t1), t2.dot(H * t2);
  S /= g.norm();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(S);
  k2 = es.eigenvalues()[0];
  k1 = es.eigenvalues()[1];
  const Eigen::Vector3d d = es.eigenvectors()(0, 1) * t1 + es.eigenvectors()(1, 1) * t2;
  d1 = Vector3(d.x(), d.y(), d.z());
}

TEST(PrincipalCurvatures, EllipsoidDirectionsMatchAnalyticAwayFromUmbilics) {
  Mesh m;
  const double a = 3, b = 2, c = 1;
  make_ellipsoid(m, a, b, c, 4);
  compute_principal_curvatures(m);
  auto kmax = find(m, kVertexKmax).first;
  auto dmax = find(m, kVertexDmax).first;
  int checked = 0, bad = 0;
  double worst = 0;
  for (VertexIndex v : m.vertices()) {
    double k1, k2;
    Vector3 d1;
    ellipsoid_principal(m.point(v), a, b, c, k1, k2, d1);
    if ((k1 - k2) < 0.25 * k1) continue;  // near the four umbilics
    ++checked;
    const double ang = angle_deg_line(dmax[v], d1);
    worst = std::max(worst, ang);
    if (ang > 10) ++bad;
    EXPECT_NEAR(kmax[v], k1, 0.15 * k1);
  }
  EXPECT_GT(checked, 1000);
  EXPECT_EQ(bad, 0) << "worst " << worst << " degrees";
  // Axis endpoints: at (a,0,0) kmax = a/c^2 along z, kmin = a/b^2 along y.
  VertexIndex best;
  double bd = 1e9;
  for (VertexIndex v : m.vertices()) {
    const double d = CGAL::squared_distance(m.point(v), Point3(a, 0, 0));
    if (d < bd) bd = d, best = v;
  }
  EXPECT_NEAR(kmax[best], a / (c * c), 0.4);
  EXPECT_LT(angle_deg_line(dmax[best], Vector3(0, 0, 1)), 10);
}

TEST(PrincipalCurvatures, TorusMaxDirectionFollowsTheMeridian) {
  Mesh m;
  make_torus(m, 3.0, 1.0, 96, 48);
  compute_principal_curvatures(m);
  auto kmax = find(m, kVertexKmax).first;
  auto dmax = find(m, kVertexDmax).first;
  double worst = 0;
  for (VertexIndex v : m.vertices()) {
    const Point3 p = m.point(v);
    const Vector3 parallel = normalized_or(Vector3(-p.y(), p.x(), 0), Vector3(1, 0, 0));
    worst = std::max(worst, 90 - angle_deg_line(dmax[v], parallel));
    EXPECT_NEAR(kmax[v], 1.0, 0.05);
  }
  EXPECT_LT(worst, 10);
}

TEST(DirectionField, OneConstraintOnAGridGivesAConstantField) {
  Mesh m;
  make_grid(m, 12, 12);
  const Vector3 d(std::cos(0.4), std::sin(0.4), 0);
  interpolate_direction_field(m, {{7, {d.x(), d.y(), d.z()}}}, {});
  auto dir = find(m, kFaceDirection).first;
  for (FaceIndex f : m.faces()) {
    // 4-symmetric: equal modulo 90 degrees, and combed: exactly equal.
    EXPECT_NEAR(dir[f] * d, 1.0, 1e-9) << f;
  }
}

// The map-free form (what the surface quilter uses on its const base mesh)
// gives the map form's directions bit for bit and leaves the mesh untouched.
TEST(DirectionField, TheMapFreeFormMatchesTheMapFormAndAddsNoMap) {
  Mesh m = skinny_grid();
  const std::vector<DirectionConstraint> c{{0, {1, 0, 0}}, {100, {0.3, 1, 0}}};
  DirectionFieldOptions o;
  o.smoothing = 2;
  const Mesh& cm = m;
  std::vector<Vector3> dirs(m.num_faces(), Vector3(0, 0, 0));
  const auto r1 = interpolate_direction_field(cm, c, dirs, o);
  EXPECT_FALSE(find(m, kFaceDirection).second);
  const auto r2 = interpolate_direction_field(m, c, o);
  EXPECT_EQ(r1.solved_faces, r2.solved_faces);
  auto dir = find(m, kFaceDirection).first;
  for (FaceIndex f : m.faces()) {
    EXPECT_EQ(dirs[f.idx()].x(), dir[f].x());
    EXPECT_EQ(dirs[f.idx()].y(), dir[f].y());
    EXPECT_EQ(dirs[f.idx()].z(), dir[f].z());
  }
  std::vector<Vector3> short_list(3, Vector3(0, 0, 0));
  EXPECT_THROW(interpolate_direction_field(cm, c, short_list, o), InvalidInputError);
}

TEST(DirectionField, LocksConstraintsAndNeverNan) {
  Mesh m = skinny_grid();
  std::vector<DirectionConstraint> c{{0, {1, 0, 0}}, {100, {0.3, 1, 0}}};
  for (int n : {1, 2, 4}) {
    DirectionFieldOptions o;
    o.symmetry = n;
    interpolate_direction_field(m, c, o);
    auto dir = find(m, kFaceDirection).first;
    for (FaceIndex f : m.faces()) {
      ASSERT_TRUE(finite(dir[f]));
      EXPECT_NEAR(norm(dir[f]), 1, 1e-9);
    }
    // Constrained face keeps its orientation modulo 2 pi / N.
    const FaceFrame fr = face_frame(m, FaceIndex(100));
    const double th = fr.angle_of(dir[FaceIndex(100)]) - fr.angle_of(Vector3(0.3, 1, 0));
    EXPECT_NEAR(std::remainder(th, 2 * M_PI / n), 0, 1e-9);
  }
  EXPECT_THROW(interpolate_direction_field(m, {}, {}), InvalidInputError);
  EXPECT_THROW(interpolate_direction_field(m, {{99999, {1, 0, 0}}}, {}), InvalidInputError);
  EXPECT_THROW(interpolate_direction_field(m, {{0, {0, 0, 1}}}, {}), InvalidInputError);
}

TEST(DirectionField, FloorVectorIsOrthogonalToTheVectorAndAwayFromTheViewer) {
  const auto f = floor_vector({0, 1, 0});
  EXPECT_NEAR(f[0], 0, 1e-12);
  EXPECT_NEAR(f[1], 0, 1e-12);
  EXPECT_NEAR(f[2], -1, 1e-12);
  const auto g = floor_vector({0.3, -2, 5});
  EXPECT_NEAR(g[0] * 0.3 - g[1] * 2 + g[2] * 5, 0, 1e-12);
  EXPECT_NEAR(g[0] * g[0] + g[1] * g[1] + g[2] * g[2], 1, 1e-12);
  EXPECT_THROW(floor_vector({0, 0, 0}), InvalidInputError);
  EXPECT_THROW(floor_vector({0, NAN, 1}), InvalidInputError);
}

// A face of the top (normal +y) whose neighbours across its edges are too:
// the rim's faces are where the rows turn from the walls' to the top's.
bool inner_top_face(const Mesh& m, FaceIndex f) {
  bool inner = robust_face_normal(m, f).y() > 0.99;
  for (HalfedgeIndex h : CGAL::halfedges_around_face(m.halfedge(f), m))
    inner = inner && robust_face_normal(m, m.face(m.opposite(h))).y() > 0.99;
  return inner;
}

// A box's top and bottom are orthogonal to the up vector, so its projection
// constrains only the walls, whose directions circle the top: interpolated
// into it, they meet in a singularity (radial rows on a CAD part's flat top,
// issue 18). With floor_constraints the top holds one direction.
TEST(DirectionField, FlatTopsHoldParallelRowsNotTheRimsSingularity) {
  Mesh box;
  make_cube(box, 2.0);
  CGAL::Polygon_mesh_processing::split_long_edges(edges(box), 0.25, box);
  const std::array<double, 3> up{0, 1, 0};
  auto top_spread_deg = [&](bool floors) {
    std::vector<DirectionConstraint> c = constraints_from_constant_vector(box, up);
    if (floors)
      for (const DirectionConstraint& f : floor_constraints(box, up)) c.push_back(f);
    DirectionFieldOptions o;
    o.symmetry = 1;
    interpolate_direction_field(box, c, o);
    auto dir = find(box, kFaceDirection).first;
    double worst = 0;
    int top = 0;
    for (FaceIndex f : box.faces()) {
      if (!inner_top_face(box, f)) continue;
      ++top;
      worst = std::max(worst, std::acos(std::clamp(dir[f] * Vector3(0, 0, -1), -1.0, 1.0)) * 180 / M_PI);
    }
    EXPECT_GE(top, 8);
    return worst;
  };
  EXPECT_LT(top_spread_deg(true), 1.0);
  EXPECT_GT(top_spread_deg(false), 60.0);  // the case the floors are for
}

// The faces of a cylinder's side whose normal is the vector form a band one
// face wide: a curved surface turning through orthogonal, where the rows
// circle without a singularity. floor_constraints leaves it out (its faces'
// neighbours across the long edges are not flat).
TEST(DirectionField, FloorsLeaveOutTheCrestOfACurvedSurface) {
  Mesh m;
  make_cylinder(m, 1.0, 3.0, 64, 12);
  Vector3 v(0, 0, 0);
  for (FaceIndex f : m.faces())
    if (std::abs(robust_face_normal(m, f).z()) < 1e-9) {
      v = robust_face_normal(m, f);
      break;
    }
  ASSERT_GT(norm(v), 0.5);
  int band = 0;
  for (FaceIndex f : m.faces()) band += robust_face_normal(m, f) * v > std::cos(0.01);
  EXPECT_GE(band, 12);
  EXPECT_TRUE(floor_constraints(m, {v.x(), v.y(), v.z()}).empty());
}

int index_sum(const Mesh& m, int n) {
  FieldIndexOptions o;
  o.symmetry = n;
  const auto idx = direction_field_indices(m, o);
  return std::accumulate(idx.begin(), idx.end(), 0);
}

TEST(DirectionField, PoincareHopfOnSphereAndTorus) {
  Mesh sphere;
  make_ellipsoid(sphere, 1.5, 1.0, 0.8, 3);
  // Sparse strokes: a handful of faces.
  std::vector<DirectionConstraint> c;
  for (std::uint32_t f : {0u, 97u, 333u, 611u, 1000u})
    c.push_back({f, {1, 0.5, 0.2}});
  for (int n : {1, 2, 4}) {
    DirectionFieldOptions o;
    o.symmetry = n;
    interpolate_direction_field(sphere, c, o);
    EXPECT_EQ(index_sum(sphere, n), 2 * n) << "N=" << n;
  }
  Mesh torus;
  make_torus(torus, 3.0, 1.0, 48, 24);
  compute_principal_curvatures(torus);
  interpolate_direction_field(torus, constraints_from_principal_directions(torus, 0.05), {});
  EXPECT_EQ(index_sum(torus, 4), 0);
  // The torus field from principal directions follows the parallels: no singularity.
  const auto idx = direction_field_indices(torus, {});
  EXPECT_EQ(std::count_if(idx.begin(), idx.end(), [](int i) { return i != 0; }), 0);
  // Constant-vector field on a sphere: singularities at least at the poles.
  interpolate_direction_field(sphere, constraints_from_constant_vector(sphere, {0, 0, 1}), {});
  EXPECT_EQ(index_sum(sphere, 4), 8);
  const auto sidx = direction_field_indices(sphere, {});
  EXPECT_GE(std::count_if(sidx.begin(), sidx.end(), [](int i) { return i != 0; }), 2);
}

// Noisy constraints (every 10th face of a torus locked to its parallel
// turned by a pseudo-random +-40 degrees): locked exactly, neighbouring
// disagreements become field singularities; smoothing (soft constraints)
// removes most of them, keeps Poincare-Hopf, and leaves the field close to
// the parallels on average.
TEST(DirectionField, SmoothingRemovesSingularitiesOfNoisyConstraints) {
  Mesh m;
  make_torus(m, 3.0, 1.0, 48, 24);
  std::vector<DirectionConstraint> c;
  std::uint32_t state = 12345;  // LCG: an explicit, fixed seed
  for (FaceIndex f : m.faces()) {
    if (f.idx() % 10 != 0) continue;
    state = state * 1664525u + 1013904223u;
    const double jitter = (double(state >> 8) / double(1u << 24) - 0.5) * 80 * M_PI / 180;
    Vector3 mid(0, 0, 0);
    for (VertexIndex v : face_vertices(m, f)) mid = mid + (m.point(v) - CGAL::ORIGIN) / 3.0;
    const Vector3 par(-mid.y(), mid.x(), 0), up(0, 0, 1);
    const Vector3 d = std::cos(jitter) * par / norm(par) + std::sin(jitter) * up;
    c.push_back({static_cast<std::uint32_t>(f.idx()), {d.x(), d.y(), d.z()}});
  }
  auto singular = [&] {
    const auto idx = direction_field_indices(m, {});
    return std::count_if(idx.begin(), idx.end(), [](int i) { return i != 0; });
  };
  interpolate_direction_field(m, c, {});
  const auto hard = singular();
  DirectionFieldOptions o;
  o.smoothing = 16;
  interpolate_direction_field(m, c, o);
  const auto smooth = singular();
  EXPECT_EQ(index_sum(m, 4), 0);
  EXPECT_GT(hard, 10);  // the noise does create singularities (24)
  EXPECT_LT(smooth, hard / 2);  // measured 24 -> 8
  // Mean angle to the parallels (modulo quarter turns) stays small.
  auto dir = find(m, kFaceDirection).first;
  double mean = 0;
  for (FaceIndex f : m.faces()) {
    Vector3 mid(0, 0, 0);
    for (VertexIndex v : face_vertices(m, f)) mid = mid + (m.point(v) - CGAL::ORIGIN) / 3.0;
    const FaceFrame fr = face_frame(m, f);
    const double a = fr.angle_of(dir[f]) - fr.angle_of(Vector3(-mid.y(), mid.x(), 0));
    mean += std::abs(std::remainder(a, M_PI / 2));
  }
  mean /= double(m.number_of_faces());
  EXPECT_LT(mean * 180 / M_PI, 10.0);
  o.smoothing = -1;
  EXPECT_THROW(interpolate_direction_field(m, c, o), InvalidInputError);
}

TEST(ScalarField, ReproducesLinearFunctionAndClamps) {
  Mesh m;
  make_grid(m, 10, 10, 2.0, 1.0);
  std::vector<ScalarConstraint> c;
  for (VertexIndex v : m.vertices())
    if (m.is_border(v)) c.push_back({static_cast<std::uint32_t>(v.idx()), 0.25 * m.point(v).x()});
  ScalarFieldOptions o = material_field_options();
  interpolate_scalar_field(m, c, o);
  auto mat = find(m, kVertexMaterial).first;
  for (VertexIndex v : m.vertices()) EXPECT_NEAR(mat[v], 0.25 * m.point(v).x(), 1e-9);

  // Out-of-range constraints: m in [0,1], S >= eps, never NaN (skinny mesh).
  Mesh sk = skinny_grid();
  const double eps = 1e-3;
  interpolate_scalar_field(sk, {{0, -3.0}, {50, 7.0}, {80, 0.5}}, material_field_options());
  interpolate_scalar_field(sk, {{0, -3.0}, {50, 2.0}}, scale_field_options(eps));
  auto mm = find(sk, kVertexMaterial).first;
  auto ss = find(sk, kVertexScale).first;
  for (VertexIndex v : sk.vertices()) {
    EXPECT_GE(mm[v], 0.0);
    EXPECT_LE(mm[v], 1.0);
    EXPECT_GE(ss[v], eps);
    EXPECT_TRUE(std::isfinite(ss[v]));
  }
  EXPECT_DOUBLE_EQ(mm[VertexIndex(80)], 0.5);
  EXPECT_THROW(interpolate_scalar_field(sk, {{100000, 1.0}}, material_field_options()),
               InvalidInputError);
}

TEST(EffectArea, GrowsByDistanceAndRespectsTheFaceBudget) {
  Mesh m;
  make_grid(m, 20, 20);
  EffectAreaOptions o;
  o.radius = 0.2;
  const std::uint32_t center = 10 * 21 + 10;
  const EffectArea a = compute_effect_area(m, {center}, o);
  EXPECT_GT(a.free_vertices, 5u);
  for (VertexIndex v : m.vertices()) {
    const double d = std::sqrt(CGAL::squared_distance(m.point(v), m.point(VertexIndex(center))));
    if (a.vertex_free[v.idx()]) {
      EXPECT_LE(d, 0.2 + 1e-12);
    }
    if (d < 0.1) {
      EXPECT_TRUE(a.vertex_free[v.idx()]) << v;
    }
  }
  o.radius = std::numeric_limits<double>::infinity();
  o.max_faces = 100;
  const EffectArea b = compute_effect_area(m, {center}, o);
  EXPECT_EQ(b.free_faces, 100u);
  EXPECT_THROW(compute_effect_area(m, {}, {}), InvalidInputError);
}

}  // namespace
}  // namespace surftex
