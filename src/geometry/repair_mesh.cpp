// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/repair_mesh.h"

#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/repair.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>
#include <CGAL/boost/graph/Euler_operations.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <exception>
#include <functional>
#include <iterator>
#include <map>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/self_intersections.h"
#include "geometry/timer.h"

namespace surftex {

namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

std::string num(std::size_t n) { return std::to_string(n); }

bool is_triangle_face(const Mesh& m, FaceIndex f) { return m.degree(f) == 3; }

std::size_t count_duplicate_vertices(const Mesh& m) {
  std::vector<Point3> pts;
  pts.reserve(m.number_of_vertices());
  for (VertexIndex v : m.vertices()) pts.push_back(m.point(v));
  std::sort(pts.begin(), pts.end(), [](const Point3& a, const Point3& b) {
    return CGAL::compare_xyz(a, b) == CGAL::SMALLER;
  });
  std::size_t dup = 0;
  for (std::size_t i = 1; i < pts.size(); ++i)
    if (pts[i] == pts[i - 1]) ++dup;
  return dup;
}

std::size_t count_non_manifold_vertices(const Mesh& m) {
  // PMP::non_manifold_vertices is linear (is_non_manifold_vertex per vertex
  // would be quadratic); it reports one halfedge per umbrella.
  std::vector<HalfedgeIndex> hs;
  PMP::non_manifold_vertices(m, std::back_inserter(hs));
  std::vector<VertexIndex> vs;
  for (HalfedgeIndex h : hs) vs.push_back(m.target(h));
  std::sort(vs.begin(), vs.end());
  return static_cast<std::size_t>(std::unique(vs.begin(), vs.end()) - vs.begin());
}

std::size_t count_degenerate_faces(const Mesh& m) {
  std::size_t n = 0;
  for (FaceIndex f : m.faces())
    if (is_triangle_face(m, f) && PMP::is_degenerate_triangle_face(f, m)) ++n;
  return n;
}

std::size_t count_border_edges(const Mesh& m) {
  std::size_t n = 0;
  for (EdgeIndex e : m.edges())
    if (m.is_border(e)) ++n;
  return n;
}

std::size_t count_boundary_loops(const Mesh& m) {
  std::vector<HalfedgeIndex> cycles;
  PMP::extract_boundary_cycles(m, std::back_inserter(cycles));
  return cycles.size();
}

/// Connected components of the faces (face -> component id), with per
/// component "closed" flag and signed volume. Works on any valid mesh
/// (polygons are fanned for the volume). Garbage must be collected.
struct Components {
  std::vector<std::size_t> of_face;  // by face idx
  std::vector<bool> closed;
  std::vector<double> volume;
  std::vector<std::size_t> faces;
  std::size_t count() const { return closed.size(); }
};

Components components_of(const Mesh& m) {
  Components c;
  c.of_face.assign(m.number_of_faces() + m.number_of_removed_faces(), std::size_t(-1));
  std::size_t next = 0;
  std::vector<FaceIndex> stack;
  // Origin at the bounding box centre keeps the volume sums well conditioned.
  CGAL::Bbox_3 box;
  for (VertexIndex v : m.vertices()) box += m.point(v).bbox();
  const Point3 o((box.xmin() + box.xmax()) / 2, (box.ymin() + box.ymax()) / 2,
                 (box.zmin() + box.zmax()) / 2);
  for (FaceIndex f0 : m.faces()) {
    if (c.of_face[f0.idx()] != std::size_t(-1)) continue;
    const std::size_t id = next++;
    c.closed.push_back(true);
    c.volume.push_back(0.0);
    c.faces.push_back(0);
    stack.assign(1, f0);
    c.of_face[f0.idx()] = id;
    while (!stack.empty()) {
      FaceIndex f = stack.back();
      stack.pop_back();
      ++c.faces[id];
      HalfedgeIndex h0 = m.halfedge(f);
      const Vector3 p0 = m.point(m.target(h0)) - o;
      HalfedgeIndex h = m.next(h0);
      for (std::size_t k = 0, d = m.degree(f); k + 2 < d; ++k, h = m.next(h)) {
        const Vector3 p1 = m.point(m.target(h)) - o, p2 = m.point(m.target(m.next(h))) - o;
        c.volume[id] += CGAL::scalar_product(p0, CGAL::cross_product(p1, p2)) / 6.0;
      }
      for (HalfedgeIndex hh : CGAL::halfedges_around_face(h0, m)) {
        FaceIndex g = m.face(m.opposite(hh));
        if (g == Mesh::null_face()) {
          c.closed[id] = false;
          continue;
        }
        if (c.of_face[g.idx()] == std::size_t(-1)) {
          c.of_face[g.idx()] = id;
          stack.push_back(g);
        }
      }
    }
  }
  return c;
}

std::size_t count_inward_closed(const Components& c) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < c.count(); ++i)
    if (c.closed[i] && c.volume[i] < 0) ++n;
  return n;
}

/// Throws TopologyError unless `m` is a valid triangle mesh (the CGAL
/// preconditions of the repair steps, which Release builds do not check).
void require_valid_triangle_mesh(const Mesh& m) {
  if (!CGAL::is_valid_polygon_mesh(m)) throw TopologyError("mesh is not a valid polygon mesh");
  if (!CGAL::is_triangle_mesh(m)) throw TopologyError("mesh has non-triangle faces");
}

Vector3 tri_normal(const Point3& a, const Point3& b, const Point3& c) {
  return CGAL::cross_product(b - a, c - a);
}

/// True when moving vertex v to `p` keeps every incident face (other than
/// `skip1`, `skip2`) non-degenerate and turns none of them by 90 degrees or more.
bool move_keeps_faces(const Mesh& m, VertexIndex v, const Point3& p, FaceIndex skip1,
                      FaceIndex skip2) {
  for (HalfedgeIndex h : CGAL::halfedges_around_target(m.halfedge(v), m)) {
    FaceIndex f = m.face(h);
    if (f == Mesh::null_face() || f == skip1 || f == skip2) continue;
    const Point3& a = m.point(m.target(m.next(h)));
    const Point3& b = m.point(m.target(m.next(m.next(h))));
    if (CGAL::collinear(p, a, b)) return false;
    const Vector3 before = tri_normal(m.point(v), a, b), after = tri_normal(p, a, b);
    if (CGAL::scalar_product(before, after) <= 0) return false;
  }
  return true;
}

bool is_border_vertex(const Mesh& m, VertexIndex v) {
  return static_cast<bool>(CGAL::is_border(v, m));
}

/// Collapses the shortest edge of needles whose collapse is topologically
/// allowed (link condition) and flips no neighbour. Returns collapses done.
std::size_t collapse_needles(Mesh& m, double threshold) {
  std::size_t done = 0;
  std::vector<FaceIndex> todo(m.faces().begin(), m.faces().end());
  for (FaceIndex f : todo) {
    if (m.is_removed(f) || !is_triangle_face(m, f)) continue;
    if (PMP::is_degenerate_triangle_face(f, m)) continue;  // handled elsewhere
    HalfedgeIndex h = PMP::is_needle_triangle_face(f, m, threshold);
    if (h == Mesh::null_halfedge()) continue;
    EdgeIndex e = m.edge(h);
    if (!CGAL::Euler::does_satisfy_link_condition(e, m)) continue;
    VertexIndex v0 = m.source(h), v1 = m.target(h);
    const bool b0 = is_border_vertex(m, v0), b1 = is_border_vertex(m, v1);
    if (b0 && b1 && !m.is_border(e)) continue;  // would pinch two border stretches
    FaceIndex f1 = m.face(h), f2 = m.face(m.opposite(h));
    std::vector<Point3> choices;
    if (b0 && !b1) choices = {m.point(v0)};
    else if (b1 && !b0) choices = {m.point(v1)};
    else choices = {m.point(v1), m.point(v0)};
    for (const Point3& p : choices) {
      if (!move_keeps_faces(m, v0, p, f1, f2) || !move_keeps_faces(m, v1, p, f1, f2)) continue;
      VertexIndex kept = CGAL::Euler::collapse_edge(e, m);
      m.point(kept) = p;
      ++done;
      break;
    }
  }
  return done;
}

/// Flips the long edge of caps when the flip is allowed (interior edge, the
/// new edge does not exist yet) and gives two proper triangles facing the
/// same way as the neighbour across the long edge. Returns flips done.
std::size_t flip_caps(Mesh& m, double threshold) {
  std::size_t done = 0;
  std::vector<FaceIndex> todo(m.faces().begin(), m.faces().end());
  for (FaceIndex f : todo) {
    if (m.is_removed(f) || !is_triangle_face(m, f)) continue;
    if (PMP::is_degenerate_triangle_face(f, m)) continue;
    HalfedgeIndex h = PMP::is_cap_triangle_face(f, m, threshold);
    if (h == Mesh::null_halfedge() || m.is_border(m.edge(h))) continue;
    HalfedgeIndex o = m.opposite(h);
    if (!is_triangle_face(m, m.face(o))) continue;
    VertexIndex a = m.source(h), b = m.target(h), c = m.target(m.next(h)), d = m.target(m.next(o));
    if (c == d || CGAL::halfedge(c, d, m).second) continue;
    const Point3 &pa = m.point(a), &pb = m.point(b), &pc = m.point(c), &pd = m.point(d);
    // After the flip the faces are (a, d, c) and (d, b, c).
    if (CGAL::collinear(pa, pd, pc) || CGAL::collinear(pd, pb, pc)) continue;
    const Vector3 ref = tri_normal(pb, pa, pd);  // the neighbour (b, a, d)
    const Vector3 n1 = tri_normal(pa, pd, pc), n2 = tri_normal(pd, pb, pc);
    if (CGAL::scalar_product(n1, ref) <= 0 || CGAL::scalar_product(n2, ref) <= 0 ||
        CGAL::scalar_product(n1, n2) <= 0)
      continue;
    CGAL::Euler::flip_edge(h, m);
    ++done;
  }
  return done;
}

/// Deletes every zero-area triangle outright (last resort after
/// remove_degenerate_faces). Returns faces deleted.
std::size_t delete_degenerate_faces(Mesh& m) {
  std::vector<FaceIndex> bad;
  for (FaceIndex f : m.faces())
    if (is_triangle_face(m, f) && PMP::is_degenerate_triangle_face(f, m)) bad.push_back(f);
  for (FaceIndex f : bad) CGAL::Euler::remove_face(m.halfedge(f), m);
  return bad.size();
}

class Repairer {
 public:
  Repairer(Mesh& m, const RepairOptions& opt, RepairReport& r) : m_(m), opt_(opt), r_(r) {}

  /// Runs `fn` as step `name`: times it, collects garbage after it, and turns
  /// any exception into a recorded step error. Returns true on success.
  bool step(const std::string& name, const std::function<void()>& fn) {
    Timer t;
    bool ok = true;
    try {
      fn();
    } catch (const std::exception& e) {
      r_.done.step_errors.push_back(name + ": " + e.what());
      ok = false;
    }
    try {
      m_.collect_garbage();
    } catch (const std::exception& e) {
      r_.done.step_errors.push_back(name + " (collect_garbage): " + e.what());
      ok = false;
    }
    seconds_[name] += t.seconds();
    if (order_.end() == std::find(order_.begin(), order_.end(), name)) order_.push_back(name);
    return ok;
  }

  void progress(double fraction) { report_progress(opt_.progress, "repair", fraction); }

  /// One cleanup round; returns true if anything changed.
  bool cleanup_round() {
    std::size_t changes = 0;
    step("stitch_borders", [&] {
      require_valid_triangle_mesh(m_);
      std::size_t n = PMP::stitch_borders(m_);
      r_.done.stitched_edges += n;
      changes += n;
    });
    step("remove_degenerate_faces", [&] {
      require_valid_triangle_mesh(m_);
      if (count_degenerate_faces(m_) == 0) return;
      std::size_t before = m_.number_of_faces();
      PMP::remove_degenerate_faces(m_);
      std::size_t after = m_.number_of_faces();
      std::size_t n = before > after ? before - after : 0;
      r_.done.degenerate_faces_removed += n;
      changes += n;
    });
    step("remove_needles_and_caps", [&] {
      require_valid_triangle_mesh(m_);
      std::size_t n = collapse_needles(m_, opt_.needle_threshold);
      r_.done.needles_collapsed += n;
      changes += n;
      m_.collect_garbage();
      n = flip_caps(m_, opt_.cap_threshold);
      r_.done.caps_flipped += n;
      changes += n;
    });
    step("delete_degenerate_faces", [&] {
      require_valid_triangle_mesh(m_);
      std::size_t n = delete_degenerate_faces(m_);
      r_.done.degenerate_faces_deleted += n;
      changes += n;
    });
    step("duplicate_non_manifold_vertices", [&] {
      if (!CGAL::is_valid_polygon_mesh(m_)) throw TopologyError("mesh is not a valid polygon mesh");
      std::size_t n = PMP::duplicate_non_manifold_vertices(m_);
      r_.done.non_manifold_vertices_split += n;
      changes += n;
    });
    step("remove_isolated_vertices", [&] {
      std::size_t n = PMP::remove_isolated_vertices(m_);
      r_.done.isolated_vertices_removed += n;
      changes += n;
    });
    ++r_.done.rounds;
    return changes > 0;
  }

  void cleanup_loop() {
    for (int round = 0; round < opt_.max_rounds; ++round) {
      if (m_.is_empty() || m_.number_of_faces() == 0) break;
      if (!cleanup_round()) break;
    }
  }

  void fill_holes() {
    step("fill_holes", [&] {
      require_valid_triangle_mesh(m_);
      std::vector<HalfedgeIndex> cycles;
      PMP::extract_boundary_cycles(m_, std::back_inserter(cycles));
      for (HalfedgeIndex h : cycles) {
        if (!m_.is_border(h)) continue;  // already closed by an earlier fill
        std::size_t len = 0;
        for (HalfedgeIndex hh : CGAL::halfedges_around_face(h, m_)) {
          (void)hh;
          ++len;
        }
        if (len > opt_.max_hole_edges) {
          ++r_.done.holes_skipped;
          continue;
        }
        std::vector<FaceIndex> patch;
        // The full (cubic) search, not CGAL's default Delaunay search space:
        // that one's result depended on the heap layout (the same hole was
        // filled differently in one process and the next; decision 605).
        PMP::triangulate_hole(m_, h, std::back_inserter(patch),
                              CGAL::parameters::use_delaunay_triangulation(false));
        if (patch.empty()) {
          ++r_.done.holes_skipped;
        } else {
          ++r_.done.holes_filled;
          r_.done.faces_added_by_filling += patch.size();
        }
      }
    });
  }

  void orient_outward() {
    step("orient", [&] {
      if (!CGAL::is_valid_polygon_mesh(m_)) throw TopologyError("mesh is not a valid polygon mesh");
      Components c = components_of(m_);
      std::vector<std::vector<FaceIndex>> flip(c.count());
      for (FaceIndex f : m_.faces()) {
        std::size_t id = c.of_face[f.idx()];
        if (c.closed[id] && c.volume[id] < 0) flip[id].push_back(f);
      }
      for (auto& fs : flip) {
        if (fs.empty()) continue;
        PMP::reverse_face_orientations(fs, m_);
        ++r_.done.components_reoriented;
      }
    });
  }

  void keep_largest() {
    step("keep_largest_component", [&] {
      if (!CGAL::is_valid_polygon_mesh(m_)) throw TopologyError("mesh is not a valid polygon mesh");
      r_.done.components_removed += PMP::keep_largest_connected_components(m_, 1);
      PMP::remove_isolated_vertices(m_);
    });
  }

  void detect_self_intersections() {
    step("self_intersections", [&] {
      require_valid_triangle_mesh(m_);
      SelfIntersectionOptions so;
      so.parallel = opt_.parallel;
      r_.self_intersecting_pairs = count_self_intersections(m_, so);
      r_.self_intersections_checked = true;
    });
  }

  void validate() {
    Timer t;
    r_.vertices = m_.number_of_vertices();
    r_.faces = m_.number_of_faces();
    r_.valid = false;
    auto refuse = [&](const std::string& why) {
      r_.refusal = why;
      if (!r_.done.step_errors.empty()) r_.refusal += " (step errors: " + r_.done.step_errors.front() + ")";
    };
    if (r_.faces == 0) {
      refuse("nothing left after repair: all " + num(r_.found.faces) +
             " input faces were degenerate or removed");
    } else if (!CGAL::is_valid_polygon_mesh(m_)) {
      refuse("result is not a valid polygon mesh (" + num(r_.faces) + " faces)");
    } else if (!CGAL::is_triangle_mesh(m_)) {
      refuse("result has non-triangle faces");
    } else {
      Components c = components_of(m_);
      r_.components = c.count();
      r_.boundary_loops = count_boundary_loops(m_);
      r_.closed = r_.boundary_loops == 0;
      std::size_t degen = count_degenerate_faces(m_);
      std::size_t nm = count_non_manifold_vertices(m_);
      std::size_t inward = count_inward_closed(c);
      if (degen > 0)
        refuse(num(degen) + " degenerate (zero-area) faces remain after repair");
      else if (nm > 0)
        refuse(num(nm) + " non-manifold vertices remain after repair");
      else if (inward > 0)
        refuse(num(inward) + " closed components remain inward-oriented (negative volume)");
      else
        r_.valid = true;
    }
    seconds_["validate"] += t.seconds();
    order_.push_back("validate");
    for (const auto& name : order_) r_.seconds.emplace_back(name, seconds_[name]);
  }

 private:
  Mesh& m_;
  const RepairOptions& opt_;
  RepairReport& r_;
  std::map<std::string, double> seconds_;
  std::vector<std::string> order_;
};

void analyse(const Mesh& m, const RepairOptions& opt, RepairFound& f) {
  f.vertices = m.number_of_vertices();
  f.faces = m.number_of_faces();
  for (FaceIndex fi : m.faces()) {
    if (!is_triangle_face(m, fi)) {
      ++f.non_triangle_faces;
      continue;
    }
    if (PMP::is_degenerate_triangle_face(fi, m)) {
      ++f.zero_area_faces;
    } else if (PMP::is_needle_triangle_face(fi, m, opt.needle_threshold) != Mesh::null_halfedge()) {
      ++f.needle_faces;
    } else if (PMP::is_cap_triangle_face(fi, m, opt.cap_threshold) != Mesh::null_halfedge()) {
      ++f.cap_faces;
    }
  }
  f.duplicate_vertices = count_duplicate_vertices(m);
  f.non_manifold_vertices = count_non_manifold_vertices(m);
  f.border_edges = count_border_edges(m);
  f.boundary_loops = count_boundary_loops(m);
  for (VertexIndex v : m.vertices())
    if (m.is_isolated(v)) ++f.isolated_vertices;
  Components c = components_of(m);
  f.components = c.count();
  f.inward_components = count_inward_closed(c);
}

}  // namespace

double signed_volume(const Mesh& mesh) {
  if (mesh.number_of_faces() == 0) return 0.0;
  Mesh copy;
  const Mesh* m = &mesh;
  if (mesh.has_garbage()) {
    copy = mesh;
    copy.collect_garbage();
    m = &copy;
  }
  Components c = components_of(*m);
  double v = 0;
  for (double x : c.volume) v += x;
  return v;
}

RepairReport repair_mesh(Mesh& mesh, const RepairOptions& opt) {
  if (!(opt.needle_threshold >= 1.0))
    throw InvalidInputError("repair: needle_threshold must be >= 1 (got " +
                            std::to_string(opt.needle_threshold) + ")");
  if (!(opt.cap_threshold >= -1.0 && opt.cap_threshold <= 0.0))
    throw InvalidInputError("repair: cap_threshold must be in [-1, 0] (got " +
                            std::to_string(opt.cap_threshold) + ")");
  if (opt.max_hole_edges < 3)
    throw InvalidInputError("repair: max_hole_edges must be >= 3 (got " +
                            std::to_string(opt.max_hole_edges) + ")");
  if (opt.max_rounds < 1)
    throw InvalidInputError("repair: max_rounds must be >= 1 (got " +
                            std::to_string(opt.max_rounds) + ")");

  RepairReport r;
  Repairer rep(mesh, opt, r);
  rep.progress(0.0);
  rep.step("analyse", [&] {
    if (!CGAL::is_valid_polygon_mesh(mesh)) throw TopologyError("input is not a valid polygon mesh");
    analyse(mesh, opt, r.found);
  });
  rep.progress(0.1);
  if (r.found.non_triangle_faces > 0 || !CGAL::is_triangle_mesh(mesh)) {
    rep.step("triangulate_faces", [&] {
      std::vector<FaceIndex> poly;
      for (FaceIndex f : mesh.faces())
        if (!is_triangle_face(mesh, f)) poly.push_back(f);
      for (FaceIndex f : poly) {
        if (PMP::triangulate_face(f, mesh)) {
          ++r.done.faces_triangulated;
        } else if (!mesh.is_removed(f) && !is_triangle_face(mesh, f)) {
          CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
          ++r.done.untriangulable_faces_removed;
        }
      }
    });
  }
  rep.progress(0.2);
  rep.cleanup_loop();
  rep.progress(0.4);
  if (opt.fill_holes && mesh.number_of_faces() > 0) {
    rep.fill_holes();
    rep.cleanup_loop();
  }
  rep.progress(0.55);
  if (mesh.number_of_faces() > 0) rep.orient_outward();
  if (opt.keep_largest_component && mesh.number_of_faces() > 0) rep.keep_largest();
  rep.progress(0.65);
  if (opt.detect_self_intersections && mesh.number_of_faces() > 0) rep.detect_self_intersections();
  rep.progress(0.95);
  rep.validate();
  rep.progress(1.0);
  return r;
}

}  // namespace surftex
