// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/load_input_mesh.h"

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/repair_mesh_json.h"

namespace surftex {
namespace {

/// True when some three corners of face f are not collinear (exact
/// predicate): the face spans a non-zero area.
bool face_has_area(const Mesh& m, FaceIndex f) {
  std::vector<Point3> p;
  for (VertexIndex v : m.vertices_around_face(m.halfedge(f))) p.push_back(m.point(v));
  for (std::size_t i = 1; i + 1 < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      if (!CGAL::collinear(p[0], p[i], p[j])) return true;
  return false;
}

bool all_triangles(const Mesh& m) {
  for (FaceIndex f : m.faces())
    if (m.degree(f) != 3) return false;
  return true;
}

/// A polygon mesh needs no repair when every face spans an area and no
/// vertex is isolated (Surface_mesh built from an oriented soup is already
/// manifold and consistently oriented).
bool polygons_usable(const Mesh& m) {
  for (VertexIndex v : m.vertices())
    if (m.is_isolated(v)) return false;
  for (FaceIndex f : m.faces())
    if (!face_has_area(m, f)) return false;
  return true;
}

}  // namespace

LoadInputReport load_input_mesh(const std::string& path, Mesh& mesh, const LoadInputOptions& opt) {
  LoadInputReport r;
  SoupToMeshOptions so;
  // repair_mesh triangulates (and counts what it cannot); with keep_polygons
  // the polygons survive when they need no repair.
  so.triangulate = false;
  read_mesh(path, mesh, so, &r.soup);
  if (opt.keep_polygons && !all_triangles(mesh) && polygons_usable(mesh)) return r;

  RepairOptions ro;
  ro.detect_self_intersections = false;  // costly, and reported by the methods that care
  ro.progress = opt.progress;
  r.repair = repair_mesh(mesh, ro);
  r.repair_ran = true;
  if (!r.repair.valid)
    throw TopologyError("cannot use mesh '" + path + "': " + r.repair.refusal);
  const RepairDone& d = r.repair.done;
  std::string s;
  auto note = [&](std::size_t n, const char* what) {  // count it and name it if it happened
    if (n == 0) return;
    r.repair_changes += n;
    if (!s.empty()) s += ", ";
    s += std::to_string(n) + " " + what;
  };
  note(d.untriangulable_faces_removed, "untriangulable faces removed");
  note(d.stitched_edges, "border edges stitched");
  note(d.degenerate_faces_removed + d.degenerate_faces_deleted, "zero-area faces removed");
  note(d.needles_collapsed, "needle triangles collapsed");
  note(d.caps_flipped, "cap triangles flipped");
  note(d.non_manifold_vertices_split, "vertices added splitting non-manifold vertices");
  note(d.isolated_vertices_removed, "isolated vertices removed");
  note(d.components_reoriented, "inward components reoriented");
  r.summary = s;
  return r;
}

nlohmann::json to_json(const LoadInputReport& r) {
  nlohmann::json j;
  j["soup"] = to_json(r.soup);
  j["repair"] = r.repair_ran ? to_json(r.repair) : nlohmann::json(nullptr);
  j["summary"] = r.summary;
  return j;
}

}  // namespace surftex
