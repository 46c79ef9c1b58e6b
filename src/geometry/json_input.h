// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Reading user JSON files (constraints, tile.json) so that no input can
// crash or stall the reader and every refusal reads
// "FILE: line L: field F: what" (issue 21 item 1):
// the size is bounded before reading, the depth while parsing (SAX, no
// recursion), overflowing numbers and malformed text refused in our words
// with line, column and field; describe() bounds value texts. Parsed objects
// carry their lines in hidden fields (is_meta_key()).

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace surftex::json_input {

struct Limits {
  /// Largest file read, in bytes. Default 16 MiB.
  std::size_t max_bytes = std::size_t(16) << 20;
  /// Deepest nesting of arrays and objects. Default 32 (the formats need 4).
  int max_depth = 32;
};

/// Reads the whole file `path` (`what` names it in messages: "constraints
/// file"). Throws IOError if it cannot be opened or read, or is larger than
/// limits.max_bytes (checked before reading).
std::string read_file(const std::string& path, const std::string& what, const Limits& limits = {});

/// Parses `text`; `source` names it in messages. Throws InvalidInputError
/// ("SOURCE: line L: field F: ...") for malformed JSON, an overflowing number
/// or nesting deeper than limits.max_depth.
nlohmann::json parse(const std::string& text, const std::string& source, const Limits& limits = {});

/// The line of object `obj`, or of its key `key` when given and present (0 = unknown).
int line_of(const nlohmann::json& obj, const std::string& key = "");
/// The line of element `i` of the array at `obj[key]` (the key's line if unknown).
int element_line(const nlohmann::json& obj, const std::string& key, std::size_t i);
/// True for the hidden fields that hold lines (skip them when listing keys).
bool is_meta_key(const std::string& key);

/// A short description of `v` for messages: a number or string as written
/// (strings cut at 40 characters), otherwise "an array of N elements" or
/// "an object". Never recursive.
std::string describe(const nlohmann::json& v);

/// Throws InvalidInputError("SOURCE: line L: field F: WHAT").
[[noreturn]] void fail(const std::string& source, int line, const std::string& field, const std::string& what);

}  // namespace surftex::json_input
