// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/embed_surface_quilt.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/self_intersections.h"
#include "shell/element_clearance.h"
#include "geometry/timer.h"
#include "geometry/vec3.h"
#include "shell/element_mesh.h"
#include "shell/shell_map.h"
#include "shell/shell_space.h"

namespace surftex {

namespace {
// Where each element's faces lie in mesh_from_elements(els)'s numbering.
struct ElementFaces {
  std::vector<std::size_t> first;  // face index of each element's first triangle; one past the last at the end
  explicit ElementFaces(const std::vector<ElementMesh>& els) : first(els.size() + 1, 0) {
    for (std::size_t e = 0; e < els.size(); ++e) first[e + 1] = first[e] + els[e].tris.size();
  }
  std::size_t element_of(std::uint32_t f) const {
    return static_cast<std::size_t>(std::upper_bound(first.begin(), first.end(), static_cast<std::size_t>(f)) - first.begin()) - 1;
  }
};

// Rebuilds `els` (with `compact` and `out`) after some triangles were found
// bad (bad[e] empty: none in element e): an element without any is kept;
// one with some is removed if compact or `remove`, else cut there (one ring
// more) and its pieces capped, a piece with an edge over max_edge (> 0) left
// out. Returns how many elements were removed or cut. `fresh` (if given)
// becomes, per element after, 1 for a cut piece and 0 for one kept as it was.
std::size_t cut_or_remove(const std::vector<std::vector<char>>& bad, bool remove, double max_edge,
                          std::vector<char>& compact, std::vector<ElementMesh>& els, Mesh& out,
                          std::vector<char>* fresh = nullptr) {
  std::vector<ElementMesh> kept;
  std::vector<char> kept_compact, kept_fresh;
  std::size_t touched = 0;
  for (std::size_t e = 0; e < els.size(); ++e) {
    const bool c = e < compact.size() && compact[e];
    if (bad[e].empty()) {
      kept.push_back(std::move(els[e]));
      kept_compact.push_back(c);
      kept_fresh.push_back(0);
      continue;
    }
    ++touched;
    if (c || remove) continue;
    for (ElementMesh& piece : trim_and_cap(els[e], bad[e], 1, std::max<std::size_t>(24, els[e].tris.size() / 10))) {
      if (max_edge > 0 && longest_edge_length(piece) > max_edge) continue;  // a cap over the shard bound
      kept.push_back(std::move(piece));
      kept_compact.push_back(0);
      kept_fresh.push_back(1);
    }
  }
  els.swap(kept);
  compact.swap(kept_compact);
  if (fresh) fresh->swap(kept_fresh);
  mesh_from_elements(els, out);
  return touched;
}

// EmbedSurfaceQuiltOptions::resolve_crossings: the face pairs of the embedded
// mesh that intersect (exact); of two elements the later yields its faces,
// an element crossing itself both; a compact element with such faces is
// removed, another has them (and one ring) cut out and its pieces capped
// (trim_and_cap; a piece with an edge over max_edge > 0 is left out); with
// `remove`, every element with such faces is removed.
// `out` is rebuilt.
void resolve_embedded_crossings(const std::vector<FacePair>& pairs, std::vector<char>& compact, bool remove,
                                double max_edge, std::vector<ElementMesh>& els, Mesh& out,
                                EmbedSurfaceQuiltResult& res, std::vector<char>& fresh) {
  const ElementFaces ef(els);
  std::vector<std::vector<char>> bad(els.size());
  auto mark = [&](std::size_t e, std::uint32_t f) {
    if (bad[e].empty()) bad[e].assign(els[e].tris.size(), 0);
    bad[e][f - ef.first[e]] = 1;
  };
  for (const FacePair& p : pairs) {
    const std::size_t a = ef.element_of(p[0]), b = ef.element_of(p[1]);
    if (a == b) {
      mark(a, p[0]);
      mark(a, p[1]);
    } else {
      mark(std::max(a, b), a > b ? p[0] : p[1]);
    }
  }
  const std::size_t n = cut_or_remove(bad, remove, max_edge, compact, els, out, &fresh);
  res.crossing_elements += n;
  if (remove) res.crossing_elements_removed_last += n;
}

/// The shell space of Zhou et al. 2006 s.3.1 over the charted base mesh, of
/// absolute height h; its counts into `res`.
ShellSpace build_quilt_shell(const Mesh& atlas_mesh, double h, EmbedSurfaceQuiltResult& res) {
  ShellSpaceOptions so;
  so.height = h;
  so.relative_height = false;
  ShellSpace shell = build_shell_space(atlas_mesh, so);
  res.tets = shell.tets.size();
  res.clamped_vertices = shell.clamped_vertices;
  res.unfolded_vertices = shell.unfolded_vertices;
  res.shell_height = shell.height;
  return shell;
}

/// The atlas's corner UVs per base face (as surface_quilt_to_texture), after
/// checking that every quilt vertex lies on a base face and that the shell
/// has three tets per face. Throws InvalidInputError otherwise.
std::vector<std::array<UV, 3>> face_corner_uvs(const Mesh& atlas_mesh, const SurfaceQuilt& quilt,
                                               const ShellSpace& shell) {
  auto [uv, has_uv] = atlas_mesh.property_map<HalfedgeIndex, UV>(kCornerUV.name);
  if (!has_uv) throw InvalidInputError("embed_surface_quilt: the atlas wrote no kCornerUV");
  const std::size_t nf = atlas_mesh.number_of_faces();
  std::vector<std::array<UV, 3>> face_uv(nf);
  for (FaceIndex f : atlas_mesh.faces()) {
    int k = 0;
    for (HalfedgeIndex hh : atlas_mesh.halfedges_around_face(atlas_mesh.halfedge(f)))
      if (k < 3) face_uv[f.idx()][static_cast<std::size_t>(k++)] = uv[hh];
  }
  for (const SurfaceQuiltVertex& v : quilt.vertices)
    if (v.face < 0 || static_cast<std::size_t>(v.face) >= nf)
      throw InvalidInputError("embed_surface_quilt: quilt vertex on face " + std::to_string(v.face) + " (base has " +
                              std::to_string(nf) + " faces)");
  // Tets 3f .. 3f+2 are the prism of base face f (build_shell_space order).
  if (shell.tets.size() != 3 * nf) throw InvalidInputError("embed_surface_quilt: unexpected shell layout");
  return face_uv;
}

/// Where the quilt's vertices went: world positions, and per vertex whether
/// it fell outside the texture space or had its location clamped (by how much).
struct QuiltVertexMapping {
  std::vector<Vec3> pos;
  std::vector<char> outside, clamped;
  std::vector<double> most_negative;
};

/// The vertex lies on its face: quilt_surface settles locations up to a
/// small negative tolerance, and on a chart-border edge such a (u, v) would
/// fall into the atlas gap beside the chart. Clamps the barycentrics `b` onto
/// the face; returns whether it had to (and the most negative one before).
bool clamp_onto_face(std::array<double, 3>& b, double& most_negative) {
  if (!(std::min({b[0], b[1], b[2]}) < 0)) return false;
  most_negative = std::min({b[0], b[1], b[2]});
  for (double& x : b) x = std::max(0.0, x);
  const double sum = b[0] + b[1] + b[2];
  if (sum > 0)
    for (double& x : b) x /= sum;
  else
    b = {1.0 / 3, 1.0 / 3, 1.0 / 3};
  return true;
}

/// Outside the chart's texture space (w beyond [0,1] after deformation; with
/// w in [0, 1] only if the chart's tets stopped tiling it): the affine map of
/// the vertex's own prism tet (base face `face`) with the largest smallest
/// barycentric coordinate, extrapolated. Local by construction: a global
/// nearest-tet search can pick a tet of another chart (long spikes).
Vec3 extrapolate_from_prism(const ShellSpace& shell, const Vec3& uvw, int face) {
  const Vec3 x{uvw[0], uvw[1], uvw[2] * shell.w_scale};
  double best = -1e300;
  std::array<double, 4> bb{1, 0, 0, 0};
  int bt = 3 * face;
  for (int k = 0; k < 3; ++k) {
    const Tet& tt = shell.tets[static_cast<std::size_t>(3 * face + k)];
    const Vec3 p0 = shell.texture_metric(tt[0]), p1 = shell.texture_metric(tt[1]), p2 = shell.texture_metric(tt[2]),
               p3 = shell.texture_metric(tt[3]);
    const double vol = tet_signed_volume(p0, p1, p2, p3);
    if (!(vol > 0)) continue;
    const std::array<double, 4> w{tet_signed_volume(x, p1, p2, p3) / vol, tet_signed_volume(p0, x, p2, p3) / vol,
                                  tet_signed_volume(p0, p1, x, p3) / vol, tet_signed_volume(p0, p1, p2, x) / vol};
    const double m = std::min({w[0], w[1], w[2], w[3]});
    if (m > best) best = m, bb = w, bt = 3 * face + k;
  }
  const Tet& tt = shell.tets[static_cast<std::size_t>(bt)];
  Vec3 q{0, 0, 0};
  for (int k = 0; k < 4; ++k)
    for (int d = 0; d < 3; ++d) q[static_cast<std::size_t>(d)] += bb[static_cast<std::size_t>(k)] * shell.shell_points[static_cast<std::size_t>(tt[static_cast<std::size_t>(k)])][static_cast<std::size_t>(d)];
  return q;
}

/// Zhou et al. 2006 s.3.2: every quilt vertex through the shell map, from
/// its texture coordinates (u, v from the face's corner UVs, w from its
/// height), in parallel (each vertex on its own).
QuiltVertexMapping map_quilt_vertices(const SurfaceQuilt& quilt, const ShellSpace& shell, const ShellMap& map,
                                      const std::vector<std::array<UV, 3>>& face_uv) {
  const std::size_t nv = quilt.vertices.size();
  const double dz = quilt.z_max - quilt.z_min;
  QuiltVertexMapping vm;
  vm.pos.resize(nv);
  vm.outside.assign(nv, 0);
  vm.clamped.assign(nv, 0);
  vm.most_negative.assign(nv, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t i = rg.begin(); i != rg.end(); ++i) {
      const SurfaceQuiltVertex& v = quilt.vertices[i];
      const auto& c = face_uv[static_cast<std::size_t>(v.face)];
      std::array<double, 3> b{1 - v.b1 - v.b2, v.b1, v.b2};
      if (clamp_onto_face(b, vm.most_negative[i])) vm.clamped[i] = 1;
      const Vec3 uvw{b[0] * c[0][0] + b[1] * c[1][0] + b[2] * c[2][0], b[0] * c[0][1] + b[1] * c[1][1] + b[2] * c[2][1],
                     (v.z - quilt.z_min) / dz};
      // Section 3.2 maps a point through the tet that contains it; where the
      // stretch minimisation moved the offset vertices that tet may belong to
      // a neighbouring prism of the same chart: walk there from the own prism.
      const ShellMap::Location loc = map.locate_texture_from(uvw, 3 * v.face);
      if (loc.inside) {
        vm.pos[i] = map.shell_point(loc);
        continue;
      }
      vm.outside[i] = 1;
      vm.pos[i] = extrapolate_from_prism(shell, uvw, v.face);
    }
  });
  return vm;
}

/// The quilt's elements as meshes of the mapped positions (each element's
/// vertices numbered in order of first use).
std::vector<ElementMesh> quilt_elements(const SurfaceQuilt& quilt, const std::vector<Vec3>& pos,
                                       std::vector<std::vector<int>>& quilt_vertex) {
  std::vector<ElementMesh> els(static_cast<std::size_t>(quilt.elements));
  quilt_vertex.assign(els.size(), {});
  std::vector<int> local(quilt.vertices.size(), -1);
  for (std::size_t f = 0; f < quilt.tris.size(); ++f) {
    ElementMesh& m = els[static_cast<std::size_t>(quilt.tri_element[f])];
    Tri tri;
    for (int k = 0; k < 3; ++k) {
      const int v = quilt.tris[f][static_cast<std::size_t>(k)];
      if (local[static_cast<std::size_t>(v)] < 0) {
        local[static_cast<std::size_t>(v)] = static_cast<int>(m.points.size());
        m.points.push_back(pos[static_cast<std::size_t>(v)]);
        quilt_vertex[static_cast<std::size_t>(quilt.tri_element[f])].push_back(v);
      }
      tri[static_cast<std::size_t>(k)] = local[static_cast<std::size_t>(v)];
    }
    m.tris.push_back(tri);
  }
  return els;
}

/// `m` with its vertices numbered in order of first use by its triangles
/// (quilt_elements' numbering), so that a whole copy's triangles equal it.
ElementMesh in_first_use_order(const ElementMesh& m) {
  std::vector<int> all(m.tris.size());
  for (std::size_t t = 0; t < all.size(); ++t) all[t] = static_cast<int>(t);
  return extract_triangles(m, all);
}

/// The affine map x -> A x + c closest (least squares) to taking each point
/// of `from` to the same point of `to`; false if `from` spans no volume or the
/// map turns space inside out (then nothing is moved).
bool fit_affine(const std::vector<P3>& from, const std::vector<P3>& to, Eigen::Matrix3d& A, Eigen::Vector3d& c) {
  const std::size_t n = from.size();
  if (n < 4 || to.size() != n) return false;
  Eigen::Vector3d mf = Eigen::Vector3d::Zero(), mt = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    mf += Eigen::Vector3d(from[i][0], from[i][1], from[i][2]);
    mt += Eigen::Vector3d(to[i][0], to[i][1], to[i][2]);
  }
  mf /= static_cast<double>(n);
  mt /= static_cast<double>(n);
  Eigen::Matrix3d xx = Eigen::Matrix3d::Zero(), yx = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x = Eigen::Vector3d(from[i][0], from[i][1], from[i][2]) - mf;
    const Eigen::Vector3d y = Eigen::Vector3d(to[i][0], to[i][1], to[i][2]) - mt;
    xx += x * x.transpose();
    yx += y * x.transpose();
  }
  const double tr = xx.trace() / 3;  // flat or degenerate: no volume to fit
  if (!(tr > 0) || !(xx.determinant() > 1e-18 * tr * tr * tr)) return false;
  A = yx * xx.inverse();
  if (!(A.determinant() > 0)) return false;
  c = mt - A * mf;
  return true;
}

/// How far a copy must move along `up` (unit) so that none of its vertices
/// lies under the plane of the base face its quilt vertex was located on.
double lift_out_of_base(const ElementMesh& el, const std::vector<int>& qv, const SurfaceQuilt& quilt,
                        const Mesh& base, const Eigen::Vector3d& up) {
  double lift = 0;
  for (std::size_t i = 0; i < el.points.size(); ++i) {
    const FaceIndex f(static_cast<std::uint32_t>(quilt.vertices[static_cast<std::size_t>(qv[i])].face));
    const HalfedgeIndex h = base.halfedge(f);
    const Point3 a = base.point(base.source(h)), b = base.point(base.target(h)), c = base.point(base.target(base.next(h)));
    const Vector3 nn = CGAL::cross_product(b - a, c - a);
    const double len = std::sqrt(nn.squared_length());
    if (!(len > 0)) continue;
    const Eigen::Vector3d n(nn.x() / len, nn.y() / len, nn.z() / len);
    const double depth = -n.dot(Eigen::Vector3d(el.points[i][0] - a.x(), el.points[i][1] - a.y(), el.points[i][2] - a.z()));
    const double along = n.dot(up);
    if (depth > 0 && along > 0.2) lift = std::max(lift, depth / along);
  }
  return lift;
}

/// Whether the element, as the shell map placed it, crosses itself in more
/// face pairs (exact) than `own`, the swatch element's own crossings.
bool folded(const ElementMesh& el, std::size_t own) {
  return element_self_crossings(el, true).size() > own;  // (in parallel: the copies are checked one by one)
}

/// Zhou et al. 2006 s.3.2 takes every vertex through the shell map, which is
/// piecewise linear: faces of a real swatch that nearly touch (wingnut.obj has
/// pairs 0.0005 of its size apart) or a torus's inner side over a tight bend
/// are folded into each other by its kinks, and the copy is then removed as
/// crossing itself (a third of the nuts on spot.ply, 14 of 177 tori on the
/// bunny). A whole copy of a compact swatch element
/// (EmbedSurfaceQuiltOptions::whole_copy_sources) that the map folded so
/// instead takes the one affine map that fits the shell map best over its
/// vertices, lifted so that it does not dip into the base: it keeps the
/// element's shape (an affine map cannot make faces cross) and sits where the
/// copy was. Copies the map did not fold, threads, and cut or merged pieces
/// bend with the surface. Returns the elements placed so; `whole[e]` = 1 for
/// whole copies, `affine[e]` = 1 for those placed affinely.
std::size_t place_whole_copies_affinely(const std::vector<ElementMesh>& sources, const std::vector<char>& compact,
                                        std::size_t own, const SurfaceQuilt& quilt,
                                        const std::vector<std::vector<int>>& quilt_vertex, const Mesh& base,
                                        std::vector<ElementMesh>& els, std::vector<char>& whole,
                                        std::vector<char>& affine) {
  whole.assign(els.size(), 0);
  affine.assign(els.size(), 0);
  if (sources.empty()) return 0;
  std::vector<ElementMesh> src;
  for (const ElementMesh& m : sources) src.push_back(in_first_use_order(m));
  std::size_t placed = 0;
  for (std::size_t e = 0; e < els.size(); ++e) {
    if (!(e < compact.size() && compact[e])) continue;
    ElementMesh& el = els[e];
    for (const ElementMesh& s : src) {
      if (s.tris.size() != el.tris.size() || s.points.size() != el.points.size() || s.tris != el.tris) continue;
      whole[e] = 1;
      if (!folded(el, own)) break;  // the copy bends with the surface, as in 3.2
      Eigen::Matrix3d A;
      Eigen::Vector3d c;
      if (!fit_affine(s.points, el.points, A, c)) break;
      for (std::size_t i = 0; i < el.points.size(); ++i) {
        const Eigen::Vector3d y = A * Eigen::Vector3d(s.points[i][0], s.points[i][1], s.points[i][2]) + c;
        el.points[i] = P3{y[0], y[1], y[2]};
      }
      const Eigen::Vector3d up = (A * Eigen::Vector3d(0, 0, 1)).normalized();
      const double lift = lift_out_of_base(el, quilt_vertex[e], quilt, base, up);
      for (P3& p : el.points)
        for (int d = 0; d < 3; ++d) p[static_cast<std::size_t>(d)] += lift * up[d];
      affine[e] = 1;
      ++placed;
      break;
    }
  }
  return placed;
}

/// Counts the clamped locations and the vertices mapped outside the texture
/// space (below, above, or beside it in u, v).
void count_mapping(const SurfaceQuilt& quilt, const QuiltVertexMapping& vm, EmbedSurfaceQuiltResult& res) {
  const std::size_t nv = quilt.vertices.size();
  const double dz = quilt.z_max - quilt.z_min;
  res.embed.vertices = nv;
  for (std::size_t i = 0; i < nv; ++i)
    if (vm.clamped[i]) ++res.locations_clamped, res.most_negative_barycentric = std::min(res.most_negative_barycentric, vm.most_negative[i]);
  for (std::size_t i = 0; i < nv; ++i) {
    if (!vm.outside[i]) continue;
    ++res.embed.outside;
    const double w = (quilt.vertices[i].z - quilt.z_min) / dz;
    if (w < 0)
      ++res.outside_below;
    else if (w > 1)
      ++res.outside_above;
    else
      ++res.outside_uv;
  }
}

/// An element's edges over `bound` shortened by moving their ends, not cut
/// (issue 17 item 1's "moved by the deformation"): position-based relaxation,
/// every edge held to its own length but those over the bound to 0.95 of it,
/// so the excess spreads to their shorter neighbours (a thread gives along its
/// length). Returns true, with `m` relaxed, when no edge is over the bound
/// after `iterations` sweeps; false (m unchanged) otherwise. The crossings are
/// checked after this, exactly, as for every embedded element.
bool relax_stretched_edges(ElementMesh& m, double bound, int iterations) {
  std::vector<std::array<int, 2>> edges;  // each undirected edge once (an open element's border too)
  for (const Tri& t : m.tris)
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  auto length = [](const P3& a, const P3& b) { return vec3::norm(vec3::sub(a, b)); };
  std::vector<double> rest(edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i)
    rest[i] = std::min(length(m.points[edges[i][0]], m.points[edges[i][1]]), 0.95 * bound);
  std::vector<P3> p = m.points;
  for (int it = 0; it < iterations; ++it) {
    double longest = 0;
    for (std::size_t i = 0; i < edges.size(); ++i) {
      P3 &a = p[edges[i][0]], &b = p[edges[i][1]];
      const double l = length(a, b);
      longest = std::max(longest, l);
      if (!(l > 0)) continue;
      const double f = 0.5 * (l - rest[i]) / l;
      for (int c = 0; c < 3; ++c) {
        const double d = f * (b[c] - a[c]);
        a[c] += d, b[c] -= d;
      }
    }
    if (longest <= bound) break;
  }
  for (const auto& e : edges)
    if (length(p[e[0]], p[e[1]]) > bound) return false;
  m.points.swap(p);
  return true;
}

/// The shard bound held on the embedded elements (embedded_edge_bound): an
/// element with a longer edge is relaxed within it when `relax` can
/// (relax_stretched_edges); otherwise its triangles with a longer edge are
/// cut out of threads (with one ring, the pieces capped; a piece whose cap is
/// over the bound too is left out) and compact elements with one are removed.
/// `compact` follows `els`; `out` is rebuilt if anything changed.
void remove_embedded_shards(double max_edge, bool relax, std::vector<char>& compact, std::vector<ElementMesh>& els,
                            Mesh& out, EmbedSurfaceQuiltResult& res) {
  if (!(max_edge > 0)) return;
  const double lim2 = max_edge * max_edge;
  std::vector<std::vector<char>> bad(els.size());  // per element: its triangles with a longer edge (empty: none)
  bool changed = false;
  for (std::size_t e = 0; e < els.size(); ++e) {
    if (longest_edge_length(els[e]) <= max_edge) continue;
    if (relax && relax_stretched_edges(els[e], max_edge, 50)) {
      ++res.elements_relaxed_embedded;
      changed = true;
      continue;
    }
    const ElementMesh& m = els[e];
    for (std::size_t t = 0; t < m.tris.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const P3 &a = m.points[static_cast<std::size_t>(m.tris[t][k])], &b = m.points[static_cast<std::size_t>(m.tris[t][(k + 1) % 3])];
        if ((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]) <= lim2) continue;
        if (bad[e].empty()) bad[e].assign(m.tris.size(), 0);
        bad[e][t] = 1;
        changed = true;
        break;
      }
  }
  if (!changed) return;
  res.elements_stretched_embedded += cut_or_remove(bad, false, max_edge, compact, els, out);
}

/// The shard bound on the embedded elements (EmbedSurfaceQuiltOptions::
/// max_edge, max_edge_over_median, min_edge_bound); `median` gets their
/// median edge when that is used.
double embedded_edge_bound(const EmbedSurfaceQuiltOptions& opt, const std::vector<ElementMesh>& els, double& median) {
  if (!(opt.max_edge > 0 && opt.max_edge_over_median > 0)) return opt.max_edge;
  median = median_edge_length(els);
  const double b = std::max(opt.max_edge_over_median * median, opt.min_edge_bound);
  return b > 0 ? std::min(opt.max_edge, b) : opt.max_edge;
}

/// The pairs to resolve: those between two elements, and those within an
/// element that has more than `own` of them (at most `own` are the swatch
/// element's own crossings, which the copy keeps); `kept` = elements keeping theirs.
std::vector<FacePair> pairs_to_resolve(const std::vector<FacePair>& pairs, const Mesh& out, std::size_t own,
                                       std::size_t& kept) {
  kept = 0;
  if (own == 0) return pairs;
  auto el = out.property_map<FaceIndex, int>(kFaceElement.name).first;
  std::map<int, std::size_t> within;
  for (const FacePair& fp : pairs)
    if (el[FaceIndex(fp[0])] == el[FaceIndex(fp[1])]) ++within[el[FaceIndex(fp[0])]];
  std::vector<FacePair> act;
  for (const FacePair& fp : pairs) {
    const int a = el[FaceIndex(fp[0])];
    if (a != el[FaceIndex(fp[1])] || within[a] > own) act.push_back(fp);
  }
  for (const auto& [e, n] : within) kept += n <= own ? 1 : 0;
  return act;
}

/// EmbedSurfaceQuiltOptions::untangle_folds on the pairs of the first check:
/// each element other than a compact one with more pairs within it than
/// `own` smoothed where it crosses (smooth_out_crossings; side by side, each
/// element on its own); `out` rebuilt and `pairs` brought up to date (those
/// of unchanged elements kept, the rest checked again near the smoothed
/// ones). Returns how many were smoothed out.
std::size_t untangle_folded_elements(std::vector<FacePair>& pairs, std::size_t own, const std::vector<char>& compact,
                                     std::vector<ElementMesh>& els, Mesh& out) {
  const ElementFaces ef(els);
  std::map<std::size_t, std::vector<FacePair>> within;
  for (const FacePair& fp : pairs)
    if (const std::size_t a = ef.element_of(fp[0]); a == ef.element_of(fp[1])) within[a].push_back(fp);
  std::vector<std::size_t> todo;
  for (const auto& [e, ps] : within)
    if (ps.size() > own && !(e < compact.size() && compact[e])) todo.push_back(e);
  std::vector<char> smoothed(els.size(), 0);
  tbb::parallel_for(std::size_t{0}, todo.size(), [&](std::size_t i) {
    const std::size_t e = todo[i];
    std::vector<char> faces(els[e].tris.size(), 0);
    for (const FacePair& fp : within.at(e)) faces[fp[0] - ef.first[e]] = faces[fp[1] - ef.first[e]] = 1;
    smoothed[e] = smooth_out_crossings(els[e], faces, own) ? 1 : 0;
  });
  const std::size_t n = static_cast<std::size_t>(std::count(smoothed.begin(), smoothed.end(), 1));
  if (n == 0) return 0;
  mesh_from_elements(els, out);  // (same faces in the same order: only points moved)
  std::vector<FacePair> now;
  for (const FacePair& fp : pairs)
    if (!smoothed[ef.element_of(fp[0])] && !smoothed[ef.element_of(fp[1])]) now.push_back(fp);
  for (const FacePair& fp : self_intersecting_faces(out, faces_near_changed_elements(els, smoothed))) now.push_back(fp);
  std::sort(now.begin(), now.end());
  now.erase(std::unique(now.begin(), now.end()), now.end());
  pairs.swap(now);
  return n;
}

/// Resolution rounds when asked (a cut piece's cap may meet another element),
/// each reusing the exact check that the count reports; what still crosses
/// after opt.crossing_trim_rounds is removed whole (removing adds no crossing, so none is
/// left); then the self-intersecting face pairs counted, within and between
/// elements. Cut pieces with an edge over `max_edge` (> 0) are left out;
/// `untangle`: folded threads smoothed out first (untangle_folded_elements).
void resolve_and_count_crossings(std::vector<char>& compact, const EmbedSurfaceQuiltOptions& opt, double max_edge,
                                 bool untangle, std::vector<ElementMesh>& els, Mesh& out, EmbedSurfaceQuiltResult& res) {
  std::vector<FacePair> pairs;
  bool checked = false, checked_whole = false;
  // After a resolution round: its cut pieces. Every pair of the round's check
  // changed an element it met, so two elements kept as they were cannot cross
  // (nor one itself): the next check needs only the pieces and what they may
  // touch (faces_near_changed_elements), and finds every pair a whole one would.
  std::vector<char> fresh;
  if (opt.resolve_crossings) {
    const int trim_rounds = opt.crossing_trim_rounds;
    for (int round = 0; round <= trim_rounds; ++round) {
      pairs = round == 0 ? self_intersecting_faces(out)
                         : self_intersecting_faces(out, faces_near_changed_elements(els, fresh));
      if (round == 0 && untangle)
        res.elements_untangled += untangle_folded_elements(pairs, opt.swatch_self_crossings, compact, els, out);
      checked = true;
      checked_whole = round == 0;
      const std::vector<FacePair> act =
          pairs_to_resolve(pairs, out, opt.swatch_self_crossings, res.elements_self_crossing_kept);
      if (act.empty()) break;
      resolve_embedded_crossings(act, compact, round == trim_rounds, max_edge, els, out, res, fresh);
      checked = false;
    }
  }
  if (opt.check_self_intersections) {
    // After the last round (which removes, so nothing is fresh), or with no
    // resolution. Elements keeping their own crossings are not fresh but
    // cross: with them, the count is of the whole mesh.
    const bool own = opt.swatch_self_crossings > 0;
    if (!checked || (own && !checked_whole)) {
      pairs = fresh.empty() || own ? self_intersecting_faces(out)
                                   : self_intersecting_faces(out, faces_near_changed_elements(els, fresh));
      pairs_to_resolve(pairs, out, opt.swatch_self_crossings, res.elements_self_crossing_kept);
    }
    auto el = out.property_map<FaceIndex, int>(kFaceElement.name).first;
    for (const FacePair& fp : pairs) {
      if (el[FaceIndex(fp[0])] == el[FaceIndex(fp[1])])
        ++res.self_intersections_within;
      else
        ++res.self_intersections_between;
    }
    res.embed.self_intersecting_pairs = pairs.size();
    res.embed.checked = true;
  }
}
// The shard bound, then the crossings; as removing elements moves the
// median, again on the final elements while one is over its bound (three
// passes at most). The crossings' cut pieces are held to the bound too; the
// untangling's smoothing may stretch, so it runs in the first pass only.
void hold_shard_bound(const EmbedSurfaceQuiltOptions& opt, bool untangle, std::vector<char>& compact,
                      std::vector<ElementMesh>& els, Mesh& out, EmbedSurfaceQuiltResult& res) {
  for (int pass = 0; pass < 3; ++pass) {
    res.embedded_edge_bound = embedded_edge_bound(opt, els, res.embedded_median_edge);
    if (pass > 0 && longest_edge_length(els) <= res.embedded_edge_bound) break;
    remove_embedded_shards(res.embedded_edge_bound, opt.relax_stretched, compact, els, out, res);
    res.self_intersections_within = res.self_intersections_between = 0;
    resolve_and_count_crossings(compact, opt, res.embedded_edge_bound, untangle && pass == 0, els, out, res);
    if (!(opt.max_edge > 0 && opt.max_edge_over_median > 0)) break;
  }
}

// EmbedSurfaceQuiltOptions::fill: pieces into the bare faces; the crossings
// that involve them (none by construction, but the count stays exact) added
// to the counts.
void fill_and_count(const Mesh& base, const EmbedSurfaceQuiltOptions& opt, std::vector<char>& compact,
                    std::vector<ElementMesh>& els, Mesh& out, EmbedSurfaceQuiltResult& res) {
  EmbeddedFillOptions fo = opt.fill;
  const double b = res.embedded_edge_bound;
  if (b > 0) fo.max_edge = fo.max_edge > 0 ? std::min(fo.max_edge, b) : b;
  const std::size_t before = els.size();
  res.fill = fill_embedded_bare(element_mesh_from(base), els, fo);
  if (res.fill.placed == 0) return;
  compact.resize(els.size(), 0);
  mesh_from_elements(els, out);
  if (!opt.check_self_intersections) return;
  std::vector<char> fresh(els.size(), 0);
  std::fill(fresh.begin() + static_cast<std::ptrdiff_t>(before), fresh.end(), 1);
  const ElementFaces ef(els);
  for (const FacePair& fp : self_intersecting_faces(out, faces_near_changed_elements(els, fresh))) {
    const std::size_t a = ef.element_of(fp[0]), c = ef.element_of(fp[1]);
    if (a < before && c < before) continue;  // counted before the fill
    ++res.embed.self_intersecting_pairs;
    ++(a == c ? res.self_intersections_within : res.self_intersections_between);
  }
}
}  // namespace

/// Zhou et al. 2006 s.3: the base mesh charted, its shell space built and
/// its shell map's stretch minimised; the quilt's vertices mapped through
/// it, its elements assembled, their crossings resolved and counted.
EmbedSurfaceQuiltResult embed_surface_quilt(const Mesh& base, const SurfaceQuilt& quilt, Mesh& out,
                                            const EmbedSurfaceQuiltOptions& opt) {
  if (!(opt.shell_height > 0) || !std::isfinite(opt.shell_height))
    throw InvalidInputError("embed_surface_quilt: shell_height must be > 0 (" + std::to_string(opt.shell_height) + ")");
  if (!(opt.max_edge >= 0) || !std::isfinite(opt.max_edge))
    throw InvalidInputError("embed_surface_quilt: max_edge must be >= 0 (" + std::to_string(opt.max_edge) + ")");
  if (!(opt.min_edge_bound >= 0) || !std::isfinite(opt.min_edge_bound))
    throw InvalidInputError("embed_surface_quilt: min_edge_bound must be >= 0 (" + std::to_string(opt.min_edge_bound) + ")");
  if (!(opt.max_edge_over_median >= 0) || !std::isfinite(opt.max_edge_over_median))
    throw InvalidInputError("embed_surface_quilt: max_edge_over_median must be >= 0 (" +
                            std::to_string(opt.max_edge_over_median) + ")");
  if (opt.crossing_trim_rounds < 0 || opt.crossing_trim_rounds > 8)
    throw InvalidInputError("embed_surface_quilt: crossing_trim_rounds must be in 0..8 (" +
                            std::to_string(opt.crossing_trim_rounds) + ")");
  const double h = opt.shell_height * (quilt.z_max - quilt.z_min) * quilt.scale;
  if (!(h > 0)) throw InvalidInputError("embed_surface_quilt: the quilt has zero height or scale");
  EmbedSurfaceQuiltResult res;
  Timer t;
  Mesh atlas_mesh = base;
  report_progress(opt.progress, "atlas", 0.0);
  res.atlas = compute_base_mesh_atlas(atlas_mesh, opt.atlas);
  res.seconds_atlas = t.seconds();
  t.reset();
  report_progress(opt.progress, "shell", 0.0);
  ShellSpace shell = build_quilt_shell(atlas_mesh, h, res);
  res.seconds_shell = t.seconds();
  t.reset();
  report_progress(opt.progress, "stretch", 0.0);
  res.stretch = shell_map_minimize_stretch(shell, opt.stretch);
  res.seconds_stretch = t.seconds();
  t.reset();
  report_progress(opt.progress, "embed", 0.0);
  const ShellMap map(shell);
  res.seconds_map = t.seconds();
  t.reset();
  const std::vector<std::array<UV, 3>> face_uv = face_corner_uvs(atlas_mesh, quilt, shell);
  const QuiltVertexMapping vm = map_quilt_vertices(quilt, shell, map, face_uv);
  // Elements as meshes (kFaceElement = element id).
  std::vector<std::vector<int>> quilt_vertex;
  std::vector<ElementMesh> els = quilt_elements(quilt, vm.pos, quilt_vertex);
  std::vector<char> whole, affine;
  res.elements_placed_affine =
      place_whole_copies_affinely(opt.whole_copy_sources, quilt.element_compact, opt.swatch_self_crossings, quilt,
                                  quilt_vertex, atlas_mesh, els, whole, affine);
  if (opt.recentre_caps)  // a whole copy has no cap of ours to recentre
    for (std::size_t e = 0; e < els.size(); ++e) res.caps_recentred += whole[e] ? 0 : recentre_fans(els[e]);
  mesh_from_elements(els, out);
  if (opt.measure_outside_shell) {  // the shell map's images; apart, where the affine copies went
    res.outside_shell = measure_outside_shell(vm.pos, shell, map, opt.outside_shell);
    std::vector<Vec3> placed;
    for (std::size_t e = 0; e < els.size(); ++e)
      if (affine[e]) placed.insert(placed.end(), els[e].points.begin(), els[e].points.end());
    if (!placed.empty()) res.affine_outside_shell = measure_outside_shell(placed, shell, map, opt.outside_shell);
    res.outside_shell_measured = true;
  }
  count_mapping(quilt, vm, res);
  std::vector<char> compact = quilt.element_compact;
  hold_shard_bound(opt, opt.untangle_folds, compact, els, out, res);
  if (!opt.fill.templates.empty()) {
    fill_and_count(base, opt, compact, els, out, res);
    // Smaller copies (shorter edges) lower the median edge: where an element
    // is now over the bound, it is held again (decision 102, session 46).
    double median = 0;
    if (res.fill.placed_smaller > 0 && longest_edge_length(els) > embedded_edge_bound(opt, els, median))
      hold_shard_bound(opt, false, compact, els, out, res);
  }
  res.elements = els.size();
  res.seconds_embed = t.seconds();
  report_progress(opt.progress, "embed", 1.0);
  return res;
}

}  // namespace surftex
