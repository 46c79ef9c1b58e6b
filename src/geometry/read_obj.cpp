// SPDX-License-Identifier: AGPL-3.0-or-later
// OBJ reader: "v x y z [w]" or "v x y z r g b" (colours), "vt u [v [w]]",
// "f a b c ..." with corners "v", "v/vt", "v//vn", "v/vt/vn" (1-based, or
// negative = relative to the elements defined so far). Lines ending in '\'
// continue on the next. `mtllib` names are kept (soup.material_libraries,
// read by read_mtl.cpp) and `usemtl` sets the material of the faces that
// follow (soup.polygon_material). vn, vp, l, p, o, g, s and unknown keywords
// are ignored.
#include <algorithm>

#include "geometry/errors.h"
#include "geometry/mesh_parsers.h"

namespace surftex::mesh_io {

namespace {

/// Resolves an OBJ index (1-based, or negative relative) against `count`
/// elements defined so far.
std::size_t resolve(const std::string& path, const std::string& where, std::string_view tok,
                    std::size_t count, const char* what) {
  std::int64_t i = 0;
  if (!parse_int64(tok, i)) fail_io(path, where, std::string("bad ") + what + " index " + show(tok));
  if (i == 0) fail_input(path, where, std::string(what) + " index 0 (OBJ indices start at 1)");
  std::int64_t r = i > 0 ? i - 1 : static_cast<std::int64_t>(count) + i;
  if (r < 0 || static_cast<std::uint64_t>(r) >= count)
    fail_input(path, where,
               std::string(what) + " index " + std::to_string(i) + " out of range (" +
                   std::to_string(count) + " defined so far)");
  return static_cast<std::size_t>(r);
}

/// What the reader carries from line to line.
struct ObjState {
  bool all_colored = true;        // every vertex so far had a colour
  std::size_t faces_with_uv = 0;  // faces with a uv on every corner
  std::vector<std::size_t> poly, puv;  // the current face's corners (reused)
  int material = -1;              // usemtl in force, index into soup.materials
};

/// The next logical line (comment stripped; lines ending in '\' joined with
/// the next into `joined`); false at the end of the file. `raw` is its first
/// physical line, `line_no` that line's number.
bool next_logical_line(TextLines& lines, std::string_view& raw, std::size_t& line_no, std::string& joined,
                       std::string_view& line) {
  if (!lines.next(raw)) return false;
  line_no = lines.line_no();
  line = strip_comment(raw);
  if (!line.empty() && line.back() == '\\') {
    joined.assign(line.substr(0, line.size() - 1));
    std::string_view more;
    while (lines.next(more)) {
      std::string_view m = strip_comment(more);
      bool cont = !m.empty() && m.back() == '\\';
      joined += ' ';
      joined.append(cont ? m.substr(0, m.size() - 1) : m);
      if (!cont) break;
    }
    line = joined;
  }
  return true;
}

/// "v x y z [w]" or "v x y z r g b": the position (finite), and the colour
/// while every vertex so far had one.
void read_vertex(const std::string& path, const std::string& where, const std::vector<std::string_view>& tok,
                 std::string_view raw, PolygonSoup& soup, ObjState& st) {
  if (tok.size() < 4) fail_io(path, where, "vertex needs 3 coordinates: " + show(raw));
  std::array<double, 3> p{};
  for (int k = 0; k < 3; ++k)
    if (!parse_double(tok[1 + k], p[k])) fail_io(path, where, "bad coordinate " + show(tok[1 + k]));
  check_finite(path, where, p);
  soup.points.push_back(p);
  if (tok.size() >= 7 && st.all_colored) {
    std::array<float, 3> col{};
    for (int k = 0; k < 3; ++k) {
      double v = 0;
      if (!parse_double(tok[4 + k], v) || !std::isfinite(v))
        fail_io(path, where, "bad colour component " + show(tok[4 + k]));
      col[k] = static_cast<float>(std::clamp(v, 0.0, 1.0));
    }
    soup.colors.push_back(col);
  } else {
    st.all_colored = false;
  }
}

/// "vt u [v [w]]": the (u, v) pair (finite).
void read_uv(const std::string& path, const std::string& where, const std::vector<std::string_view>& tok,
             PolygonSoup& soup) {
  if (tok.size() < 2) fail_io(path, where, "texture coordinate without values");
  std::array<double, 3> uv{0.0, 0.0, 0.0};
  for (std::size_t k = 0; k < 2 && 1 + k < tok.size(); ++k)
    if (!parse_double(tok[1 + k], uv[k])) fail_io(path, where, "bad texture coordinate " + show(tok[1 + k]));
  check_finite(path, where, uv);
  soup.uvs.push_back({uv[0], uv[1]});
}

/// "f a b c ...": corners "v", "v/vt", "v//vn", "v/vt/vn" resolved against
/// the elements defined so far; the face kept with the material in force and
/// its uvs if every corner has one (a face of fewer than 3 corners dropped
/// and counted).
void read_face(const std::string& path, const std::string& where, const std::vector<std::string_view>& tok,
               std::string_view raw, PolygonSoup& soup, ObjState& st) {
  std::vector<std::size_t>& poly = st.poly;
  std::vector<std::size_t>& puv = st.puv;
  poly.clear();
  puv.clear();
  bool uv_complete = true;
  for (std::size_t k = 1; k < tok.size(); ++k) {
    std::string_view c = tok[k];
    std::size_t s1 = c.find('/');
    std::string_view vpart = c.substr(0, s1);
    poly.push_back(resolve(path, where, vpart, soup.points.size(), "vertex"));
    std::string_view tpart;
    if (s1 != std::string_view::npos) {
      std::string_view rest = c.substr(s1 + 1);
      std::size_t s2 = rest.find('/');
      tpart = rest.substr(0, s2);
      if (s2 != std::string_view::npos && rest.substr(s2 + 1).find('/') != std::string_view::npos)
        fail_io(path, where, "bad face corner " + show(c));
    }
    if (tpart.empty()) uv_complete = false;
    else puv.push_back(resolve(path, where, tpart, soup.uvs.size(), "texture coordinate"));
  }
  if (poly.size() < 3) {  // validated, but bounds no area: dropped and counted
    if (soup.short_polygons_dropped++ == 0)
      soup.first_short_polygon = where + ": " + std::to_string(poly.size()) + "-vertex face " + show(raw);
    return;
  }
  soup.polygons.push_back(poly);
  soup.polygon_material.push_back(st.material);
  if (uv_complete) {
    if (soup.polygon_uvs.size() < soup.polygons.size() - 1) soup.polygon_uvs.resize(soup.polygons.size() - 1);
    soup.polygon_uvs.push_back(puv);
    ++st.faces_with_uv;
  } else if (!soup.polygon_uvs.empty()) {
    soup.polygon_uvs.emplace_back();
  }
}

/// "mtllib NAME" (kept for read_mtl) or "usemtl NAME" (the material of the
/// faces that follow, added on first use); names may hold blanks.
void read_material_line(std::string_view kw, std::string_view line, PolygonSoup& soup, ObjState& st) {
  std::string_view rest = line.substr(line.find(kw) + kw.size());
  while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
  while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t' || rest.back() == '\r')) rest.remove_suffix(1);
  if (kw == "mtllib") {
    if (!rest.empty()) soup.material_libraries.emplace_back(rest);
    return;
  }
  const std::string name(rest);
  auto it = std::find_if(soup.materials.begin(), soup.materials.end(),
                         [&](const MeshMaterial& m) { return m.name == name; });
  st.material = static_cast<int>(it - soup.materials.begin());
  if (it == soup.materials.end()) {
    soup.materials.emplace_back();
    soup.materials.back().name = name;
  }
}

}  // namespace

PolygonSoup read_obj(const std::string& path, std::string_view data) {
  PolygonSoup soup;
  TextLines lines(path, data, utf8_bom_length(data));
  std::string_view raw, line;
  std::size_t line_no = 0;
  std::string joined;  // for continued lines
  std::vector<std::string_view> tok;
  ObjState st;
  while (next_logical_line(lines, raw, line_no, joined, line)) {
    split_blanks(line, tok);
    if (tok.empty()) continue;
    const std::string_view kw = tok[0];
    if (kw == "v")
      read_vertex(path, at_line(line_no), tok, raw, soup, st);
    else if (kw == "vt")
      read_uv(path, at_line(line_no), tok, soup);
    else if (kw == "f")
      read_face(path, at_line(line_no), tok, raw, soup, st);
    else if (kw == "mtllib" || kw == "usemtl")
      read_material_line(kw, line, soup, st);
    // vn, vp, l, p, o, g, s, ...: not needed here.
  }
  // Attributes only when complete: colours on every vertex, uvs on some face.
  if (soup.materials.empty()) soup.polygon_material.clear();
  if (!st.all_colored || soup.colors.size() != soup.points.size()) soup.colors.clear();
  if (st.faces_with_uv == 0) {
    soup.uvs.clear();
    soup.polygon_uvs.clear();
  } else {
    soup.polygon_uvs.resize(soup.polygons.size());
  }
  return soup;
}

}  // namespace surftex::mesh_io
