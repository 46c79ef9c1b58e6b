// SPDX-License-Identifier: AGPL-3.0-or-later
// sqrt(2)-subdivision (Li et al. 2004; Bangay & Morkel 2006, sections 3.2.1
// and 3.2.2). See sqrt2_subdivide.h for the rules.
#include "geometry/sqrt2_subdivide.h"

#include <array>
#include <optional>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

Sqrt2SubdivideResult subdivide_impl(Mesh& mesh, const std::vector<char>* refine, const Sqrt2SubdivideOptions& opt,
                                    bool smooth) {
  if (mesh.has_garbage()) mesh.collect_garbage();
  const std::size_t nv = mesh.number_of_vertices();
  const std::size_t nf = mesh.number_of_faces();
  if (nv == 0 || nf == 0) throw InvalidInputError("sqrt2_subdivide: the mesh is empty (no vertices or faces)");
  if (!(opt.vertex_weight >= 0.0 && opt.vertex_weight <= 1.0))
    throw InvalidInputError("sqrt2_subdivide: vertex_weight must be in [0,1] (got " +
                            std::to_string(opt.vertex_weight) + ")");
  if (refine && refine->size() != nf)
    throw InvalidInputError("sqrt2_subdivide_selected: refine has " + std::to_string(refine->size()) +
                            " entries but the mesh has " + std::to_string(nf) + " faces");
  auto refined = [&](FaceIndex f) { return f != Mesh::null_face() && (!refine || (*refine)[f.idx()] != 0); };

  Sqrt2SubdivideResult res;
  res.old_vertices = nv;
  std::vector<long> fp(nf, -1);
  std::vector<Point3> pos(nv);
  for (VertexIndex v : mesh.vertices()) pos[v.idx()] = mesh.point(v);
  for (FaceIndex f : mesh.faces()) {
    if (!refined(f)) continue;
    double x = 0, y = 0, z = 0;
    int c = 0;
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
      const Point3& p = mesh.point(v);
      x += p.x(), y += p.y(), z += p.z();
      ++c;
    }
    fp[f.idx()] = static_cast<long>(pos.size());
    pos.emplace_back(x / c, y / c, z / c);
  }
  res.face_points = pos.size() - nv;

  // Approximating vertex rule (uniform split only): v' = (1-beta) v + beta mean(f*).
  if (smooth && !refine && opt.smooth && opt.vertex_weight > 0) {
    const double beta = opt.vertex_weight;
    for (VertexIndex v : mesh.vertices()) {
      if (mesh.is_border(v, false) || mesh.is_isolated(v)) continue;
      double x = 0, y = 0, z = 0;
      int c = 0;
      for (FaceIndex f : mesh.faces_around_target(mesh.halfedge(v))) {
        if (f == Mesh::null_face()) continue;
        const Point3& q = pos[fp[f.idx()]];
        x += q.x(), y += q.y(), z += q.z();
        ++c;
      }
      if (c == 0) continue;
      const Point3& p = mesh.point(v);
      pos[v.idx()] = Point3((1 - beta) * p.x() + beta * x / c, (1 - beta) * p.y() + beta * y / c,
                            (1 - beta) * p.z() + beta * z / c);
    }
  }

  // Carried properties: old vertices keep theirs, face points average their face's.
  auto col = find(mesh, kVertexColor);
  auto swp = find(mesh, kVertexSweep);
  auto dir = find(mesh, kVertexDirection);
  const bool do_col = opt.carry_color && col.second, do_swp = opt.carry_sweep && swp.second,
             do_dir = opt.carry_direction && dir.second;
  std::vector<Color3f> ncol;
  std::vector<double> nswp;
  std::vector<Vector3> ndir;
  if (do_col || do_swp || do_dir) {
    if (do_col) ncol.resize(pos.size());
    if (do_swp) nswp.resize(pos.size());
    if (do_dir) ndir.resize(pos.size(), Vector3(0, 0, 0));
    for (VertexIndex v : mesh.vertices()) {
      if (do_col) ncol[v.idx()] = col.first[v];
      if (do_swp) nswp[v.idx()] = swp.first[v];
      if (do_dir) ndir[v.idx()] = dir.first[v];
    }
    for (FaceIndex f : mesh.faces()) {
      if (fp[f.idx()] < 0) continue;
      std::array<double, 3> c{0, 0, 0};
      double s = 0;
      Vector3 d(0, 0, 0);
      int n = 0;
      for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
        if (do_col)
          for (int k = 0; k < 3; ++k) c[k] += col.first[v][k];
        if (do_swp) s += swp.first[v];
        if (do_dir) d = d + dir.first[v];
        ++n;
      }
      const std::size_t i = static_cast<std::size_t>(fp[f.idx()]);
      if (do_col) ncol[i] = {float(c[0] / n), float(c[1] / n), float(c[2] / n)};
      if (do_swp) nswp[i] = s / n;
      if (do_dir) ndir[i] = d / n;
    }
  }

  Mesh out;
  out.reserve(static_cast<Mesh::size_type>(pos.size()), 0, 0);
  for (const Point3& p : pos) out.add_vertex(p);
  auto add = [&](std::initializer_list<std::size_t> ids) {
    std::vector<VertexIndex> vs;
    for (std::size_t i : ids) vs.push_back(VertexIndex(static_cast<Mesh::size_type>(i)));
    if (out.add_face(vs) == Mesh::null_face())
      throw TopologyError("sqrt2_subdivide: the subdivided mesh refuses a face (non-manifold input?)");
  };
  // Unrefined faces first, unchanged.
  for (FaceIndex f : mesh.faces()) {
    if (fp[f.idx()] >= 0) continue;
    std::vector<VertexIndex> vs;
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) vs.push_back(VertexIndex(v.idx()));
    if (out.add_face(vs) == Mesh::null_face())
      throw TopologyError("sqrt2_subdivide: could not keep face " + std::to_string(f.idx()));
    ++res.faces_kept;
  }
  for (EdgeIndex e : mesh.edges()) {
    const HalfedgeIndex h = mesh.halfedge(e, 0);
    const VertexIndex a = mesh.source(h), b = mesh.target(h);
    const FaceIndex f = mesh.face(h), g = mesh.face(mesh.opposite(h));
    if (f == g) throw TopologyError("sqrt2_subdivide: edge " + std::to_string(e.idx()) + " has the same face on both sides");
    const bool fr = refined(f), gr = refined(g);
    if (fr && gr) {
      add({a.idx(), std::size_t(fp[g.idx()]), b.idx(), std::size_t(fp[f.idx()])});
      ++res.quads;
    } else if (fr) {
      add({a.idx(), b.idx(), std::size_t(fp[f.idx()])});
      ++res.triangles;
    } else if (gr) {
      add({b.idx(), a.idx(), std::size_t(fp[g.idx()])});
      ++res.triangles;
    }
  }
  mesh = std::move(out);
  if (do_col) {
    auto m = get_or_add(mesh, kVertexColor);
    for (VertexIndex v : mesh.vertices()) m[v] = ncol[v.idx()];
  }
  if (do_swp) {
    auto m = get_or_add(mesh, kVertexSweep);
    for (VertexIndex v : mesh.vertices()) m[v] = nswp[v.idx()];
  }
  if (do_dir) {
    auto m = get_or_add(mesh, kVertexDirection, Vector3(0, 0, 0));
    for (VertexIndex v : mesh.vertices()) m[v] = ndir[v.idx()];
  }
  return res;
}

}  // namespace

Sqrt2SubdivideResult sqrt2_subdivide(Mesh& mesh, const Sqrt2SubdivideOptions& opt) {
  return subdivide_impl(mesh, nullptr, opt, true);
}

Sqrt2SubdivideResult sqrt2_subdivide_selected(Mesh& mesh, const std::vector<char>& refine,
                                              const Sqrt2SubdivideOptions& opt) {
  return subdivide_impl(mesh, &refine, opt, false);
}

}  // namespace surftex
