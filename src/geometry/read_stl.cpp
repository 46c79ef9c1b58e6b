// SPDX-License-Identifier: AGPL-3.0-or-later
// STL reader. Binary when the file size is exactly 84 + 50 n, n being the
// little-endian triangle count at byte 80 (many binary files start with
// "solid" too, so the prefix decides nothing); otherwise ascii
// ("solid / facet normal / outer loop / vertex x y z ... / endloop /
// endfacet / endsolid", several solids allowed). Corners are welded on exactly
// equal positions (-0 == +0).
#include <cstring>
#include <unordered_map>

#include "geometry/errors.h"
#include "geometry/mesh_parsers.h"

namespace surftex::mesh_io {

namespace {

class Welder {
 public:
  explicit Welder(PolygonSoup& soup) : soup_(soup) {}
  std::size_t add(const std::array<double, 3>& p) {
    auto [it, inserted] = index_.emplace(canonical_position(p), soup_.points.size());
    if (inserted) soup_.points.push_back(p);
    return it->second;
  }

 private:
  PolygonSoup& soup_;
  std::unordered_map<std::array<double, 3>, std::size_t, PositionHash> index_;
};

float read_f32_le(const unsigned char* b) {
  std::uint32_t u = static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
                    static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

PolygonSoup read_binary(const std::string& path, std::string_view data) {
  const auto* b = reinterpret_cast<const unsigned char*>(data.data());
  const std::uint32_t n = static_cast<std::uint32_t>(b[80]) | static_cast<std::uint32_t>(b[81]) << 8 |
                          static_cast<std::uint32_t>(b[82]) << 16 | static_cast<std::uint32_t>(b[83]) << 24;
  PolygonSoup soup;
  soup.polygons.reserve(n);  // n is bounded by the file size (checked by the caller)
  Welder weld(soup);
  for (std::uint32_t t = 0; t < n; ++t) {
    const unsigned char* f = b + 84 + 50 * static_cast<std::size_t>(t) + 12;  // skip the normal
    std::vector<std::size_t> tri(3);
    for (int k = 0; k < 3; ++k) {
      std::array<double, 3> p{read_f32_le(f + 12 * k), read_f32_le(f + 12 * k + 4), read_f32_le(f + 12 * k + 8)};
      check_finite(path, "triangle " + std::to_string(t) + " (byte " + std::to_string(84 + 50 * std::size_t(t)) + ")", p);
      tri[k] = weld.add(p);
    }
    soup.polygons.push_back(std::move(tri));
  }
  return soup;
}

PolygonSoup read_ascii(const std::string& path, std::string_view data) {
  PolygonSoup soup;
  Welder weld(soup);
  TextLines lines(path, data, utf8_bom_length(data));
  std::string_view line;
  std::vector<std::string_view> tok;
  bool in_solid = false, in_facet = false, in_loop = false;
  std::size_t loop_line = 0;
  std::vector<std::size_t> loop;
  while (lines.next(line)) {
    split_blanks(line, tok);
    if (tok.empty()) continue;
    const std::string where = at_line(lines.line_no());
    const std::string_view kw = tok[0];
    if (kw == "solid") {
      if (in_solid) fail_io(path, where, "'solid' inside a solid");
      in_solid = true;
    } else if (kw == "endsolid") {
      if (!in_solid || in_facet) fail_io(path, where, "unexpected 'endsolid'");
      in_solid = false;
    } else if (kw == "facet") {
      if (!in_solid || in_facet) fail_io(path, where, "unexpected 'facet'");
      in_facet = true;
    } else if (kw == "outer") {
      if (!in_facet || in_loop) fail_io(path, where, "unexpected 'outer loop'");
      in_loop = true;
      loop_line = lines.line_no();
      loop.clear();
    } else if (kw == "vertex") {
      if (!in_loop) fail_io(path, where, "'vertex' outside an 'outer loop'");
      if (tok.size() < 4) fail_io(path, where, "vertex needs 3 coordinates: " + show(line));
      std::array<double, 3> p{};
      for (int k = 0; k < 3; ++k)
        if (!parse_double(tok[1 + k], p[k])) fail_io(path, where, "bad coordinate " + show(tok[1 + k]));
      check_finite(path, where, p);
      loop.push_back(weld.add(p));
    } else if (kw == "endloop") {
      if (!in_loop) fail_io(path, where, "unexpected 'endloop'");
      if (loop.size() < 3)
        fail_io(path, at_line(loop_line),
                "facet has " + std::to_string(loop.size()) + " vertices (at least 3 needed)");
      soup.polygons.push_back(loop);
      in_loop = false;
    } else if (kw == "endfacet") {
      if (!in_facet || in_loop) fail_io(path, where, "unexpected 'endfacet'");
      in_facet = false;
    } else {
      fail_io(path, where, "unexpected " + show(kw) + " in ascii STL");
    }
  }
  if (in_facet || in_loop || in_solid)
    fail_io(path, at_line(lines.line_no()),
            std::string("file ends inside a ") + (in_solid && !in_facet ? "solid (no 'endsolid')" : "facet") +
                " (truncated)");
  return soup;
}

}  // namespace

PolygonSoup read_stl(const std::string& path, std::string_view data) {
  if (looks_like_binary_stl(data)) return read_binary(path, data);
  std::size_t i = utf8_bom_length(data);
  while (i < data.size() && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r' || data[i] == '\n')) ++i;
  // "solid" and no NUL byte: ascii. With NUL bytes it is a binary file whose
  // header happens to start with "solid" and whose size is wrong.
  if (data.substr(i, 5) == "solid" && std::memchr(data.data(), '\0', data.size()) == nullptr)
    return read_ascii(path, data);
  if (data.size() < 84)
    fail_io(path, "", "too short for a binary STL (" + std::to_string(data.size()) +
                          " bytes) and no ascii 'solid' header");
  const auto* b = reinterpret_cast<const unsigned char*>(data.data() + 80);
  const std::uint64_t n = static_cast<std::uint64_t>(b[0]) | static_cast<std::uint64_t>(b[1]) << 8 |
                          static_cast<std::uint64_t>(b[2]) << 16 | static_cast<std::uint64_t>(b[3]) << 24;
  fail_io(path, "", "binary STL header claims " + std::to_string(n) + " triangles (" +
                        std::to_string(84 + 50 * n) + " bytes) but the file has " +
                        std::to_string(data.size()) + " bytes (truncated or corrupt)");
}

}  // namespace surftex::mesh_io
