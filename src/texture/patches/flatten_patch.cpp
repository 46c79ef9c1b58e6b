// SPDX-License-Identifier: AGPL-3.0-or-later
// Patch flattening with rotated boundary triangles (Gorla et al. 2003, 3.2).
#include "texture/patches/flatten_patch.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

#include "geometry/image.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

using Tri2 = std::array<Uv2, 3>;

CGAL::Orientation orient(const Uv2& a, const Uv2& b, const Uv2& c) {
  return CGAL::orientation(Point2(a[0], a[1]), Point2(b[0], b[1]), Point2(c[0], c[1]));
}

struct Box2 {
  double x0, y0, x1, y1;
};
Box2 box_of(const Tri2& t) {
  Box2 b{t[0][0], t[0][1], t[0][0], t[0][1]};
  for (const Uv2& p : t) {
    b.x0 = std::min(b.x0, p[0]);
    b.y0 = std::min(b.y0, p[1]);
    b.x1 = std::max(b.x1, p[0]);
    b.y1 = std::max(b.y1, p[1]);
  }
  return b;
}
bool boxes_overlap(const Box2& a, const Box2& b) {
  return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

std::vector<int> read_patches(const Mesh& mesh, int& count) {
  auto [pm, found] = find(mesh, kFacePatch);
  if (!found) throw InvalidInputError("flatten_patches: the mesh has no f:patch map (partition first)");
  std::vector<int> patch(mesh.num_faces(), -1);
  count = 0;
  for (FaceIndex f : mesh.faces()) {
    if (pm[f] < 0)
      throw InvalidInputError("flatten_patches: face " + std::to_string(f.idx()) + " has no patch (" +
                              std::to_string(pm[f]) + ")");
    patch[f.idx()] = pm[f];
    count = std::max(count, pm[f] + 1);
  }
  return patch;
}

}  // namespace

bool triangles_overlap_2d(const Tri2& a, const Tri2& b) {
  const CGAL::Orientation oa = orient(a[0], a[1], a[2]);
  const CGAL::Orientation ob = orient(b[0], b[1], b[2]);
  if (oa == CGAL::COLLINEAR || ob == CGAL::COLLINEAR) return false;
  // Separating axis: two convex polygons have disjoint interiors iff a line
  // through an edge of one of them has the other polygon entirely on its
  // closed outer side.
  auto separated = [](const Tri2& t, CGAL::Orientation ot, const Tri2& o) {
    for (int i = 0; i < 3; ++i) {
      const Uv2& p = t[i];
      const Uv2& q = t[(i + 1) % 3];
      bool all_out = true;
      for (int k = 0; k < 3 && all_out; ++k) {
        const CGAL::Orientation s = orient(p, q, o[k]);
        if (s == ot) all_out = false;  // strictly on the inner side
      }
      if (all_out) return true;
    }
    return false;
  };
  return !separated(a, oa, b) && !separated(b, ob, a);
}

FlatPatch flatten_patch_geometry(const Mesh& mesh, int patch, int seed_face, int rings) {
  auto [pm, found] = find(mesh, kFacePatch);
  if (!found) throw InvalidInputError("flatten_patch_geometry: the mesh has no f:patch map");
  const FaceIndex sf(static_cast<Mesh::size_type>(seed_face));
  if (seed_face < 0 || seed_face >= static_cast<int>(mesh.num_faces()) || pm[sf] != patch)
    throw InvalidInputError("flatten_patch_geometry: seed face " + std::to_string(seed_face) +
                            " is not in patch " + std::to_string(patch));
  FlatPatch fp;
  fp.id = patch;
  fp.seed_face = seed_face;
  const auto sv = face_vertices(mesh, sf);
  const Point3 o = CGAL::centroid(mesh.point(sv[0]), mesh.point(sv[1]), mesh.point(sv[2]));
  const Vector3 n = robust_face_normal(mesh, sf);
  // The raster's rows along the texture's +x at the seed (kFaceDirection, when
  // the field is there), else along the seed's first edge: see
  // docs/decisions/505-efros-leung-details.md ("raster frame").
  auto fdir = find(mesh, kFaceDirection);
  Vector3 e1 = fdir.second && fdir.first[sf].squared_length() > 0 ? fdir.first[sf] : mesh.point(sv[1]) - mesh.point(sv[0]);
  e1 = e1 - (e1 * n) * n;
  e1 = normalized_or(e1, std::abs(n.x()) < 0.9 ? CGAL::cross_product(n, Vector3(1, 0, 0))
                                               : CGAL::cross_product(n, Vector3(0, 1, 0)));
  e1 = normalized_or(e1, Vector3(1, 0, 0));
  const Vector3 e2 = CGAL::cross_product(n, e1);
  fp.origin = {o.x(), o.y(), o.z()};
  fp.e1 = {e1.x(), e1.y(), e1.z()};
  fp.e2 = {e2.x(), e2.y(), e2.z()};
  fp.normal = {n.x(), n.y(), n.z()};
  auto project = [&](VertexIndex v) -> Uv2 {
    const Vector3 d = mesh.point(v) - o;
    return {d * e1, d * e2};
  };
  // Patch triangles, breadth-first from the seed (the order split uses).
  std::vector<int> placed(mesh.num_faces(), 0);  // 0 = no, 1 = patch, 2 = boundary visited
  std::vector<Uv2> vuv(mesh.num_vertices());
  std::vector<char> vin(mesh.num_vertices(), 0);
  std::deque<FaceIndex> q{sf};
  placed[seed_face] = 1;
  while (!q.empty()) {
    const FaceIndex f = q.front();
    q.pop_front();
    FlatTriangle t;
    t.face = static_cast<int>(f.idx());
    const auto v = face_vertices(mesh, f);
    for (int k = 0; k < 3; ++k) {
      t.corner[k] = project(v[k]);
      vuv[v[k].idx()] = t.corner[k];
      vin[v[k].idx()] = 1;
    }
    fp.triangles.push_back(t);
    for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const FaceIndex g = mesh.face(mesh.opposite(h));
      if (g == Mesh::null_face() || placed[g.idx()] || pm[g] != patch) continue;
      placed[g.idx()] = 1;
      q.push_back(g);
    }
  }
  // Boundary rings: unfold neighbours about shared edges.
  std::vector<Box2> boxes;
  for (const FlatTriangle& t : fp.triangles) boxes.push_back(box_of(t.corner));
  std::vector<FlatTriangle> ring_prev = fp.triangles;
  std::vector<FlatTriangle> kept;
  for (int r = 1; r <= rings; ++r) {
    std::vector<FlatTriangle> ring_now;
    for (const FlatTriangle& pt : ring_prev) {
      const FaceIndex f(static_cast<Mesh::size_type>(pt.face));
      const auto fv = face_vertices(mesh, f);
      HalfedgeIndex h = mesh.halfedge(f);  // target(h) = fv[0]
      for (int k = 0; k < 3; ++k, h = mesh.next(h)) {
        // halfedge h goes from fv[(k+2)%3] to fv[k]
        const FaceIndex g = mesh.face(mesh.opposite(h));
        if (g == Mesh::null_face() || placed[g.idx()] || pm[g] == patch) continue;
        placed[g.idx()] = 2;
        const int ia = (k + 2) % 3, ib = k, ic = (k + 1) % 3;
        const Point3& A = mesh.point(fv[ia]);
        const Point3& B = mesh.point(fv[ib]);
        const Uv2 a = pt.corner[ia], b = pt.corner[ib], cin = pt.corner[ic];
        const auto gv = face_vertices(mesh, g);
        FlatTriangle t;
        t.face = static_cast<int>(g.idx());
        t.ring = r;
        for (int j = 0; j < 3; ++j) {
          const VertexIndex w = gv[j];
          if (w == fv[ia]) { t.corner[j] = a; continue; }
          if (w == fv[ib]) { t.corner[j] = b; continue; }
          if (vin[w.idx()]) { t.corner[j] = vuv[w.idx()]; continue; }
          const Vector3 AB = B - A, AC = mesh.point(w) - A;
          const double L3 = AB.squared_length();
          const double tt = L3 > 0 ? (AC * AB) / L3 : 0.0;
          const double d = norm(AC - tt * AB);
          const double abx = b[0] - a[0], aby = b[1] - a[1];
          const double L2 = std::hypot(abx, aby);
          const double s = L3 > 0 ? L2 / std::sqrt(L3) : 0.0;
          double px = -aby, py = abx;  // left normal of a->b
          if (L2 > 0) { px /= L2; py /= L2; }
          // the patch triangle's third vertex side: put C on the other side
          const double side = (cin[0] - a[0]) * px + (cin[1] - a[1]) * py;
          const double sg = side > 0 ? -1.0 : 1.0;
          t.corner[j] = {a[0] + tt * abx + sg * d * s * px, a[1] + tt * aby + sg * d * s * py};
        }
        // Overlap check against everything placed so far.
        const Box2 bb = box_of(t.corner);
        bool overlap = false;
        for (std::size_t i = 0; i < boxes.size() && !overlap; ++i) {
          if (!boxes_overlap(bb, boxes[i])) continue;
          const Tri2& other =
              i < fp.triangles.size() ? fp.triangles[i].corner : kept[i - fp.triangles.size()].corner;
          overlap = triangles_overlap_2d(t.corner, other);
        }
        if (overlap) {
          ++fp.dropped_boundary;
          continue;
        }
        boxes.push_back(bb);
        kept.push_back(t);
        ring_now.push_back(t);
      }
    }
    ring_prev = std::move(ring_now);
  }
  fp.boundary = std::move(kept);
  return fp;
}

std::vector<std::array<int, 2>> patch_overlaps(const FlatPatch& patch) {
  std::vector<std::array<int, 2>> out;
  const auto& T = patch.triangles;
  std::vector<Box2> b(T.size());
  for (std::size_t i = 0; i < T.size(); ++i) b[i] = box_of(T[i].corner);
  for (std::size_t i = 0; i < T.size(); ++i)
    for (std::size_t j = i + 1; j < T.size(); ++j)
      if (boxes_overlap(b[i], b[j]) && triangles_overlap_2d(T[i].corner, T[j].corner))
        out.push_back({T[i].face, T[j].face});
  return out;
}

int split_overlapping_patches(Mesh& mesh, std::vector<int>& seeds, double max_angle_deg,
                              int max_rounds) {
  if (!(max_angle_deg > 0 && max_angle_deg < 90))
    throw InvalidInputError("split_overlapping_patches: max_angle_deg " +
                            std::to_string(max_angle_deg) + " outside (0, 90)");
  require_triangle_mesh(mesh, "split_overlapping_patches");
  int count = 0;
  std::vector<int> patch = read_patches(mesh, count);
  if (static_cast<int>(seeds.size()) != count)
    throw InvalidInputError("split_overlapping_patches: " + std::to_string(seeds.size()) +
                            " seed faces for " + std::to_string(count) + " patches");
  const double cos_max = std::cos(max_angle_deg * M_PI / 180.0);
  int split = 0;
  for (int round = 0; round < max_rounds; ++round) {
    std::vector<int> leaving;
    for (int p = 0; p < count; ++p) {
      const FlatPatch fp = flatten_patch_geometry(mesh, p, seeds[p], 0);
      const auto ov = patch_overlaps(fp);
      if (ov.empty()) continue;
      ++split;
      std::vector<int> rank(mesh.num_faces(), -1);
      for (std::size_t i = 0; i < fp.triangles.size(); ++i) rank[fp.triangles[i].face] = static_cast<int>(i);
      std::vector<char> out(mesh.num_faces(), 0);
      for (const auto& pr : ov) {
        if (out[pr[0]] || out[pr[1]]) continue;
        out[rank[pr[0]] > rank[pr[1]] ? pr[0] : pr[1]] = 1;
      }
      // Faces no longer connected to the seed leave too.
      std::vector<char> reach(mesh.num_faces(), 0);
      std::deque<int> q{seeds[p]};
      reach[seeds[p]] = 1;
      while (!q.empty()) {
        const FaceIndex f(static_cast<Mesh::size_type>(q.front()));
        q.pop_front();
        for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
          const FaceIndex g = mesh.face(mesh.opposite(h));
          if (g == Mesh::null_face() || reach[g.idx()] || out[g.idx()] || patch[g.idx()] != p) continue;
          reach[g.idx()] = 1;
          q.push_back(static_cast<int>(g.idx()));
        }
      }
      for (const FlatTriangle& t : fp.triangles)
        if (!reach[t.face]) leaving.push_back(t.face);
    }
    if (leaving.empty()) break;
    std::sort(leaving.begin(), leaving.end());
    for (int f : leaving) patch[f] = -1;
    // Regrow new patches from the leaving faces (lowest index first).
    for (int f : leaving) {
      if (patch[f] != -1) continue;
      const int id = count++;
      seeds.push_back(f);
      const FaceIndex sf(static_cast<Mesh::size_type>(f));
      const Vector3 ns = robust_face_normal(mesh, sf);
      patch[f] = id;
      std::deque<int> q{f};
      while (!q.empty()) {
        const FaceIndex g(static_cast<Mesh::size_type>(q.front()));
        q.pop_front();
        for (HalfedgeIndex h : CGAL::halfedges_around_face(mesh.halfedge(g), mesh)) {
          const FaceIndex k = mesh.face(mesh.opposite(h));
          if (k == Mesh::null_face() || patch[k.idx()] != -1) continue;
          if (robust_face_normal(mesh, k) * ns < cos_max) continue;
          patch[k.idx()] = id;
          q.push_back(static_cast<int>(k.idx()));
        }
      }
    }
    auto pm = get_or_add(mesh, kFacePatch, -1);
    for (FaceIndex f : mesh.faces()) pm[f] = patch[f.idx()];
  }
  return split;
}

namespace {

// A triangle's pixel range in the raster (inclusive, clipped to 0..res-1) and
// its corners in pixel units; false when degenerate or off the raster.
struct TriangleSpan {
  std::array<std::array<double, 2>, 3> q;
  double det = 0;
  int x0 = 0, x1 = -1, y0 = 0, y1 = -1;
};

bool triangle_span(const FlatPatch& fp, const FlatTriangle& t, TriangleSpan& s) {
  for (int k = 0; k < 3; ++k) s.q[k] = fp.to_pixel(t.corner[k][0], t.corner[k][1]);
  const auto& q = s.q;
  s.det = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
  if (!(std::abs(s.det) > 1e-18)) return false;
  const int R = fp.res;
  s.x0 = std::max(0, static_cast<int>(std::floor(std::min({q[0][0], q[1][0], q[2][0]}) - 0.5)));
  s.x1 = std::min(R - 1, static_cast<int>(std::ceil(std::max({q[0][0], q[1][0], q[2][0]}))));
  s.y0 = std::max(0, static_cast<int>(std::floor(std::min({q[0][1], q[1][1], q[2][1]}) - 0.5)));
  s.y1 = std::min(R - 1, static_cast<int>(std::ceil(std::max({q[0][1], q[1][1], q[2][1]}))));
  return s.x0 <= s.x1 && s.y0 <= s.y1;
}

// Window (bx, by, bw, bh) and arrays of fp set to the given box, all Outside.
void reset_window(FlatPatch& fp, int x0, int y0, int x1, int y1) {
  fp.bx = x0;
  fp.by = y0;
  fp.bw = x1 - x0 + 1;
  fp.bh = y1 - y0 + 1;
  const std::size_t N = static_cast<std::size_t>(fp.bw) * fp.bh;
  fp.pixel.assign(N, PatchPixel::Outside);
  fp.pixel_face.assign(N, -1);
  fp.pixel_bary.assign(N, {0.f, 0.f, 0.f});
}

// Pixels whose centre lies in t (and not yet claimed) take kind, face and
// barycentrics; the window must cover t's span.
void rasterise_triangle(FlatPatch& fp, const FlatTriangle& t, const TriangleSpan& s, PatchPixel kind) {
  const auto& q = s.q;
  for (int y = s.y0; y <= s.y1; ++y)
    for (int x = s.x0; x <= s.x1; ++x) {
      const std::size_t i = fp.index(x, y);
      if (fp.pixel[i] != PatchPixel::Outside) continue;
      const double px = x + 0.5, py = y + 0.5;
      const double b1 = ((px - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (py - q[0][1])) / s.det;
      const double b2 = ((q[1][0] - q[0][0]) * (py - q[0][1]) - (px - q[0][0]) * (q[1][1] - q[0][1])) / s.det;
      const double b0 = 1.0 - b1 - b2;
      const double eps = -1e-9;
      if (b0 < eps || b1 < eps || b2 < eps) continue;
      fp.pixel[i] = kind;
      fp.pixel_face[i] = t.face;
      fp.pixel_bary[i] = {static_cast<float>(b0), static_cast<float>(b1), static_cast<float>(b2)};
    }
}

// The window shrunk to the box of its Inside and Boundary pixels.
void crop_window(FlatPatch& fp) {
  int x0 = fp.bx + fp.bw, y0 = fp.by + fp.bh, x1 = -1, y1 = -1;
  for (std::size_t i = 0; i < fp.pixel.size(); ++i)
    if (fp.pixel[i] != PatchPixel::Outside) {
      x0 = std::min(x0, fp.raster_x(i));
      x1 = std::max(x1, fp.raster_x(i));
      y0 = std::min(y0, fp.raster_y(i));
      y1 = std::max(y1, fp.raster_y(i));
    }
  if (x1 < 0) {
    reset_window(fp, 0, 0, 0, 0);
    return;
  }
  if (x0 == fp.bx && y0 == fp.by && x1 == fp.bx + fp.bw - 1 && y1 == fp.by + fp.bh - 1) return;
  FlatPatch old;
  old.bx = fp.bx, old.by = fp.by, old.bw = fp.bw, old.bh = fp.bh;
  old.pixel.swap(fp.pixel);
  old.pixel_face.swap(fp.pixel_face);
  old.pixel_bary.swap(fp.pixel_bary);
  reset_window(fp, x0, y0, x1, y1);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const std::size_t i = fp.index(x, y), j = old.index(x, y);
      fp.pixel[i] = old.pixel[j];
      fp.pixel_face[i] = old.pixel_face[j];
      fp.pixel_bary[i] = old.pixel_bary[j];
    }
}

// The patch's pixels (3.2): Inside where a patch triangle covers the centre,
// else Boundary where a kept neighbour triangle does; stored in the window of
// those pixels.
void rasterise_patch(FlatPatch& fp) {
  std::vector<TriangleSpan> in(fp.triangles.size()), out(fp.boundary.size());
  std::vector<char> in_ok(in.size()), out_ok(out.size());
  int x0 = fp.res, y0 = fp.res, x1 = -1, y1 = -1;
  auto grow = [&](const TriangleSpan& s) {
    x0 = std::min(x0, s.x0), y0 = std::min(y0, s.y0), x1 = std::max(x1, s.x1), y1 = std::max(y1, s.y1);
  };
  for (std::size_t k = 0; k < in.size(); ++k)
    if ((in_ok[k] = triangle_span(fp, fp.triangles[k], in[k]))) grow(in[k]);
  for (std::size_t k = 0; k < out.size(); ++k)
    if ((out_ok[k] = triangle_span(fp, fp.boundary[k], out[k]))) grow(out[k]);
  if (x1 < 0) {
    reset_window(fp, 0, 0, 0, 0);
    return;
  }
  reset_window(fp, x0, y0, x1, y1);
  for (std::size_t k = 0; k < in.size(); ++k)
    if (in_ok[k]) rasterise_triangle(fp, fp.triangles[k], in[k], PatchPixel::Inside);
  for (std::size_t k = 0; k < out.size(); ++k)
    if (out_ok[k]) rasterise_triangle(fp, fp.boundary[k], out[k], PatchPixel::Boundary);
  crop_window(fp);
}

}  // namespace

FlattenResult flatten_patches(const Mesh& mesh, const std::vector<int>& seeds,
                              const FlattenOptions& opt) {
  if (opt.resolution < 8 || opt.resolution > 4096)
    throw InvalidInputError("flatten_patches: resolution " + std::to_string(opt.resolution) +
                            " outside 8..4096");
  if (opt.margin < 0 || opt.margin > opt.resolution / 4)
    throw InvalidInputError("flatten_patches: margin " + std::to_string(opt.margin) + " outside 0.." +
                            std::to_string(opt.resolution / 4));
  if (opt.boundary_rings < 0 || opt.boundary_rings > 4)
    throw InvalidInputError("flatten_patches: boundary_rings " + std::to_string(opt.boundary_rings) +
                            " outside 0..4");
  require_triangle_mesh(mesh, "flatten_patches");
  int count = 0;
  read_patches(mesh, count);
  if (static_cast<int>(seeds.size()) != count)
    throw InvalidInputError("flatten_patches: " + std::to_string(seeds.size()) + " seed faces for " +
                            std::to_string(count) + " patches");
  FlattenResult res;
  res.patches.resize(count);
  tbb::parallel_for(0, count, [&](int p) {
    res.patches[p] = flatten_patch_geometry(mesh, p, seeds[p], opt.boundary_rings);
  });
  // Common texel size from the largest patch extent.
  double extent = 0;
  std::vector<Box2> pbox(count);
  for (int p = 0; p < count; ++p) {
    const auto& T = res.patches[p].triangles;
    Box2 b = box_of(T.front().corner);
    for (const FlatTriangle& t : T) {
      const Box2 c = box_of(t.corner);
      b = {std::min(b.x0, c.x0), std::min(b.y0, c.y0), std::max(b.x1, c.x1), std::max(b.y1, c.y1)};
    }
    pbox[p] = b;
    extent = std::max({extent, b.x1 - b.x0, b.y1 - b.y0});
  }
  const int R = opt.resolution;
  // One texel of the side is kept for the grid's shift below (at most half a
  // texel either way), so the margin holds.
  const double texel = extent > 0 ? extent / std::max(1, R - 2 * opt.margin - 1) : 1.0;
  res.texel = texel;
  tbb::parallel_for(0, count, [&](int p) {
    FlatPatch& fp = res.patches[p];
    fp.res = R;
    fp.texel = texel;
    // Pixel centres on one lattice of the texel in world coordinates along
    // e1 and e2: patches whose planes and frames agree (a flat part under a
    // steady field) then share one pixel grid, so a neighbour's pixels are
    // read at their centres, not resampled half a texel off.
    const auto lattice = [&](double centre, const std::array<double, 3>& e) {
      const double w = fp.origin[0] * e[0] + fp.origin[1] * e[1] + fp.origin[2] * e[2];
      return std::round((w + centre) / texel) * texel - w;
    };
    fp.u0 = lattice(0.5 * (pbox[p].x0 + pbox[p].x1) - 0.5 * R * texel, fp.e1);
    fp.v0 = lattice(0.5 * (pbox[p].y0 + pbox[p].y1) + 0.5 * R * texel, fp.e2);
    rasterise_patch(fp);
  });
  for (const FlatPatch& fp : res.patches) {
    res.dropped_boundary += fp.dropped_boundary;
    for (PatchPixel s : fp.pixel) {
      if (s == PatchPixel::Inside) ++res.inside_pixels;
      if (s == PatchPixel::Boundary) ++res.boundary_pixels;
    }
  }
  return res;
}

bool sample_inside(const FlatPatch& fp, const Image& img, double px, double py, float* out) {
  const int C = img.channels;
  const double fx = px - 0.5, fy = py - 0.5;
  const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy));
  const double ax = fx - x0, ay = fy - y0;
  double small[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  std::vector<double> large;  // more than 8 channels: rare
  double* acc = small;
  if (C > 8) large.assign(static_cast<std::size_t>(C), 0.0), acc = large.data();
  double wsum = 0;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const int x = x0 + i, y = y0 + j;
      if (fp.state(x, y) != PatchPixel::Inside) continue;
      const double w = (i ? ax : 1 - ax) * (j ? ay : 1 - ay) + 1e-6;
      for (int c = 0; c < C; ++c) acc[c] += w * img.at(x - fp.bx, y - fp.by, c);
      wsum += w;
    }
  if (wsum <= 0) return false;
  for (int c = 0; c < C; ++c) out[c] = static_cast<float>(acc[c] / wsum);
  return true;
}

}  // namespace surftex
