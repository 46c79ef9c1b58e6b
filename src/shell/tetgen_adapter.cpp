// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/tetgen_adapter.h"

#include <tetgen.h>

#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/self_intersections.h"

namespace surftex {

namespace {
std::string tetgen_code(int code) {
  switch (code) {
    case 1: return "1 (out of memory)";
    case 2: return "2 (internal error)";
    case 3: return "3 (self-intersecting input facets)";
    case 4: return "4 (very small input feature)";
    case 5: return "5 (two very close input facets)";
    case 10: return "10 (input error)";
    default: return std::to_string(code);
  }
}
}  // namespace

TetMeshResult tetrahedralize_closed_surface(const Mesh& boundary, const TetGenOptions& opt) {
  if (opt.switches.find('p') == std::string::npos)
    throw InvalidInputError("tetgen: switches must contain 'p' (PLC input), got \"" + opt.switches + "\"");
  if (opt.switches.find('r') != std::string::npos || opt.switches.find("o2") != std::string::npos)
    throw InvalidInputError("tetgen: switches 'r' and 'o2' are not supported, got \"" + opt.switches + "\"");
  if (boundary.number_of_faces() < 4) throw InvalidInputError("tetgen: boundary surface has fewer than 4 faces");
  if (boundary.has_garbage()) throw InvalidInputError("tetgen: boundary surface has removed elements");
  for (HalfedgeIndex h : boundary.halfedges())
    if (boundary.is_border(h))
      throw InvalidInputError("tetgen: boundary surface is not closed (border edge at vertex " +
                              std::to_string(boundary.target(h).idx()) + ")");
  for (FaceIndex f : boundary.faces())
    if (boundary.degree(f) != 3)
      throw InvalidInputError("tetgen: boundary face " + std::to_string(f.idx()) + " is not a triangle");

  // TetGen 1.5 crashes (segmentation fault, no throw) on some self-intersecting
  // PLCs: refuse them first with the exact check.
  if (const std::size_t n = count_self_intersections(boundary); n > 0)
    throw InvalidInputError("tetgen: boundary surface self-intersects (" + std::to_string(n) +
                            " face pairs); TetGen needs a valid PLC");

  tetgenio in, out;  // their destructors free the arrays with delete[]
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(boundary.num_vertices());
  in.pointlist = new REAL[3 * static_cast<std::size_t>(in.numberofpoints)];
  for (VertexIndex v : boundary.vertices()) {
    const Point3& p = boundary.point(v);
    in.pointlist[3 * v.idx()] = p.x();
    in.pointlist[3 * v.idx() + 1] = p.y();
    in.pointlist[3 * v.idx() + 2] = p.z();
  }
  in.numberoffacets = static_cast<int>(boundary.number_of_faces());
  in.facetlist = new tetgenio::facet[static_cast<std::size_t>(in.numberoffacets)];
  int fi = 0;
  for (FaceIndex f : boundary.faces()) {
    tetgenio::facet& fa = in.facetlist[fi++];
    tetgenio::init(&fa);
    fa.numberofpolygons = 1;
    fa.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&fa.polygonlist[0]);
    fa.polygonlist[0].numberofvertices = 3;
    fa.polygonlist[0].vertexlist = new int[3];
    int k = 0;
    for (VertexIndex v : boundary.vertices_around_face(boundary.halfedge(f)))
      fa.polygonlist[0].vertexlist[k++] = static_cast<int>(v.idx());
  }

  std::vector<char> sw(opt.switches.begin(), opt.switches.end());
  sw.push_back('\0');
  try {
    tetrahedralize(sw.data(), &in, &out);
  } catch (int code) {
    throw SolverError("tetgen: tetrahedralize(\"" + opt.switches + "\") failed with code " + tetgen_code(code) +
                      " on a surface of " + std::to_string(boundary.number_of_faces()) + " faces");
  } catch (const std::exception& e) {
    throw SolverError(std::string("tetgen: tetrahedralize failed: ") + e.what());
  } catch (...) {
    throw SolverError("tetgen: tetrahedralize failed with an unknown exception");
  }

  if (out.numberoftetrahedra <= 0 || out.tetrahedronlist == nullptr)
    throw SolverError("tetgen: no tetrahedra produced (switches \"" + opt.switches + "\")");
  if (out.numberofcorners != 4)
    throw SolverError("tetgen: expected 4 corners per tet, got " + std::to_string(out.numberofcorners));
  if (out.numberofpoints < in.numberofpoints || out.pointlist == nullptr)
    throw SolverError("tetgen: output lost input points (" + std::to_string(out.numberofpoints) + " < " +
                      std::to_string(in.numberofpoints) + ")");

  TetMeshResult r;
  r.input_points = static_cast<std::size_t>(in.numberofpoints);
  r.steiner_points = static_cast<std::size_t>(out.numberofpoints - in.numberofpoints);
  r.points.resize(static_cast<std::size_t>(out.numberofpoints));
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    r.points[i] = {out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2]};
    if (!std::isfinite(r.points[i][0]) || !std::isfinite(r.points[i][1]) || !std::isfinite(r.points[i][2]))
      throw SolverError("tetgen: non-finite output point " + std::to_string(i));
  }
  const int base = out.firstnumber;
  r.tets.resize(static_cast<std::size_t>(out.numberoftetrahedra));
  for (std::size_t t = 0; t < r.tets.size(); ++t) {
    std::array<int, 4> q;
    Point3 p[4];
    for (int k = 0; k < 4; ++k) {
      q[k] = out.tetrahedronlist[4 * t + k] - base;
      if (q[k] < 0 || q[k] >= out.numberofpoints)
        throw SolverError("tetgen: tet " + std::to_string(t) + " has an out-of-range corner " + std::to_string(q[k]));
      const auto& a = r.points[static_cast<std::size_t>(q[k])];
      p[k] = Point3(a[0], a[1], a[2]);
    }
    const CGAL::Orientation o = CGAL::orientation(p[0], p[1], p[2], p[3]);
    if (o == CGAL::ZERO) throw SolverError("tetgen: tet " + std::to_string(t) + " is degenerate (flat)");
    if (o == CGAL::NEGATIVE) std::swap(q[0], q[1]), ++r.reoriented;
    r.tets[t] = q;
  }
  return r;
}

}  // namespace surftex
