// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/embed_surface_quilt.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/self_intersections.h"
#include "shell/element_clearance.h"
#include "geometry/timer.h"
#include "shell/element_mesh.h"
#include "shell/shell_map.h"
#include "shell/shell_space.h"

namespace surftex {

namespace {
// EmbedSurfaceQuiltOptions::resolve_crossings: the face pairs of the embedded
// mesh that intersect (exact); of two elements the later yields its faces,
// an element crossing itself both; a compact element with such faces is
// removed, another has them (and one ring) cut out and its pieces capped
// (trim_and_cap). `out` is rebuilt.
void resolve_embedded_crossings(const std::vector<FacePair>& pairs, std::vector<char>& compact,
                                std::vector<ElementMesh>& els, Mesh& out, EmbedSurfaceQuiltResult& res) {
  std::vector<std::size_t> first(els.size() + 1, 0);  // face index of each element's first triangle
  for (std::size_t e = 0; e < els.size(); ++e) first[e + 1] = first[e] + els[e].tris.size();
  auto element_of = [&](std::uint32_t f) {
    return static_cast<std::size_t>(std::upper_bound(first.begin(), first.end(), static_cast<std::size_t>(f)) - first.begin()) - 1;
  };
  std::vector<std::vector<char>> bad(els.size());
  auto mark = [&](std::size_t e, std::uint32_t f) {
    if (bad[e].empty()) bad[e].assign(els[e].tris.size(), 0);
    bad[e][f - first[e]] = 1;
  };
  for (const FacePair& p : pairs) {
    const std::size_t a = element_of(p[0]), b = element_of(p[1]);
    if (a == b) {
      mark(a, p[0]);
      mark(a, p[1]);
    } else {
      mark(std::max(a, b), a > b ? p[0] : p[1]);
    }
  }
  std::vector<ElementMesh> kept;
  std::vector<char> kept_compact;
  for (std::size_t e = 0; e < els.size(); ++e) {
    const bool c = e < compact.size() && compact[e];
    if (bad[e].empty()) {
      kept.push_back(std::move(els[e]));
      kept_compact.push_back(c);
      continue;
    }
    ++res.crossing_elements;
    if (c) continue;
    for (ElementMesh& piece : trim_and_cap(els[e], bad[e], 1, std::max<std::size_t>(24, els[e].tris.size() / 10))) {
      kept.push_back(std::move(piece));
      kept_compact.push_back(0);
    }
  }
  els.swap(kept);
  compact.swap(kept_compact);
  mesh_from_elements(els, out);
}
}  // namespace

EmbedSurfaceQuiltResult embed_surface_quilt(const Mesh& base, const SurfaceQuilt& quilt, Mesh& out,
                                            const EmbedSurfaceQuiltOptions& opt) {
  if (!(opt.shell_height > 0) || !std::isfinite(opt.shell_height))
    throw InvalidInputError("embed_surface_quilt: shell_height must be > 0 (" + std::to_string(opt.shell_height) + ")");
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
  ShellSpaceOptions so;
  so.height = h;
  so.relative_height = false;
  ShellSpace shell = build_shell_space(atlas_mesh, so);
  res.tets = shell.tets.size();
  res.clamped_vertices = shell.clamped_vertices;
  res.shell_height = shell.height;
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
  // Texture coordinates (u, v, w) of every quilt vertex (as surface_quilt_to_texture).
  auto [uv, has_uv] = atlas_mesh.property_map<HalfedgeIndex, UV>(kCornerUV.name);
  if (!has_uv) throw InvalidInputError("embed_surface_quilt: the atlas wrote no kCornerUV");
  const std::size_t nf = atlas_mesh.number_of_faces(), nv = quilt.vertices.size();
  const double dz = quilt.z_max - quilt.z_min;
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
  std::vector<Vec3> pos(nv);
  std::vector<char> outside(nv, 0), clamped(nv, 0);
  std::vector<double> most_negative(nv, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t i = rg.begin(); i != rg.end(); ++i) {
      const SurfaceQuiltVertex& v = quilt.vertices[i];
      const auto& c = face_uv[static_cast<std::size_t>(v.face)];
      // The vertex lies on its face: quilt_surface settles locations up to a
      // small negative tolerance, and on a chart-border edge such a (u, v)
      // would fall into the atlas gap beside the chart. Clamp onto the face.
      std::array<double, 3> b{1 - v.b1 - v.b2, v.b1, v.b2};
      if (std::min({b[0], b[1], b[2]}) < 0) {
        clamped[i] = 1;
        most_negative[i] = std::min({b[0], b[1], b[2]});
        for (double& x : b) x = std::max(0.0, x);
        const double sum = b[0] + b[1] + b[2];
        if (sum > 0)
          for (double& x : b) x /= sum;
        else
          b = {1.0 / 3, 1.0 / 3, 1.0 / 3};
      }
      const Vec3 uvw{b[0] * c[0][0] + b[1] * c[1][0] + b[2] * c[2][0], b[0] * c[0][1] + b[1] * c[1][1] + b[2] * c[2][1],
                     (v.z - quilt.z_min) / dz};
      // Section 3.2 maps a point through the tet that contains it; where the
      // stretch minimisation moved the offset vertices that tet may belong to
      // a neighbouring prism of the same chart: walk there from the own prism.
      const ShellMap::Location loc = map.locate_texture_from(uvw, 3 * v.face);
      if (loc.inside) {
        pos[i] = map.shell_point(loc);
        continue;
      }
      // Outside the chart's texture space (w beyond [0,1] after deformation;
      // with w in [0, 1] only if the chart's tets stopped tiling it): the
      // affine map of the vertex's own prism tet with the largest smallest
      // barycentric coordinate, extrapolated. Local by construction: a global
      // nearest-tet search can pick a tet of another chart (long spikes).
      outside[i] = 1;
      const Vec3 x{uvw[0], uvw[1], uvw[2] * shell.w_scale};
      double best = -1e300;
      std::array<double, 4> bb{1, 0, 0, 0};
      int bt = 3 * v.face;
      for (int k = 0; k < 3; ++k) {
        const Tet& tt = shell.tets[static_cast<std::size_t>(3 * v.face + k)];
        const Vec3 p0 = shell.texture_metric(tt[0]), p1 = shell.texture_metric(tt[1]), p2 = shell.texture_metric(tt[2]),
                   p3 = shell.texture_metric(tt[3]);
        const double vol = tet_signed_volume(p0, p1, p2, p3);
        if (!(vol > 0)) continue;
        const std::array<double, 4> w{tet_signed_volume(x, p1, p2, p3) / vol, tet_signed_volume(p0, x, p2, p3) / vol,
                                      tet_signed_volume(p0, p1, x, p3) / vol, tet_signed_volume(p0, p1, p2, x) / vol};
        const double m = std::min({w[0], w[1], w[2], w[3]});
        if (m > best) best = m, bb = w, bt = 3 * v.face + k;
      }
      const Tet& tt = shell.tets[static_cast<std::size_t>(bt)];
      Vec3 q{0, 0, 0};
      for (int k = 0; k < 4; ++k)
        for (int d = 0; d < 3; ++d) q[static_cast<std::size_t>(d)] += bb[static_cast<std::size_t>(k)] * shell.shell_points[static_cast<std::size_t>(tt[static_cast<std::size_t>(k)])][static_cast<std::size_t>(d)];
      pos[i] = q;
    }
  });
  // Elements as meshes (kFaceElement = element id).
  std::vector<ElementMesh> els(static_cast<std::size_t>(quilt.elements));
  std::vector<int> local(nv, -1);
  for (std::size_t f = 0; f < quilt.tris.size(); ++f) {
    ElementMesh& m = els[static_cast<std::size_t>(quilt.tri_element[f])];
    Tri tri;
    for (int k = 0; k < 3; ++k) {
      const int v = quilt.tris[f][static_cast<std::size_t>(k)];
      if (local[static_cast<std::size_t>(v)] < 0) {
        local[static_cast<std::size_t>(v)] = static_cast<int>(m.points.size());
        m.points.push_back(pos[static_cast<std::size_t>(v)]);
      }
      tri[static_cast<std::size_t>(k)] = local[static_cast<std::size_t>(v)];
    }
    m.tris.push_back(tri);
  }
  mesh_from_elements(els, out);
  if (opt.measure_outside_shell) {
    res.outside_shell = measure_outside_shell(pos, shell, map, opt.outside_shell);
    res.outside_shell_measured = true;
  }
  res.embed.vertices = nv;
  for (std::size_t i = 0; i < nv; ++i)
    if (clamped[i]) ++res.locations_clamped, res.most_negative_barycentric = std::min(res.most_negative_barycentric, most_negative[i]);
  for (std::size_t i = 0; i < nv; ++i) {
    if (!outside[i]) continue;
    ++res.embed.outside;
    const double w = (quilt.vertices[i].z - quilt.z_min) / dz;
    if (w < 0)
      ++res.outside_below;
    else if (w > 1)
      ++res.outside_above;
    else
      ++res.outside_uv;
  }
  // Resolution rounds (a cut piece's cap may meet another element), each
  // reusing the exact check that the count below reports.
  std::vector<FacePair> pairs;
  bool checked = false;
  if (opt.resolve_crossings) {
    std::vector<char> compact = quilt.element_compact;
    for (int round = 0; round < 3; ++round) {
      pairs = self_intersecting_faces(out);
      checked = true;
      if (pairs.empty()) break;
      resolve_embedded_crossings(pairs, compact, els, out, res);
      checked = false;
    }
  }
  if (opt.check_self_intersections) {
    if (!checked) pairs = self_intersecting_faces(out);
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
  res.seconds_embed = t.seconds();
  report_progress(opt.progress, "embed", 1.0);
  return res;
}

}  // namespace surftex
