// SPDX-License-Identifier: AGPL-3.0-or-later
// sqrt(2)-subdivision (Li et al. 2004; Bangay & Morkel 2006, sections 3.2.1
// and 3.2.2). See sqrt2_subdivide.h for the rules.
#include "texture/subdivision/sqrt2_subdivide.h"

#include <array>
#include <optional>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

/// Whether face f is split (every face without a selection).
bool is_refined(FaceIndex f, const std::vector<char>* refine) {
  return f != Mesh::null_face() && (!refine || (*refine)[f.idx()] != 0);
}

void check_subdivide_inputs(const Mesh& mesh, const std::vector<char>* refine, const Sqrt2SubdivideOptions& opt) {
  const std::size_t nv = mesh.number_of_vertices();
  const std::size_t nf = mesh.number_of_faces();
  if (nv == 0 || nf == 0) throw InvalidInputError("sqrt2_subdivide: the mesh is empty (no vertices or faces)");
  if (!(opt.vertex_weight >= 0.0 && opt.vertex_weight <= 1.0))
    throw InvalidInputError("sqrt2_subdivide: vertex_weight must be in [0,1] (got " +
                            std::to_string(opt.vertex_weight) + ")");
  if (refine && refine->size() != nf)
    throw InvalidInputError("sqrt2_subdivide_selected: refine has " + std::to_string(refine->size()) +
                            " entries but the mesh has " + std::to_string(nf) + " faces");
}

/// The new vertex positions: the old vertices, then one face point (the
/// centroid) per refined face, in face order; fp[f] = its index, -1 if none.
void add_face_points(const Mesh& mesh, const std::vector<char>* refine, std::vector<long>& fp,
                     std::vector<Point3>& pos) {
  fp.assign(mesh.number_of_faces(), -1);
  pos.resize(mesh.number_of_vertices());
  for (VertexIndex v : mesh.vertices()) pos[v.idx()] = mesh.point(v);
  for (FaceIndex f : mesh.faces()) {
    if (!is_refined(f, refine)) continue;
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
}

/// Approximating vertex rule (uniform split only), interior vertices:
/// v' = (1-beta) v + beta mean(f*), the mean of the surrounding face points.
void smooth_old_vertices(const Mesh& mesh, const std::vector<long>& fp, double beta, std::vector<Point3>& pos) {
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

/// Vertex properties carried to the subdivided mesh (colour, sweep,
/// direction), per new vertex.
struct CarriedProperties {
  bool col = false, swp = false, dir = false;
  std::vector<Color3f> ncol;
  std::vector<double> nswp;
  std::vector<Vector3> ndir;
};

/// Carried properties: old vertices keep theirs, face points average their face's.
CarriedProperties carry_properties(const Mesh& mesh, const Sqrt2SubdivideOptions& opt, const std::vector<long>& fp,
                                   std::size_t new_vertices) {
  auto col = find(mesh, kVertexColor);
  auto swp = find(mesh, kVertexSweep);
  auto dir = find(mesh, kVertexDirection);
  CarriedProperties cp;
  cp.col = opt.carry_color && col.second;
  cp.swp = opt.carry_sweep && swp.second;
  cp.dir = opt.carry_direction && dir.second;
  if (!(cp.col || cp.swp || cp.dir)) return cp;
  if (cp.col) cp.ncol.resize(new_vertices);
  if (cp.swp) cp.nswp.resize(new_vertices);
  if (cp.dir) cp.ndir.resize(new_vertices, Vector3(0, 0, 0));
  for (VertexIndex v : mesh.vertices()) {
    if (cp.col) cp.ncol[v.idx()] = col.first[v];
    if (cp.swp) cp.nswp[v.idx()] = swp.first[v];
    if (cp.dir) cp.ndir[v.idx()] = dir.first[v];
  }
  for (FaceIndex f : mesh.faces()) {
    if (fp[f.idx()] < 0) continue;
    std::array<double, 3> c{0, 0, 0};
    double s = 0;
    Vector3 d(0, 0, 0);
    int n = 0;
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) {
      if (cp.col)
        for (int k = 0; k < 3; ++k) c[k] += col.first[v][k];
      if (cp.swp) s += swp.first[v];
      if (cp.dir) d = d + dir.first[v];
      ++n;
    }
    const std::size_t i = static_cast<std::size_t>(fp[f.idx()]);
    if (cp.col) cp.ncol[i] = {float(c[0] / n), float(c[1] / n), float(c[2] / n)};
    if (cp.swp) cp.nswp[i] = s / n;
    if (cp.dir) cp.ndir[i] = d / n;
  }
  return cp;
}

/// The subdivided connectivity over `pos`: unrefined faces first, unchanged;
/// then per old edge (the edge flip of sqrt(2) subdivision) the quad
/// (a, face point of g, b, face point of f) between two refined faces, or a
/// triangle towards the one refined face. Throws TopologyError when a face is refused.
Mesh connect_subdivided(const Mesh& mesh, const std::vector<char>* refine, const std::vector<long>& fp,
                        const std::vector<Point3>& pos, Sqrt2SubdivideResult& res) {
  Mesh out;
  out.reserve(static_cast<Mesh::size_type>(pos.size()), 0, 0);
  for (const Point3& p : pos) out.add_vertex(p);
  auto add = [&](std::initializer_list<std::size_t> ids) {
    std::vector<VertexIndex> vs;
    for (std::size_t i : ids) vs.push_back(VertexIndex(static_cast<Mesh::size_type>(i)));
    if (out.add_face(vs) == Mesh::null_face())
      throw TopologyError("sqrt2_subdivide: the subdivided mesh refuses a face (non-manifold input?)");
  };
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
    const bool fr = is_refined(f, refine), gr = is_refined(g, refine);
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
  return out;
}

/// The carried properties onto the subdivided mesh.
void attach_properties(const CarriedProperties& cp, Mesh& mesh) {
  if (cp.col) {
    auto m = get_or_add(mesh, kVertexColor);
    for (VertexIndex v : mesh.vertices()) m[v] = cp.ncol[v.idx()];
  }
  if (cp.swp) {
    auto m = get_or_add(mesh, kVertexSweep);
    for (VertexIndex v : mesh.vertices()) m[v] = cp.nswp[v.idx()];
  }
  if (cp.dir) {
    auto m = get_or_add(mesh, kVertexDirection, Vector3(0, 0, 0));
    for (VertexIndex v : mesh.vertices()) m[v] = cp.ndir[v.idx()];
  }
}

/// One sqrt(2) step (Bangay & Morkel 2006 s.3.2.1-3.2.2): a face point per
/// refined face, the old vertices smoothed (uniform split only), the old
/// edges flipped into quads between face points, the carried properties
/// averaged onto the face points.
Sqrt2SubdivideResult subdivide_impl(Mesh& mesh, const std::vector<char>* refine, const Sqrt2SubdivideOptions& opt,
                                    bool smooth) {
  if (mesh.has_garbage()) mesh.collect_garbage();
  check_subdivide_inputs(mesh, refine, opt);
  Sqrt2SubdivideResult res;
  const std::size_t nv = mesh.number_of_vertices();
  res.old_vertices = nv;
  std::vector<long> fp;
  std::vector<Point3> pos;
  add_face_points(mesh, refine, fp, pos);
  res.face_points = pos.size() - nv;
  if (smooth && !refine && opt.smooth && opt.vertex_weight > 0) smooth_old_vertices(mesh, fp, opt.vertex_weight, pos);
  const CarriedProperties carried = carry_properties(mesh, opt, fp, pos.size());
  mesh = connect_subdivided(mesh, refine, fp, pos, res);
  attach_properties(carried, mesh);
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
