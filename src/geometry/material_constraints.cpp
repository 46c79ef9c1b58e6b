// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/material_constraints.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "geometry/errors.h"
#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {

namespace {

using nlohmann::json;

// Hidden keys holding source lines, added to every object while parsing.
const char* const kLineKey = "\x01line";
const char* const kKeyLines = "\x01keys";

// A character iterator that records how far the parser has read, so the
// parse callback knows the current line.
struct TrackingIterator {
  using iterator_category = std::forward_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;
  const char* p = nullptr;
  const char** furthest = nullptr;
  reference operator*() const { return *p; }
  TrackingIterator& operator++() {
    ++p;
    if (p > *furthest) *furthest = p;
    return *this;
  }
  TrackingIterator operator++(int) {
    TrackingIterator t = *this;
    ++*this;
    return t;
  }
  bool operator==(const TrackingIterator& o) const { return p == o.p; }
  bool operator!=(const TrackingIterator& o) const { return p != o.p; }
};

struct Ctx {
  std::string source;
  const Mesh& mesh;
};

int line_of(const json& obj, const std::string& key = "") {
  if (!obj.is_object()) return 0;
  if (!key.empty()) {
    auto k = obj.find(kKeyLines);
    if (k != obj.end() && k->contains(key)) return (*k)[key].get<int>();
  }
  auto l = obj.find(kLineKey);
  return l != obj.end() ? l->get<int>() : 0;
}

[[noreturn]] void fail(const Ctx& c, int line, const std::string& field, const std::string& what) {
  throw InvalidInputError(c.source + ":" + std::to_string(line) + ": " + field + ": " + what);
}

void check_keys(const Ctx& c, const json& obj, const std::string& where, std::initializer_list<const char*> allowed) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    if (it.key() == kLineKey || it.key() == kKeyLines) continue;
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      fail(c, line_of(obj, it.key()), where.empty() ? it.key() : where + "." + it.key(),
           "unknown field (expected one of: " + list + ")");
    }
  }
}

std::array<double, 3> point3(const Ctx& c, const json& v, int line, const std::string& field) {
  if (!v.is_array() || v.size() != 3) fail(c, line, field, "must be an array of 3 numbers, got " + v.dump());
  std::array<double, 3> p{};
  for (int k = 0; k < 3; ++k) {
    if (!v[k].is_number() || !std::isfinite(v[k].get<double>()))
      fail(c, line, field, "must be an array of 3 finite numbers, got " + v.dump());
    p[k] = v[k].get<double>();
  }
  return p;
}

const json& array_field(const Ctx& c, const json& obj, const char* key, const std::string& where) {
  const json& v = obj.at(key);
  if (!v.is_array()) fail(c, line_of(obj, key), where, "must be an array");
  return v;
}

struct Locator {
  const Mesh& mesh;
  std::vector<VertexIndex> verts;
  double mean_edge = 0;
  explicit Locator(const Mesh& m) : mesh(m) {
    for (VertexIndex v : m.vertices()) verts.push_back(v);
    double sum = 0;
    std::size_t n = 0;
    for (EdgeIndex e : m.edges()) {
      sum += std::sqrt(CGAL::squared_distance(m.point(m.source(m.halfedge(e))), m.point(m.target(m.halfedge(e)))));
      ++n;
    }
    mean_edge = n ? sum / n : 0;
  }
  VertexIndex nearest_vertex(const std::array<double, 3>& p) const {
    const Point3 q(p[0], p[1], p[2]);
    double best = std::numeric_limits<double>::infinity();
    VertexIndex bv;
    for (VertexIndex v : verts) {
      const double d = CGAL::squared_distance(mesh.point(v), q);
      if (d < best) {
        best = d;
        bv = v;
      }
    }
    return bv;
  }
  FaceIndex nearest_face(const std::array<double, 3>& p) const {
    const VertexIndex v = nearest_vertex(p);
    const Point3 q(p[0], p[1], p[2]);
    double best = std::numeric_limits<double>::infinity();
    FaceIndex bf;
    if (mesh.halfedge(v) == Mesh::null_halfedge()) return bf;
    for (FaceIndex f : CGAL::faces_around_target(mesh.halfedge(v), mesh)) {
      if (f == Mesh::null_face()) continue;
      const auto vs = face_vertices(mesh, f);
      const Point3 cen = CGAL::centroid(mesh.point(vs[0]), mesh.point(vs[1]), mesh.point(vs[2]));
      const double d = CGAL::squared_distance(cen, q);
      if (d < best) {
        best = d;
        bf = f;
      }
    }
    return bf;
  }
};

}  // namespace

MaterialConstraints parse_material_constraints(const std::string& text, const Mesh& mesh, const std::string& source) {
  require_triangle_mesh(mesh, "material constraints");
  Ctx c{source, mesh};
  std::vector<std::size_t> line_starts{0};
  for (std::size_t i = 0; i < text.size(); ++i)
    if (text[i] == '\n') line_starts.push_back(i + 1);
  const char* furthest = text.data();
  auto current_line = [&]() {
    const std::size_t off = static_cast<std::size_t>(furthest - text.data());
    // The last character read belongs to the current token.
    const std::size_t pos = off > 0 ? off - 1 : 0;
    return static_cast<int>(std::upper_bound(line_starts.begin(), line_starts.end(), pos) - line_starts.begin());
  };
  std::vector<std::pair<int, json>> stack;  // per open object: its line and key lines
  std::string last_key;
  json::parser_callback_t cb = [&](int, json::parse_event_t ev, json& parsed) {
    switch (ev) {
      case json::parse_event_t::object_start:
        stack.push_back({current_line(), json::object()});
        break;
      case json::parse_event_t::key:
        if (!stack.empty()) stack.back().second[parsed.get<std::string>()] = current_line();
        break;
      case json::parse_event_t::object_end:
        if (!stack.empty()) {
          if (parsed.is_object()) {
            parsed[kLineKey] = stack.back().first;
            parsed[kKeyLines] = std::move(stack.back().second);
          }
          stack.pop_back();
        }
        break;
      default:
        break;
    }
    return true;
  };
  json root;
  try {
    TrackingIterator first{text.data(), &furthest}, last{text.data() + text.size(), &furthest};
    root = json::parse(first, last, cb);
  } catch (const json::parse_error& e) {
    const std::size_t pos = e.byte > 0 ? e.byte - 1 : 0;
    const auto it = std::upper_bound(line_starts.begin(), line_starts.end(), pos);
    const std::size_t line = static_cast<std::size_t>(it - line_starts.begin());
    const std::size_t col = pos - line_starts[line - 1] + 1;
    throw InvalidInputError(source + ":" + std::to_string(line) + ":" + std::to_string(col) +
                            ": malformed JSON: " + e.what());
  }
  if (!root.is_object()) fail(c, 1, "(top level)", "must be an object");
  check_keys(c, root, "", {"effect_radius", "strokes", "scale", "material"});

  MaterialConstraints out;
  const Locator loc(mesh);
  std::vector<char> face_taken(mesh.num_faces(), 0);
  std::vector<std::uint32_t> seeds;

  if (root.contains("effect_radius")) {
    const json& r = root["effect_radius"];
    if (!r.is_number() || !(r.get<double>() > 0) || !std::isfinite(r.get<double>()))
      fail(c, line_of(root, "effect_radius"), "effect_radius", "must be a finite number > 0, got " + r.dump());
    out.effect_radius = r.get<double>();
  }
  auto add_face = [&](FaceIndex f, const std::array<double, 3>& d) {
    if (face_taken[f.idx()]) return;
    face_taken[f.idx()] = 1;
    out.directions.push_back({static_cast<std::uint32_t>(f.idx()), d});
    for (VertexIndex v : face_vertices(mesh, f)) seeds.push_back(static_cast<std::uint32_t>(v.idx()));
  };
  if (root.contains("strokes")) {
    const json& strokes = array_field(c, root, "strokes", "strokes");
    for (std::size_t i = 0; i < strokes.size(); ++i) {
      const std::string where = "strokes[" + std::to_string(i) + "]";
      const json& s = strokes[i];
      if (!s.is_object()) fail(c, line_of(root, "strokes"), where, "must be an object");
      check_keys(c, s, where, {"faces", "direction", "polyline"});
      const bool has_faces = s.contains("faces"), has_poly = s.contains("polyline");
      if (has_faces == has_poly)
        fail(c, line_of(s), where, "needs exactly one of 'faces' (with 'direction') or 'polyline'");
      ++out.strokes;
      if (has_faces) {
        if (!s.contains("direction")) fail(c, line_of(s), where + ".direction", "missing (required with 'faces')");
        const std::array<double, 3> d = point3(c, s["direction"], line_of(s, "direction"), where + ".direction");
        if (d[0] == 0 && d[1] == 0 && d[2] == 0)
          fail(c, line_of(s, "direction"), where + ".direction", "must not be the zero vector");
        const json& faces = array_field(c, s, "faces", where + ".faces");
        if (faces.empty()) fail(c, line_of(s, "faces"), where + ".faces", "must not be empty");
        for (std::size_t k = 0; k < faces.size(); ++k) {
          const std::string fw = where + ".faces[" + std::to_string(k) + "]";
          if (!faces[k].is_number_integer()) fail(c, line_of(s, "faces"), fw, "must be an integer, got " + faces[k].dump());
          const long long fi = faces[k].get<long long>();
          if (fi < 0 || fi >= static_cast<long long>(mesh.num_faces()) || mesh.is_removed(FaceIndex(static_cast<std::uint32_t>(fi))))
            fail(c, line_of(s, "faces"), fw,
                 "face " + std::to_string(fi) + " out of range (" + std::to_string(mesh.number_of_faces()) + " faces)");
          add_face(FaceIndex(static_cast<std::uint32_t>(fi)), d);
        }
      } else {
        if (s.contains("direction"))
          fail(c, line_of(s, "direction"), where + ".direction", "not allowed with 'polyline' (its tangent is the direction)");
        const json& poly = array_field(c, s, "polyline", where + ".polyline");
        if (poly.size() < 2) fail(c, line_of(s, "polyline"), where + ".polyline", "needs at least 2 points");
        std::vector<std::array<double, 3>> pts;
        for (std::size_t k = 0; k < poly.size(); ++k)
          pts.push_back(point3(c, poly[k], line_of(s, "polyline"), where + ".polyline[" + std::to_string(k) + "]"));
        for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
          const std::array<double, 3> d{pts[k + 1][0] - pts[k][0], pts[k + 1][1] - pts[k][1], pts[k + 1][2] - pts[k][2]};
          const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
          if (!(len > 0))
            fail(c, line_of(s, "polyline"), where + ".polyline[" + std::to_string(k + 1) + "]",
                 "repeats the previous point (zero-length segment)");
          const int n = std::max(1, static_cast<int>(std::ceil(loc.mean_edge > 0 ? len / loc.mean_edge : 1)));
          for (int q = 0; q < n; ++q) {
            const double a = (q + 0.5) / n;
            const std::array<double, 3> p{pts[k][0] + a * d[0], pts[k][1] + a * d[1], pts[k][2] + a * d[2]};
            const FaceIndex f = loc.nearest_face(p);
            if (f != Mesh::null_face()) add_face(f, d);
          }
        }
      }
    }
  }
  auto scalars = [&](const char* key, std::vector<ScalarConstraint>& dst, double lo, double hi, const char* range) {
    if (!root.contains(key)) return;
    const json& arr = array_field(c, root, key, key);
    std::map<std::uint32_t, std::size_t> slot;
    for (std::size_t i = 0; i < arr.size(); ++i) {
      const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
      const json& e = arr[i];
      if (!e.is_object()) fail(c, line_of(root, key), where, "must be an object with 'point' and 'value'");
      check_keys(c, e, where, {"point", "value"});
      if (!e.contains("point")) fail(c, line_of(e), where + ".point", "missing");
      if (!e.contains("value")) fail(c, line_of(e), where + ".value", "missing");
      const auto p = point3(c, e["point"], line_of(e, "point"), where + ".point");
      const json& v = e["value"];
      if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi) || !std::isfinite(v.get<double>()))
        fail(c, line_of(e, "value"), where + ".value", std::string("must be a number in ") + range + ", got " + v.dump());
      if (lo == 0 && hi > 1 && !(v.get<double>() > 0))
        fail(c, line_of(e, "value"), where + ".value", std::string("must be a number in ") + range + ", got " + v.dump());
      const auto vi = static_cast<std::uint32_t>(loc.nearest_vertex(p).idx());
      seeds.push_back(vi);
      auto it = slot.find(vi);
      if (it != slot.end()) {
        dst[it->second].value = v.get<double>();
      } else {
        slot[vi] = dst.size();
        dst.push_back({vi, v.get<double>()});
      }
    }
  };
  scalars("scale", out.scale, 0, std::numeric_limits<double>::max(), "(0, inf)");
  scalars("material", out.material, 0, 1, "[0, 1]");
  std::sort(seeds.begin(), seeds.end());
  seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
  out.seed_vertices = std::move(seeds);
  return out;
}

MaterialConstraints read_material_constraints(const std::string& path, const Mesh& mesh) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IOError("cannot open constraints file '" + path + "'");
  std::stringstream buf;
  buf << in.rdbuf();
  if (in.bad()) throw IOError("cannot read constraints file '" + path + "'");
  return parse_material_constraints(buf.str(), mesh, path);
}

}  // namespace surftex
