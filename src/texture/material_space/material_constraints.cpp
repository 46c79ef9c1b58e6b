// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/material_constraints.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <nanoflann.hpp>
#include <nlohmann/json.hpp>

#include "geometry/errors.h"
#include "geometry/json_input.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

namespace {

using nlohmann::json;
namespace ji = json_input;

struct Ctx {
  std::string source;
  const Mesh& mesh;
};

[[noreturn]] void fail(const Ctx& c, int line, const std::string& field, const std::string& what) {
  ji::fail(c.source, line, field, what);
}

void check_keys(const Ctx& c, const json& obj, const std::string& where, std::initializer_list<const char*> allowed) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    if (ji::is_meta_key(it.key())) continue;
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      std::string key = it.key().size() > 40 ? it.key().substr(0, 40) + "..." : it.key();
      fail(c, ji::line_of(obj, it.key()), where.empty() ? key : where + "." + key,
           "unknown field (expected one of: " + list + ")");
    }
  }
}

const json& array_field(const Ctx& c, const json& obj, const char* key, const std::string& where) {
  const json& v = obj.at(key);
  if (!v.is_array()) fail(c, ji::line_of(obj, key), where, "must be an array, got " + ji::describe(v));
  return v;
}

// The mesh's frame: every point the file gives is checked against the mesh's
// box and taken to unit coordinates (u = (p - centre) / half-size) before any
// arithmetic, so that no distance can overflow whatever the mesh's or the
// file's magnitudes (issue 21: a point at 1e200 overflowed a squared
// distance and crashed).
struct Frame {
  std::array<double, 3> centre{}, lo{}, hi{};
  double half = 1;  // half the box's largest side (> 0)
  // A point may lie at most this many half-sizes from the centre on any axis:
  // the box and one box size around it.
  static constexpr double kReach = 3.0;

  explicit Frame(const Mesh& m) {
    lo = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
    hi = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (VertexIndex v : m.vertices())
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], m.point(v)[k]);
        hi[k] = std::max(hi[k], m.point(v)[k]);
      }
    double h = 0;
    for (int k = 0; k < 3; ++k) {
      if (!(lo[k] <= hi[k])) lo[k] = hi[k] = 0;
      centre[k] = lo[k] / 2 + hi[k] / 2;  // halves: no overflow near the double range
      h = std::max(h, hi[k] / 2 - lo[k] / 2);
    }
    half = h > 0 && std::isfinite(h) ? h : 1;
  }
  std::array<double, 3> unit(const Point3& p) const {
    return {(p.x() / 2 - centre[0] / 2) / (half / 2), (p.y() / 2 - centre[1] / 2) / (half / 2),
            (p.z() / 2 - centre[2] / 2) / (half / 2)};
  }
  // The unit coordinates of a file's point, or an error if it is far outside the mesh.
  std::array<double, 3> unit_checked(const Ctx& c, const std::array<double, 3>& p, int line,
                                     const std::string& field) const {
    std::array<double, 3> u{};
    for (int k = 0; k < 3; ++k) {
      u[k] = (p[k] / 2 - centre[k] / 2) / (half / 2);
      if (!(std::fabs(u[k]) <= kReach)) {
        char b[160];
        std::snprintf(b, sizeof b, "coordinate %.6g is far outside the mesh (its box spans %.6g..%.6g on that axis; ",
                      p[k], lo[k], hi[k]);
        fail(c, line, field, std::string(b) + "points must lie within one box size of it)");
      }
    }
    return u;
  }
};

std::array<double, 3> numbers3(const Ctx& c, const json& v, int line, const std::string& field) {
  if (!v.is_array() || v.size() != 3) fail(c, line, field, "must be an array of 3 numbers, got " + ji::describe(v));
  std::array<double, 3> p{};
  for (std::size_t k = 0; k < 3; ++k) {
    if (!v[k].is_number() || !std::isfinite(v[k].get<double>()))
      fail(c, line, field + "[" + std::to_string(k) + "]", "must be a finite number, got " + ji::describe(v[k]));
    p[k] = v[k].get<double>();
  }
  return p;
}

// A direction scaled to unit length without squaring large components.
std::array<double, 3> unit_direction(std::array<double, 3> d) {
  const double m = std::max({std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2])});
  if (!(m > 0)) return {0, 0, 0};
  for (double& x : d) x /= m;
  const double l = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  for (double& x : d) x /= l;
  return d;
}

// Nearest vertex and face in the mesh's unit frame (kd-tree: O(log V) a query).
struct Locator {
  struct Cloud {
    std::vector<std::array<double, 3>> pts;
    std::size_t kdtree_get_point_count() const { return pts.size(); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const { return pts[i][d]; }
    template <class B>
    bool kdtree_get_bbox(B&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3>;

  const Mesh& mesh;
  Cloud cloud;
  std::vector<VertexIndex> verts;
  std::unique_ptr<Tree> tree;
  double mean_edge = 0;  // in unit coordinates

  Locator(const Mesh& m, const Frame& fr) : mesh(m) {
    for (VertexIndex v : m.vertices()) {
      verts.push_back(v);
      cloud.pts.push_back(fr.unit(m.point(v)));
    }
    std::vector<std::array<double, 3>> at(m.num_vertices());
    for (std::size_t i = 0; i < verts.size(); ++i) at[verts[i].idx()] = cloud.pts[i];
    double sum = 0;
    std::size_t n = 0;
    for (EdgeIndex e : m.edges()) {
      const auto& a = at[m.source(m.halfedge(e)).idx()];
      const auto& b = at[m.target(m.halfedge(e)).idx()];
      sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
      ++n;
    }
    mean_edge = n ? sum / n : 0;
    if (!verts.empty()) {
      tree = std::make_unique<Tree>(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));  // builds the index
    }
  }
  VertexIndex nearest_vertex(const std::array<double, 3>& u) const {
    if (!tree) return VertexIndex();
    std::size_t idx = 0;
    double d2 = 0;
    nanoflann::KNNResultSet<double> rs(1);
    rs.init(&idx, &d2);
    tree->findNeighbors(rs, u.data(), nanoflann::SearchParams());
    return verts[idx];
  }
  FaceIndex nearest_face(const std::array<double, 3>& u, const Frame& fr) const {
    const VertexIndex v = nearest_vertex(u);
    double best = std::numeric_limits<double>::infinity();
    FaceIndex bf;
    if (v == VertexIndex() || mesh.halfedge(v) == Mesh::null_halfedge()) return bf;
    for (FaceIndex f : CGAL::faces_around_target(mesh.halfedge(v), mesh)) {
      if (f == Mesh::null_face()) continue;
      double d = 0;
      std::array<double, 3> cen{0, 0, 0};
      for (VertexIndex w : face_vertices(mesh, f)) {
        const auto p = fr.unit(mesh.point(w));
        for (int k = 0; k < 3; ++k) cen[k] += p[k] / 3;
      }
      for (int k = 0; k < 3; ++k) d += (cen[k] - u[k]) * (cen[k] - u[k]);
      if (d < best) {
        best = d;
        bf = f;
      }
    }
    return bf;
  }
};

struct Parser {
  Parser(const Ctx& ctx, const Frame& fr, const Locator& lc)
      : c(ctx), frame(fr), loc(lc), face_taken(ctx.mesh.num_faces(), 0) {}
  const Ctx& c;
  const Frame& frame;
  const Locator& loc;
  MaterialConstraints out;
  std::vector<char> face_taken;
  std::vector<std::uint32_t> seeds;

  // True if `d` has a part in the plane of face f (the direction field
  // projects it there and refuses a direction normal to the face).
  bool tangent_to(FaceIndex f, const std::array<double, 3>& d) const {
    const Vector3 n = robust_face_normal(c.mesh, f);
    const double dn = d[0] * n.x() + d[1] * n.y() + d[2] * n.z();
    const double t2 = (d[0] - dn * n.x()) * (d[0] - dn * n.x()) + (d[1] - dn * n.y()) * (d[1] - dn * n.y()) +
                      (d[2] - dn * n.z()) * (d[2] - dn * n.z());
    return t2 > 1e-12;  // d is a unit vector
  }

  void add_face(FaceIndex f, const std::array<double, 3>& d) {
    if (face_taken[f.idx()]) return;
    face_taken[f.idx()] = 1;
    out.directions.push_back({static_cast<std::uint32_t>(f.idx()), d});
    for (VertexIndex v : face_vertices(c.mesh, f)) seeds.push_back(static_cast<std::uint32_t>(v.idx()));
  }

  void face_stroke(const json& s, const std::string& where) {
    if (!s.contains("direction")) fail(c, ji::line_of(s), where + ".direction", "missing (required with 'faces')");
    const std::array<double, 3> d = unit_direction(numbers3(c, s["direction"], ji::line_of(s, "direction"), where + ".direction"));
    if (d[0] == 0 && d[1] == 0 && d[2] == 0)
      fail(c, ji::line_of(s, "direction"), where + ".direction", "must not be the zero vector");
    const json& faces = array_field(c, s, "faces", where + ".faces");
    if (faces.empty()) fail(c, ji::line_of(s, "faces"), where + ".faces", "must not be empty");
    const Mesh& mesh = c.mesh;
    for (std::size_t k = 0; k < faces.size(); ++k) {
      const std::string fw = where + ".faces[" + std::to_string(k) + "]";
      const int line = ji::element_line(s, "faces", k);
      if (!faces[k].is_number_integer()) fail(c, line, fw, "must be an integer, got " + ji::describe(faces[k]));
      const bool neg = faces[k].is_number_integer() && !faces[k].is_number_unsigned() && faces[k].get<long long>() < 0;
      const unsigned long long fi = neg ? 0 : faces[k].get<unsigned long long>();
      if (neg || fi >= mesh.num_faces() || mesh.is_removed(FaceIndex(static_cast<std::uint32_t>(fi))))
        fail(c, line, fw,
             "face " + ji::describe(faces[k]) + " out of range (" + std::to_string(mesh.number_of_faces()) + " faces)");
      if (!tangent_to(FaceIndex(static_cast<std::uint32_t>(fi)), d))
        fail(c, ji::line_of(s, "direction"), where + ".direction",
             "is normal to face " + std::to_string(fi) + " (it needs a part along the surface)");
      add_face(FaceIndex(static_cast<std::uint32_t>(fi)), d);
    }
  }

  // Polylines in unit coordinates, checked; sampled once every stroke is read.
  std::vector<std::vector<std::array<double, 3>>> polylines;

  void polyline_stroke(const json& s, const std::string& where) {
    if (s.contains("direction"))
      fail(c, ji::line_of(s, "direction"), where + ".direction", "not allowed with 'polyline' (its tangent is the direction)");
    const json& poly = array_field(c, s, "polyline", where + ".polyline");
    if (poly.size() < 2) fail(c, ji::line_of(s, "polyline"), where + ".polyline", "needs at least 2 points");
    std::vector<std::array<double, 3>> pts;
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const std::string pw = where + ".polyline[" + std::to_string(k) + "]";
      const int line = ji::element_line(s, "polyline", k);
      pts.push_back(frame.unit_checked(c, numbers3(c, poly[k], line, pw), line, pw));
      if (k > 0 && pts[k] == pts[k - 1]) fail(c, line, pw, "repeats the previous point (zero-length segment)");
    }
    polylines.push_back(std::move(pts));
  }

  // Samples every polyline: about one sample per mean edge length, and in
  // all at most two samples per face plus one per segment, however long the
  // strokes are (the work is bounded by the mesh, not by the file).
  void sample_polylines() {
    double total = 0;
    std::size_t segments = 0;
    auto length = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
      return std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    };
    for (const auto& pts : polylines)
      for (std::size_t k = 0; k + 1 < pts.size(); ++k) total += length(pts[k], pts[k + 1]), ++segments;
    const double budget = 2.0 * static_cast<double>(c.mesh.number_of_faces()) + 1;
    const double spacing = std::max(loc.mean_edge, total / budget);
    for (const auto& pts : polylines)
      for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
        const double len = length(pts[k], pts[k + 1]);
        const std::array<double, 3> d{pts[k + 1][0] - pts[k][0], pts[k + 1][1] - pts[k][1], pts[k + 1][2] - pts[k][2]};
        const std::array<double, 3> t = unit_direction(d);
        const int n = static_cast<int>(std::min(budget, std::max(1.0, std::ceil(spacing > 0 ? len / spacing : 1))));
        for (int q = 0; q < n; ++q) {
          const double a = (q + 0.5) / n;
          const std::array<double, 3> p{pts[k][0] + a * d[0], pts[k][1] + a * d[1], pts[k][2] + a * d[2]};
          const FaceIndex f = loc.nearest_face(p, frame);
          // A stroke crossing the surface straight through gives that face no direction.
          if (f != Mesh::null_face() && tangent_to(f, t)) add_face(f, t);
        }
      }
  }

  void strokes(const json& root) {
    const json& strokes = array_field(c, root, "strokes", "strokes");
    for (std::size_t i = 0; i < strokes.size(); ++i) {
      const std::string where = "strokes[" + std::to_string(i) + "]";
      const json& s = strokes[i];
      if (!s.is_object()) fail(c, ji::element_line(root, "strokes", i), where, "must be an object, got " + ji::describe(s));
      check_keys(c, s, where, {"faces", "direction", "polyline"});
      const bool has_faces = s.contains("faces"), has_poly = s.contains("polyline");
      if (has_faces == has_poly)
        fail(c, ji::line_of(s), where, "needs exactly one of 'faces' (with 'direction') or 'polyline'");
      ++out.strokes;
      if (has_faces) face_stroke(s, where);
      else polyline_stroke(s, where);
    }
    sample_polylines();
  }

  void scalars(const json& root, const char* key, std::vector<ScalarConstraint>& dst, double lo, double hi,
               bool open_lo, const std::string& range) {
    if (!root.contains(key)) return;
    const json& arr = array_field(c, root, key, key);
    std::map<std::uint32_t, std::size_t> slot;
    for (std::size_t i = 0; i < arr.size(); ++i) {
      const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
      const json& e = arr[i];
      if (!e.is_object())
        fail(c, ji::element_line(root, key, i), where, "must be an object with 'point' and 'value', got " + ji::describe(e));
      check_keys(c, e, where, {"point", "value"});
      if (!e.contains("point")) fail(c, ji::line_of(e), where + ".point", "missing");
      if (!e.contains("value")) fail(c, ji::line_of(e), where + ".value", "missing");
      const int pl = ji::line_of(e, "point");
      const auto u = frame.unit_checked(c, numbers3(c, e["point"], pl, where + ".point"), pl, where + ".point");
      const json& v = e["value"];
      const double x = v.is_number() ? v.get<double>() : std::nan("");
      if (!v.is_number() || !std::isfinite(x) || !(open_lo ? x > lo : x >= lo) || !(x <= hi))
        fail(c, ji::line_of(e, "value"), where + ".value", "must be a number in " + range + ", got " + ji::describe(v));
      const VertexIndex nv = loc.nearest_vertex(u);
      if (nv == VertexIndex()) fail(c, pl, where + ".point", "the mesh has no vertex");
      const auto vi = static_cast<std::uint32_t>(nv.idx());
      seeds.push_back(vi);
      auto it = slot.find(vi);
      if (it != slot.end()) {
        dst[it->second].value = x;
      } else {
        slot[vi] = dst.size();
        dst.push_back({vi, x});
      }
    }
  }
};

// The texture period a scale point may ask for, relative to the mesh's size:
// 1e-6 to 1e6 times half the box's largest side.
constexpr double kScaleRange = 1e6;

}  // namespace

MaterialConstraints parse_material_constraints(const std::string& text, const Mesh& mesh, const std::string& source) {
  require_triangle_mesh(mesh, "material constraints");
  const Ctx c{source, mesh};
  const json root = ji::parse(text, source);
  if (!root.is_object()) fail(c, 1, "(top level)", "must be an object, got " + ji::describe(root));
  check_keys(c, root, "", {"effect_radius", "strokes", "scale", "material"});

  const Frame frame(mesh);
  const Locator loc(mesh, frame);
  Parser p(c, frame, loc);

  if (root.contains("effect_radius")) {
    const json& r = root["effect_radius"];
    if (!r.is_number() || !(r.get<double>() > 0) || !std::isfinite(r.get<double>()))
      fail(c, ji::line_of(root, "effect_radius"), "effect_radius", "must be a finite number > 0, got " + ji::describe(r));
    p.out.effect_radius = r.get<double>();
  }
  if (root.contains("strokes")) p.strokes(root);
  char range[96];
  const double slo = frame.half / kScaleRange, shi = frame.half * kScaleRange;
  std::snprintf(range, sizeof range, "[%.3g, %.3g] (1e-6 to 1e6 times the mesh's half-size)", slo, shi);
  p.scalars(root, "scale", p.out.scale, slo, shi, false, range);
  p.scalars(root, "material", p.out.material, 0, 1, false, "[0, 1]");
  std::sort(p.seeds.begin(), p.seeds.end());
  p.seeds.erase(std::unique(p.seeds.begin(), p.seeds.end()), p.seeds.end());
  p.out.seed_vertices = std::move(p.seeds);
  return std::move(p.out);
}

MaterialConstraints read_material_constraints(const std::string& path, const Mesh& mesh) {
  return parse_material_constraints(json_input::read_file(path, "constraints file"), mesh, path);
}

}  // namespace surftex
