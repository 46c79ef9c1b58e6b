// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/json_input.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "geometry/errors.h"

namespace surftex::json_input {

namespace {

using nlohmann::json;

const char* const kLine = "\x01line";
const char* const kKeyLines = "\x01keys";
const char* const kElemLines = "\x01elems";

// A character iterator that records how far the parser has read, so that
// the handler knows the current line.
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

std::string show_token(const std::string& t) {
  std::string out;
  for (char c : t) {
    if (out.size() >= 40) {
      out += "...";
      break;
    }
    const unsigned char u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02X", u);
      out += b;
    }
  }
  return out;
}

// Builds the DOM with line annotations; stops at the depth limit.
class Builder {
 public:
  Builder(const std::string& text, const char** furthest, int max_depth)
      : text_(text), furthest_(furthest), max_depth_(max_depth) {
    line_starts_.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i)
      if (text[i] == '\n') line_starts_.push_back(i + 1);
  }

  json root;
  std::string error;  // set when the handler stopped the parse
  int error_line = 0;
  std::string error_field;

  bool null() { return value(json(nullptr)); }
  bool boolean(bool v) { return value(json(v)); }
  bool number_integer(json::number_integer_t v) { return value(json(v)); }
  bool number_unsigned(json::number_unsigned_t v) { return value(json(v)); }
  bool number_float(json::number_float_t v, const std::string&) { return value(json(v)); }
  bool string(std::string& v) { return value(json(std::move(v))); }
  bool binary(json::binary_t&) { return stop(current_line(), "binary values are not JSON"); }
  bool start_object(std::size_t) { return open(json::object()); }
  bool start_array(std::size_t) { return open(json::array()); }
  bool key(std::string& k) {
    Frame& f = frames_.back();
    f.key = k;
    f.key_lines[k] = current_line();
    return true;
  }
  bool end_object() { return close(); }
  bool end_array() { return close(); }
  bool parse_error(std::size_t, const std::string& last_token, const nlohmann::detail::exception& ex) {
    if (!error.empty()) return false;  // our own stop
    const int line = current_line();
    if (ex.id == 406)
      return stop(line, "number " + show_token(last_token) + " is out of range (beyond +-1.8e308)");
    if (last_token.empty() || furthest_pos() >= text_.size())
      return stop(line, "malformed JSON: the file ends before the value is complete");
    const std::size_t at = furthest_pos() > 0 ? furthest_pos() - 1 : 0;
    return stop(line, "malformed JSON: unexpected '" + show_token(text_.substr(at, 1)) + "'");
  }

  std::size_t furthest_pos() const { return static_cast<std::size_t>(*furthest_ - text_.data()); }
  int current_line() const {
    const std::size_t off = furthest_pos();
    const std::size_t pos = off > 0 ? off - 1 : 0;
    return static_cast<int>(std::upper_bound(line_starts_.begin(), line_starts_.end(), pos) - line_starts_.begin());
  }
  int column(int line) const {
    const std::size_t off = furthest_pos();
    const std::size_t pos = off > 0 ? off - 1 : 0;
    return static_cast<int>(pos - line_starts_[static_cast<std::size_t>(line - 1)] + 1);
  }

 private:
  struct Frame {
    json* node;
    int line;
    std::string key;        // objects: the key being read
    json key_lines = json::object();
    json elem_lines = json::object();  // objects: per array-valued key, its element lines
    std::vector<int> lines;            // arrays: each element's line
  };

  std::string path() const {
    std::string p;
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      const Frame& f = frames_[i];
      if (f.node->is_object()) {
        if (!f.key.empty()) p += (p.empty() ? "" : ".") + f.key;
      } else {
        // An enclosing array's last element is the open child; the innermost
        // array is at its next element.
        const std::size_t n = f.node->size();
        p += "[" + std::to_string(i + 1 < frames_.size() && n > 0 ? n - 1 : n) + "]";
      }
    }
    return p.empty() ? "(top level)" : p;
  }

  bool stop(int line, const std::string& what) {
    error = what;
    error_line = line;
    error_field = path();
    return false;
  }

  json* place(json v) {
    if (frames_.empty()) {
      root = std::move(v);
      return &root;
    }
    Frame& f = frames_.back();
    if (f.node->is_object()) return &((*f.node)[f.key] = std::move(v));
    f.lines.push_back(current_line());
    f.node->push_back(std::move(v));
    return &f.node->back();
  }
  bool value(json v) {
    place(std::move(v));
    return true;
  }
  bool open(json v) {
    if (static_cast<int>(frames_.size()) >= max_depth_)
      return stop(current_line(), "nested deeper than " + std::to_string(max_depth_) + " levels");
    const int line = current_line();
    json* n = place(std::move(v));
    frames_.push_back({n, line, {}, json::object(), json::object(), {}});
    return true;
  }
  bool close() {
    Frame f = std::move(frames_.back());
    frames_.pop_back();
    if (f.node->is_object()) {
      (*f.node)[kLine] = f.line;
      (*f.node)[kKeyLines] = std::move(f.key_lines);
      if (!f.elem_lines.empty()) (*f.node)[kElemLines] = std::move(f.elem_lines);
    } else if (!frames_.empty() && frames_.back().node->is_object()) {
      frames_.back().elem_lines[frames_.back().key] = f.lines;
    }
    return true;
  }

  const std::string& text_;
  const char** furthest_;
  int max_depth_;
  std::vector<std::size_t> line_starts_;
  std::vector<Frame> frames_;
};

}  // namespace

std::string read_file(const std::string& path, const std::string& what, const Limits& limits) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw IOError("cannot open " + what + " '" + path + "'");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw IOError("cannot read " + what + " '" + path + "'");
  if (size > limits.max_bytes)
    throw IOError(what + " '" + path + "' is " + std::to_string(size) + " bytes, more than the " +
                  std::to_string(limits.max_bytes) + " a JSON input may have");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IOError("cannot open " + what + " '" + path + "'");
  std::string text(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !in.read(text.data(), static_cast<std::streamsize>(size)))
    throw IOError("cannot read " + what + " '" + path + "'");
  return text;
}

json parse(const std::string& text, const std::string& source, const Limits& limits) {
  if (text.size() > limits.max_bytes)
    throw InvalidInputError(source + ": " + std::to_string(text.size()) + " bytes, more than the " +
                            std::to_string(limits.max_bytes) + " a JSON input may have");
  const char* furthest = text.data();
  Builder b(text, &furthest, limits.max_depth);
  TrackingIterator first{text.data(), &furthest}, last{text.data() + text.size(), &furthest};
  bool ok = false;
  try {
    ok = json::sax_parse(first, last, &b);
  } catch (const json::exception&) {
    ok = false;  // the handler records every error; this is a safety net
  }
  if (!ok) {
    const int line = b.error.empty() ? b.current_line() : b.error_line;
    const std::string what = b.error.empty() ? "malformed JSON" : b.error;
    throw InvalidInputError(source + ": line " + std::to_string(line) + ": field " +
                            (b.error_field.empty() ? "(top level)" : b.error_field) + ": " + what + " (column " +
                            std::to_string(b.column(line)) + ")");
  }
  return std::move(b.root);
}

int line_of(const json& obj, const std::string& key) {
  if (!obj.is_object()) return 0;
  if (!key.empty()) {
    auto k = obj.find(kKeyLines);
    if (k != obj.end() && k->is_object()) {
      auto l = k->find(key);
      if (l != k->end() && l->is_number_integer()) return l->get<int>();
    }
  }
  auto l = obj.find(kLine);
  return l != obj.end() && l->is_number_integer() ? l->get<int>() : 0;
}

int element_line(const json& obj, const std::string& key, std::size_t i) {
  if (obj.is_object()) {
    auto e = obj.find(kElemLines);
    if (e != obj.end() && e->is_object()) {
      auto a = e->find(key);
      if (a != e->end() && a->is_array() && i < a->size() && (*a)[i].is_number_integer()) return (*a)[i].get<int>();
    }
  }
  return line_of(obj, key);
}

bool is_meta_key(const std::string& key) { return key == kLine || key == kKeyLines || key == kElemLines; }

std::string describe(const json& v) {
  switch (v.type()) {
    case json::value_t::array: return "an array of " + std::to_string(v.size()) + " elements";
    case json::value_t::object: return "an object";
    case json::value_t::string: {
      const std::string& s = v.get_ref<const std::string&>();
      return "\"" + show_token(s) + "\"";
    }
    case json::value_t::null: return "null";
    case json::value_t::boolean: return v.get<bool>() ? "true" : "false";
    case json::value_t::number_float: {
      char b[40];
      std::snprintf(b, sizeof b, "%.17g", v.get<double>());
      return b;
    }
    case json::value_t::number_integer: return std::to_string(v.get<long long>());
    case json::value_t::number_unsigned: return std::to_string(v.get<unsigned long long>());
    default: return "a value";
  }
}

void fail(const std::string& source, int line, const std::string& field, const std::string& what) {
  throw InvalidInputError(source + ": line " + std::to_string(line) + ": field " + field + ": " + what);
}

}  // namespace surftex::json_input
