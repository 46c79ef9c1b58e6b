// SPDX-License-Identifier: AGPL-3.0-or-later
// OFF reader: [ST][C][N]OFF keyword (optional), "nv nf [ne]", nv vertex lines
// "x y z [nx ny nz] [r g b [a]] [s t]", nf face lines "n i0 .. i(n-1) [colour]".
// '#' starts a comment. 4D ("4OFF") and "OFF BINARY" are refused.
#include <algorithm>

#include "geometry/errors.h"
#include "geometry/mesh_parsers.h"

namespace surftex::mesh_io {

namespace {
bool is_integer_token(std::string_view t) {
  return t.find_first_of(".eE") == std::string_view::npos;
}
}  // namespace

PolygonSoup read_off(const std::string& path, std::string_view data) {
  TextLines lines(path, data, utf8_bom_length(data));
  std::string_view line;
  std::vector<std::string_view> tok;
  auto next_content = [&]() -> bool {
    while (lines.next(line)) {
      split_blanks(strip_comment(line), tok);
      if (!tok.empty()) return true;
    }
    return false;
  };
  if (!next_content()) fail_io(path, "", "no OFF header (only blanks and comments)");

  bool has_st = false, has_color = false, has_normal = false;
  std::size_t ti = 0;
  std::string_view kw = tok[0];
  if (kw.size() >= 3 && kw.substr(kw.size() - 3) == "OFF") {
    std::string_view pre = kw.substr(0, kw.size() - 3);
    if (pre.substr(0, 2) == "ST") {
      has_st = true;
      pre.remove_prefix(2);
    }
    for (char ch : pre) {
      if (ch == 'C') has_color = true;
      else if (ch == 'N') has_normal = true;
      else if (ch == '4' || ch == 'n')
        fail_io(path, at_line(lines.line_no()), "OFF variant " + show(kw) + " (not 3D) is not supported");
      else fail_io(path, at_line(lines.line_no()), "unknown OFF keyword " + show(kw));
    }
    ti = 1;
    if (tok.size() > 1 && tok[1] == "BINARY")
      fail_io(path, at_line(lines.line_no()), "binary OFF is not supported");
    if (tok.size() <= 1) {
      if (!next_content()) fail_io(path, at_line(lines.line_no()), "file ends before the element counts");
      ti = 0;
    }
  }
  const std::size_t count_line = lines.line_no();
  std::uint64_t nv = 0, nf = 0;
  if (tok.size() < ti + 2 || !parse_uint64(tok[ti], nv) || !parse_uint64(tok[ti + 1], nf))
    fail_io(path, at_line(count_line),
            "expected the vertex and face counts, got " + show(line));
  // Every vertex line holds at least "0 0 0\n" (6 bytes), every face line
  // "0\n" (2 bytes; faces with < 3 vertices are read, then dropped): refuse
  // counts the file cannot hold before allocating.
  const std::uint64_t rest = lines.remaining() + 1;
  if (nv > rest / 6 || nf > rest / 2 || nv * 6 + nf * 2 > rest)
    fail_io(path, at_line(count_line),
            "header claims " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                " faces, but only " + std::to_string(lines.remaining()) +
                " bytes follow (truncated file or corrupt header)");

  PolygonSoup soup;
  soup.points.reserve(nv);
  if (has_color) soup.colors.reserve(nv);
  const std::size_t need = 3 + (has_normal ? 3 : 0);
  for (std::uint64_t i = 0; i < nv; ++i) {
    if (!next_content())
      fail_io(path, at_line(lines.line_no()),
              "file ends after " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
    const std::string where = at_line(lines.line_no()) + " (vertex " + std::to_string(i) + ")";
    if (tok.size() < need)
      fail_io(path, where, "expected " + std::to_string(need) + " numbers, got " + show(line));
    std::array<double, 3> p{};
    for (int k = 0; k < 3; ++k)
      if (!parse_double(tok[k], p[k])) fail_io(path, where, "bad coordinate " + show(tok[k]));
    check_finite(path, where, p);
    soup.points.push_back(p);
    if (has_color) {
      if (tok.size() < need + 3)
        fail_io(path, where, "COFF vertex without a colour: " + show(line));
      std::array<float, 3> col{};
      bool ints = is_integer_token(tok[need]) && is_integer_token(tok[need + 1]) &&
                  is_integer_token(tok[need + 2]);
      for (int k = 0; k < 3; ++k) {
        double v = 0;
        if (!parse_double(tok[need + k], v) || !std::isfinite(v))
          fail_io(path, where, "bad colour component " + show(tok[need + k]));
        if (ints) v /= 255.0;
        col[k] = static_cast<float>(std::clamp(v, 0.0, 1.0));
      }
      soup.colors.push_back(col);
    }
  }
  (void)has_st;  // texture coordinates after the colour are not used

  soup.polygons.reserve(nf);
  for (std::uint64_t j = 0; j < nf; ++j) {
    if (!next_content())
      fail_io(path, at_line(lines.line_no()),
              "file ends after " + std::to_string(j) + " of " + std::to_string(nf) + " faces");
    const std::string where = at_line(lines.line_no()) + " (face " + std::to_string(j) + ")";
    std::uint64_t n = 0;
    if (!parse_uint64(tok[0], n)) fail_io(path, where, "bad vertex count " + show(tok[0]));
    if (n > tok.size() - 1)
      fail_io(path, where,
              "face claims " + std::to_string(n) + " vertices but lists " + std::to_string(tok.size() - 1));
    std::vector<std::size_t> poly(n);
    for (std::uint64_t k = 0; k < n; ++k) {
      std::int64_t idx = 0;
      if (!parse_int64(tok[1 + k], idx)) fail_io(path, where, "bad vertex index " + show(tok[1 + k]));
      if (idx < 0 || static_cast<std::uint64_t>(idx) >= nv)
        fail_input(path, where,
                   "vertex index " + std::to_string(idx) + " out of range [0, " + std::to_string(nv) + ")");
      poly[k] = static_cast<std::size_t>(idx);
    }
    if (n < 3) {  // validated, but bounds no area: dropped and counted
      if (soup.short_polygons_dropped++ == 0)
        soup.first_short_polygon = where + ": " + std::to_string(n) + "-vertex face";
      continue;
    }
    soup.polygons.push_back(std::move(poly));
  }
  return soup;
}

}  // namespace surftex::mesh_io
