// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/swatch.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <CGAL/Polygon_mesh_processing/connected_components.h>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/self_intersections.h"
#include "geometry/union_find.h"
#include "shell/element_clearance.h"

namespace surftex {

namespace {

// The swatch's self-intersecting face pairs, exact (face t = triangle t).
std::vector<FacePair> swatch_crossings(const ElementMesh& m) {
  Mesh whole;
  mesh_from_elements({m}, whole);
  return self_intersecting_faces(whole);
}

// Components that pass through each other (a pair of `crossings` between two
// of them) joined into one element: a scanned or modelled group such as
// apples sunk into their bowl is one element to quilting, which copies,
// merges and removes elements whole (Zhou 2.5-2.7) and would resolve the
// copies' crossings by dropping the apples. Relabels `face_element`
// (components of triangle_components, 0..n-1) in order of first face and
// returns the number of elements.
int group_crossing_components(const std::vector<FacePair>& crossings, std::vector<int>& face_element, int n) {
  if (n < 2) return n;
  UnionFind<int> groups(static_cast<std::size_t>(n));
  bool joined = false;
  for (const FacePair& p : crossings) joined |= groups.unite(face_element[p[0]], face_element[p[1]]);
  if (!joined) return n;
  std::vector<int> relabel(static_cast<std::size_t>(n), -1);
  int count = 0;
  for (int& e : face_element) {
    int& r = relabel[static_cast<std::size_t>(groups.find(e))];
    if (r < 0) r = count++;
    e = r;
  }
  return count;
}

// The most of `crossings` within one of the n elements.
std::size_t most_crossings_within(const std::vector<FacePair>& crossings, const std::vector<int>& face_element, int n) {
  std::vector<std::size_t> per(static_cast<std::size_t>(n), 0);
  for (const FacePair& p : crossings)
    if (face_element[p[0]] == face_element[p[1]]) ++per[static_cast<std::size_t>(face_element[p[0]])];
  return per.empty() ? 0 : *std::max_element(per.begin(), per.end());
}

}  // namespace

Swatch make_swatch(const Mesh& mesh) {
  if (mesh.number_of_faces() == 0) throw InvalidInputError("swatch: the mesh has no faces");
  // read_mesh refuses NaN/inf in files; a mesh built or transformed in code
  // (e.g. scaled by a huge factor) can still carry them, and one non-finite
  // point would poison every bounding box and cell size downstream.
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw InvalidInputError("swatch: vertex " + std::to_string(v.idx()) + " has a non-finite coordinate (" +
                              std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                              ")");
  }
  Swatch s;
  s.mesh = element_mesh_from(mesh);
  s.components = triangle_components(s.mesh, s.face_element);
  const std::vector<FacePair> crossings = swatch_crossings(s.mesh);
  const int n = group_crossing_components(crossings, s.face_element, s.components);
  s.element_self_crossings = most_crossings_within(crossings, s.face_element, n);
  s.elements.assign(static_cast<std::size_t>(n), SwatchElement{});
  const std::vector<ElementMesh> els = swatch_element_meshes(s);
  s.bbox_min = {1e300, 1e300, 1e300};
  s.bbox_max = {-1e300, -1e300, -1e300};
  double edge_sum = 0;
  std::size_t edges = 0;
  for (int e = 0; e < n; ++e) {
    const ElementMesh& em = els[static_cast<std::size_t>(e)];
    SwatchElement& el = s.elements[e];
    el.faces = em.tris.size();
    el.closed = count_border_edges(em) == 0;
    el.bbox_min = {1e300, 1e300, 1e300};
    el.bbox_max = {-1e300, -1e300, -1e300};
    for (const P3& p : em.points)
      for (int d = 0; d < 3; ++d) {
        el.bbox_min[d] = std::min(el.bbox_min[d], p[d]);
        el.bbox_max[d] = std::max(el.bbox_max[d], p[d]);
        el.centroid[d] += p[d] / static_cast<double>(em.points.size());
      }
    for (int d = 0; d < 3; ++d) {
      s.bbox_min[d] = std::min(s.bbox_min[d], el.bbox_min[d]);
      s.bbox_max[d] = std::max(s.bbox_max[d], el.bbox_max[d]);
    }
    for (const Tri& t : em.tris)
      for (int k = 0; k < 3; ++k) {
        const P3 &a = em.points[t[k]], &b = em.points[t[(k + 1) % 3]];
        edge_sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                              (a[2] - b[2]) * (a[2] - b[2]));
        ++edges;
      }
  }
  s.mean_edge_length = edges ? edge_sum / static_cast<double>(edges) : 0;
  if (!(s.length() > 0) || !(s.width() > 0))
    throw InvalidInputError("swatch: zero extent in x or y (" + std::to_string(s.length()) + " x " +
                            std::to_string(s.width()) + ")");
  if (n > 1) s.min_gap = smallest_element_gap(els, std::max(s.length(), s.width()));
  return s;
}

int swatch_thin_axis(const Mesh& mesh) {
  if (mesh.number_of_vertices() == 0) throw InvalidInputError("swatch: the mesh has no vertices");
  P3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    const P3 q{p.x(), p.y(), p.z()};
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], q[d]), hi[d] = std::max(hi[d], q[d]);
  }
  const P3 ext{hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
  int axis = 2;
  for (int d : {1, 0})
    if (ext[d] < 0.99 * ext[axis]) axis = d;
  return axis;
}

void orient_swatch_up(Mesh& mesh, int axis) {
  if (axis == 2) return;
  for (VertexIndex v : mesh.vertices()) {
    const Point3 p = mesh.point(v);
    mesh.point(v) = axis == 0 ? Point3(p.y(), p.z(), p.x()) : Point3(p.z(), p.x(), p.y());
  }
}

double swatch_element_spacing(const Swatch& s) {
  if (s.elements.size() < 2) return std::max(s.length(), s.width());
  std::vector<double> d;
  for (const SwatchElement& a : s.elements) {
    double best = 1e300;
    for (const SwatchElement& b : s.elements)
      if (&a != &b) best = std::min(best, std::hypot(a.centroid[0] - b.centroid[0], a.centroid[1] - b.centroid[1]));
    d.push_back(best);
  }
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

const char* axis_name(int axis) { return axis == 0 ? "x" : axis == 1 ? "y" : "z"; }

Swatch make_swatch(const Mesh& mesh, SwatchAxis up) {
  if (mesh.number_of_faces() == 0) throw InvalidInputError("swatch: the mesh has no faces");
  const int axis = up == SwatchAxis::kAuto ? swatch_thin_axis(mesh) : up == SwatchAxis::kX ? 0 : up == SwatchAxis::kY ? 1 : 2;
  if (axis == 2) return make_swatch(mesh);
  Mesh turned = mesh;
  orient_swatch_up(turned, axis);
  Swatch s = make_swatch(turned);
  s.up_axis = axis;
  return s;
}

void swatch_cells(const Swatch& s, double c, const std::string& who, int& sx, int& sy) {
  sx = static_cast<int>(std::ceil(s.length() / c - 1e-9));
  sy = static_cast<int>(std::ceil(s.width() / c - 1e-9));
  if (std::min(sx, sy) >= 3) return;
  // The input's axes that became x and y (orient_swatch_up's cyclic turn).
  const int ax = (s.up_axis + 1) % 3, ay = (s.up_axis + 2) % 3;
  auto num = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return std::string(buf);
  };
  throw InvalidInputError(who + ": the swatch covers only " + std::to_string(sx) + "x" + std::to_string(sy) +
                          " cells of size " + num(c) + " along its " + axis_name(ax) + " and " + axis_name(ay) +
                          " axes (extent " + num(s.length()) + " x " + num(s.width()) + "; its thin axis " +
                          axis_name(s.up_axis) + ", extent " + num(s.height()) +
                          ", is the height); need >= 3 along each: give a smaller cell (--cell, at most " +
                          num(std::min(s.length(), s.width()) / 3) + ") or the swatch's thin axis (--swatch-up x|y|z)");
}

Swatch load_swatch(const std::string& path) {
  Mesh m;
  read_mesh(path, m);
  return make_swatch(m);
}

std::vector<ElementMesh> swatch_element_meshes(const Swatch& s) {
  std::size_t n = 0;
  for (int e : s.face_element) n = std::max(n, static_cast<std::size_t>(e) + 1);
  std::vector<std::vector<int>> tris(n);
  for (std::size_t t = 0; t < s.face_element.size(); ++t) tris[static_cast<std::size_t>(s.face_element[t])].push_back(static_cast<int>(t));
  std::vector<ElementMesh> out;
  out.reserve(n);
  for (const std::vector<int>& t : tris) out.push_back(extract_triangles(s.mesh, t));
  return out;
}


ElementMesh swatch_element(const Swatch& s, int e) {
  std::vector<int> tris;
  for (std::size_t t = 0; t < s.face_element.size(); ++t)
    if (s.face_element[t] == e) tris.push_back(static_cast<int>(t));
  return extract_triangles(s.mesh, tris);
}

int label_elements(Mesh& mesh) {
  auto elem = get_or_add(mesh, kFaceElement, -1);
  // Component ids numbered in order of the first face, independent of CGAL's
  // numbering: relabel by first appearance.
  auto tmp = mesh.add_property_map<FaceIndex, std::size_t>("f:tmp_cc", 0).first;
  CGAL::Polygon_mesh_processing::connected_components(mesh, tmp);
  std::vector<int> relabel;
  int n = 0;
  for (FaceIndex f : mesh.faces()) {
    std::size_t c = tmp[f];
    if (c >= relabel.size()) relabel.resize(c + 1, -1);
    if (relabel[c] < 0) relabel[c] = n++;
    elem[f] = relabel[c];
  }
  mesh.remove_property_map(tmp);
  return n;
}

}  // namespace surftex
