// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Private to the mesh readers (read_mesh.cpp, read_off.cpp, read_obj.cpp,
// read_ply.cpp, read_stl.cpp): the per-format parsers and the small defensive
// text/number helpers they share. Not part of the public API.
//
// Every parser takes the whole file in memory (`data`) and the path (for
// messages), and returns a PolygonSoup whose indices are already validated
// against its points. Errors: IOError for malformed/truncated content,
// InvalidInputError for non-finite coordinates and bad indices; every message
// names the file and the line (text) or element and byte offset (binary).

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "geometry/read_mesh.h"

namespace surftex::mesh_io {

PolygonSoup read_off(const std::string& path, std::string_view data);
PolygonSoup read_obj(const std::string& path, std::string_view data);
PolygonSoup read_ply(const std::string& path, std::string_view data);
PolygonSoup read_stl(const std::string& path, std::string_view data);
/// glTF 2.0: `binary` = GLB container, else the JSON text of a .gltf.
PolygonSoup read_gltf(const std::string& path, std::string_view data, bool binary);
/// Reads the .mtl files an OBJ soup names (soup.material_libraries, relative to
/// the OBJ's folder) into soup.materials (read_mtl.cpp).
void read_obj_materials(const std::string& obj_path, PolygonSoup& soup);

/// Length of a UTF-8 byte-order mark at the start of `data` (3 or 0). Text
/// readers skip it (an editor on Windows may add one); without this the BOM
/// glued to the first keyword made an OBJ's first `v` line an unknown
/// keyword and shifted every face index (issue 21).
inline std::size_t utf8_bom_length(std::string_view data) {
  return data.substr(0, 3) == std::string_view("\xEF\xBB\xBF", 3) ? 3 : 0;
}

/// True if the 84-byte header's triangle count matches the file size exactly.
bool looks_like_binary_stl(std::string_view data);

/// "'path' line 12: msg" and friends.
[[noreturn]] void fail_io(const std::string& path, const std::string& where, const std::string& msg);
[[noreturn]] void fail_input(const std::string& path, const std::string& where, const std::string& msg);
std::string at_line(std::size_t line);

/// A printable, length-limited rendering of a token for error messages.
std::string show(std::string_view token);

/// Lines of a text buffer, 1-based line numbers, "\r\n" and "\n" endings. A NUL
/// byte in a line is an IOError (binary data in a text format).
class TextLines {
 public:
  TextLines(const std::string& path, std::string_view data, std::size_t offset = 0,
            std::size_t first_line = 1)
      : path_(path), data_(data), pos_(offset), next_line_(first_line) {}
  /// The next line (without its ending); false at the end of the buffer.
  bool next(std::string_view& line);
  /// Number of the line last returned.
  std::size_t line_no() const { return line_; }
  /// Offset of the first byte not yet consumed.
  std::size_t offset() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }

 private:
  const std::string& path_;
  std::string_view data_;
  std::size_t pos_;
  std::size_t next_line_;
  std::size_t line_ = 0;
};

/// Splits on blanks (space, tab, \v, \f, \r) into `out` (cleared first).
void split_blanks(std::string_view line, std::vector<std::string_view>& out);
/// Cuts `line` at the first '#'.
std::string_view strip_comment(std::string_view line);

/// Whole-token parses (the entire token must be consumed; a leading '+' is
/// accepted). parse_double accepts "nan"/"inf" so that callers can report
/// them precisely; out-of-range magnitudes become +-inf.
bool parse_double(std::string_view tok, double& v);
bool parse_int64(std::string_view tok, std::int64_t& v);
bool parse_uint64(std::string_view tok, std::uint64_t& v);

/// Throws InvalidInputError if any coordinate is NaN or infinite.
void check_finite(const std::string& path, const std::string& where, const std::array<double, 3>& p);

/// Exact-position key (with -0 folded onto +0) for welding and for mapping
/// attributes through repair.
struct PositionHash {
  std::size_t operator()(const std::array<double, 3>& p) const noexcept;
};
inline std::array<double, 3> canonical_position(std::array<double, 3> p) {
  for (double& c : p)
    if (c == 0.0) c = 0.0;  // -0 -> +0
  return p;
}

}  // namespace surftex::mesh_io
