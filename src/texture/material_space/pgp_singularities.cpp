// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/pgp_singularities.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

namespace {

using StmMap = PropertyMap<HalfedgeIndex, STM>;

/// Whether face f's texture-space gradient (of the linear interpolant of its
/// corners' (s,t)) departs from the field's target pair, in any of its N
/// rotations, by more than distortion_threshold times its length (squared);
/// a face of zero area always does.
bool face_distorted(const Mesh& mesh, FaceIndex f, const StmMap& stm, const std::array<std::array<double, 3>, 2>& g,
                    const PgpSingularityOptions& opt) {
  const HalfedgeIndex h0 = mesh.halfedge(f);
  const HalfedgeIndex hs[3] = {h0, mesh.next(h0), mesh.next(mesh.next(h0))};
  // Gradient of the linear interpolant: sum_c x_c (n x e_c) / (2A), e_c the
  // edge opposite corner c (counter-clockwise).
  const Vector3 n = robust_face_normal(mesh, f);
  const double A2 = 2 * face_area(mesh, f);
  if (!(A2 > 0)) return true;
  Vector3 gs(0, 0, 0), gt(0, 0, 0);
  for (int c = 0; c < 3; ++c) {
    const Vector3 e = mesh.point(mesh.target(hs[(c + 2) % 3])) - mesh.point(mesh.target(hs[(c + 1) % 3]));
    const Vector3 r = CGAL::cross_product(n, e) / A2;
    gs = gs + stm[hs[c]][0] * r;
    gt = gt + stm[hs[c]][1] * r;
  }
  const Vector3 es(g[0][0], g[0][1], g[0][2]), et(g[1][0], g[1][1], g[1][2]);
  // The target is the cross of the N-symmetric field: (g_s, g_t) rotated by
  // any multiple of 2 pi / N in the face (the PGP matches representatives
  // across edges, so a region may follow another representative than the
  // face's stored one; the texture then still follows the field).
  double best_s = std::numeric_limits<double>::infinity(), best_t = best_s;
  const int N = opt.pgp.symmetry;
  for (int r = 0; r < N; ++r) {
    // rotation by r * 2pi/N of the pair (g_s, g_t) (g_t = n x g_s, same length).
    const int q = r * (4 / N);  // quarter turns
    const Vector3 rs = q == 0 ? es : q == 1 ? et : q == 2 ? -es : -et;
    const Vector3 rt = q == 0 ? et : q == 1 ? -es : q == 2 ? -et : es;
    const double ds = (gs - rs).squared_length(), dt = (gt - rt).squared_length();
    if (std::max(ds, dt) < std::max(best_s, best_t)) {
      best_s = ds;
      best_t = dt;
    }
  }
  return best_s > opt.distortion_threshold * es.squared_length() ||
         best_t > opt.distortion_threshold * et.squared_length() || !std::isfinite(best_s + best_t);
}

/// The corners' (s,t,m) per face, and the distorted faces (face_distorted).
void mark_distorted_faces(const Mesh& mesh, const StmMap& stm, const PgpTarget& target,
                          const PgpSingularityOptions& opt, PgpSingularities& out) {
  for (FaceIndex f : mesh.faces()) {
    const HalfedgeIndex h0 = mesh.halfedge(f);
    const HalfedgeIndex hs[3] = {h0, mesh.next(h0), mesh.next(mesh.next(h0))};
    for (int c = 0; c < 3; ++c) out.corners[f.idx()][c] = stm[hs[c]];
    if (face_distorted(mesh, f, stm, target.gradients[f.idx()], opt)) out.distorted_face[f.idx()] = 1;
  }
}

/// Interior edges whose two faces disagree on the increase of (s,t) along
/// them. The two faces' (s,t) may be expressed in representatives of the
/// cross that differ by quarter turns (a cut of the combed field, where the
/// coupled PGP turns (s,t) -> (t,-s)): the edge matches if the increase
/// along it agrees up to such a turn (a multiple of 4 / N turns).
void mark_mismatched_edges(const Mesh& mesh, const StmMap& stm, const PgpSingularityOptions& opt,
                           PgpSingularities& out) {
  for (EdgeIndex e : mesh.edges()) {
    if (mesh.is_border(e)) continue;
    const HalfedgeIndex h = mesh.halfedge(e, 0), o = mesh.opposite(h);
    // Corner of face(h) at target(h) and at source(h) = target(prev(h)).
    const double d1[2] = {stm[h][0] - stm[mesh.prev(h)][0], stm[h][1] - stm[mesh.prev(h)][1]};
    double d2[2] = {stm[mesh.prev(o)][0] - stm[o][0], stm[mesh.prev(o)][1] - stm[o][1]};
    bool match = false;
    const int turns = 4 / opt.pgp.symmetry;
    for (int r = 0; r < 4; ++r) {
      if (r % turns == 0 && std::abs(d1[0] - d2[0]) <= opt.mismatch_tolerance &&
          std::abs(d1[1] - d2[1]) <= opt.mismatch_tolerance)
        match = true;
      const double s = d2[0];
      d2[0] = d2[1];
      d2[1] = -s;
    }
    if (!match) out.mismatched_edge[e.idx()] = 1;
  }
}

/// A vertex is singular when one of its spokes is mismatched or one of its
/// faces distorted (the rim edges of the ring do not touch v's chart).
void mark_singular_vertices(const Mesh& mesh, PgpSingularities& out) {
  for (VertexIndex v : mesh.vertices()) {
    if (mesh.halfedge(v) == Mesh::null_halfedge()) continue;
    bool sing = false;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(mesh.halfedge(v), mesh)) {
      if (out.mismatched_edge[mesh.edge(h).idx()]) sing = true;
      if (!mesh.is_border(h) && out.distorted_face[mesh.face(h).idx()]) sing = true;
    }
    out.singular_vertex[v.idx()] = sing;
  }
}

/// Per face and corner k, the chart of corner k's vertex: the face's own
/// (s,t,m) at a regular vertex; at a singular one, the vertex's origin (its
/// corner in the face of its first non-border halfedge) plus the field's
/// alphas along the face's edges from it. Faces with a singular corner are
/// singular (rendered per chart, Ray et al. 2009 s.2.3).
void build_charts(const Mesh& mesh, const StmMap& stm, const std::vector<std::array<double, 2>>& alpha,
                  PgpSingularities& out) {
  for (FaceIndex f : mesh.faces()) {
    const HalfedgeIndex h0 = mesh.halfedge(f);
    const HalfedgeIndex hs[3] = {h0, mesh.next(h0), mesh.next(mesh.next(h0))};
    bool any = false;
    for (int k = 0; k < 3; ++k) {
      const VertexIndex vi = mesh.target(hs[k]);
      if (!out.singular_vertex[vi.idx()]) {
        for (int l = 0; l < 3; ++l) out.charts[f.idx()][k][l] = stm[hs[l]];
        continue;
      }
      any = true;
      // The chart's origin: vi's corner in the face of its first non-border halfedge.
      HalfedgeIndex hv = mesh.halfedge(vi);
      if (mesh.is_border(hv)) hv = mesh.opposite(mesh.next(hv));  // still targets vi
      const STM origin = stm[hv];
      for (int l = 0; l < 3; ++l) {
        if (l == k) {
          out.charts[f.idx()][k][l] = origin;
          continue;
        }
        // Halfedge vi -> vl: in face f, from corner k to corner l.
        const HalfedgeIndex he = (l == (k + 1) % 3) ? hs[l] : hs[k];
        const double sgn = (l == (k + 1) % 3) ? 1.0 : -1.0;
        // alpha along vi -> vl.
        const auto& a = alpha[he.idx()];
        out.charts[f.idx()][k][l] = {origin[0] + sgn * a[0], origin[1] + sgn * a[1], stm[hs[l]][2]};
      }
    }
    out.singular_face[f.idx()] = any;
    out.singular_faces += any;
  }
}

}  // namespace

/// Singularities of a PGP solution (Ray et al. 2009 s.2.3): distorted faces,
/// mismatched edges, the singular vertices they touch, and per-corner charts
/// for the faces around them.
PgpSingularities detect_pgp_singularities(const Mesh& mesh, const PgpSingularityOptions& opt) {
  if (!(opt.distortion_threshold > 0))
    throw InvalidInputError("detect_pgp_singularities: distortion_threshold must be > 0, got " +
                            std::to_string(opt.distortion_threshold));
  if (!(opt.mismatch_tolerance >= 0))
    throw InvalidInputError("detect_pgp_singularities: mismatch_tolerance must be >= 0");
  auto found = find(mesh, opt.pgp.stm_map);
  if (!found.second)
    throw InvalidInputError("detect_pgp_singularities: corner map '" + std::string(opt.pgp.stm_map.name) + "' absent");
  const StmMap& stm = found.first;
  const PgpTarget target = pgp_target(mesh, opt.pgp);

  PgpSingularities out;
  out.distorted_face.assign(mesh.num_faces(), 0);
  out.mismatched_edge.assign(mesh.num_edges(), 0);
  out.singular_vertex.assign(mesh.num_vertices(), 0);
  out.singular_face.assign(mesh.num_faces(), 0);
  out.charts.assign(mesh.num_faces(), FaceCharts{});
  out.corners.assign(mesh.num_faces(), {});
  mark_distorted_faces(mesh, stm, target, opt, out);
  mark_mismatched_edges(mesh, stm, opt, out);
  mark_singular_vertices(mesh, out);
  build_charts(mesh, stm, target.alphas, out);
  out.singular_fraction =
      mesh.number_of_faces() ? double(out.singular_faces) / mesh.number_of_faces() : 0.0;
  return out;
}

}  // namespace surftex
