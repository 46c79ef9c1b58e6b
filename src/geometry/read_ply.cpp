// SPDX-License-Identifier: AGPL-3.0-or-later
// PLY reader: ascii, binary_little_endian and binary_big_endian. Reads the
// vertex element's x/y/z (any numeric type) and optional red/green/blue
// (integers as 0-255, floats as 0-1), and the face element's vertex_indices /
// vertex_index list (any count and index type). Every other element and
// property is skipped. Element counts are checked against the bytes left
// before anything is allocated.
#include <algorithm>
#include <cstring>

#include "geometry/errors.h"
#include "geometry/mesh_parsers.h"

namespace surftex::mesh_io {

namespace {

enum class Type { I8, U8, I16, U16, I32, U32, F32, F64 };

bool parse_type(std::string_view s, Type& t) {
  if (s == "char" || s == "int8") t = Type::I8;
  else if (s == "uchar" || s == "uint8") t = Type::U8;
  else if (s == "short" || s == "int16") t = Type::I16;
  else if (s == "ushort" || s == "uint16") t = Type::U16;
  else if (s == "int" || s == "int32") t = Type::I32;
  else if (s == "uint" || s == "uint32") t = Type::U32;
  else if (s == "float" || s == "float32") t = Type::F32;
  else if (s == "double" || s == "float64") t = Type::F64;
  else return false;
  return true;
}

std::size_t type_size(Type t) {
  switch (t) {
    case Type::I8: case Type::U8: return 1;
    case Type::I16: case Type::U16: return 2;
    case Type::I32: case Type::U32: case Type::F32: return 4;
    case Type::F64: return 8;
  }
  return 0;
}
bool is_float(Type t) { return t == Type::F32 || t == Type::F64; }

struct Property {
  std::string name;
  Type type = Type::F32;
  bool is_list = false;
  Type count_type = Type::U8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> props;
  std::size_t header_line = 0;
};

enum class Encoding { Ascii, Little, Big };

/// A value read from the body: doubles for everything (exact for every
/// integer type up to 32 bits).
class BodyReader {
 public:
  BodyReader(const std::string& path, std::string_view data, std::size_t offset, Encoding enc,
             std::size_t first_line)
      : path_(path), data_(data), pos_(offset), enc_(enc), lines_(path, data, offset, first_line) {
    const std::uint16_t one = 1;
    unsigned char b;
    std::memcpy(&b, &one, 1);
    host_little_ = b == 1;
  }

  std::size_t remaining() const {
    return enc_ == Encoding::Ascii ? lines_.remaining() + (tok_.size() - ti_) * 2 : data_.size() - pos_;
  }
  std::size_t offset() const { return enc_ == Encoding::Ascii ? lines_.offset() : pos_; }

  /// Where the reader is, for messages.
  std::string where(const std::string& element, std::uint64_t index) const {
    std::string w = element + " " + std::to_string(index);
    if (enc_ == Encoding::Ascii) return at_line(lines_.line_no()) + " (" + w + ")";
    return w + " (byte " + std::to_string(pos_) + ")";
  }

  double read(Type t, const std::string& element, std::uint64_t index) {
    if (enc_ == Encoding::Ascii) return read_ascii(t, element, index);
    std::size_t n = type_size(t);
    if (data_.size() - pos_ < n)
      fail_io(path_, where(element, index), "file ends inside the data (truncated)");
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    if ((enc_ == Encoding::Little) != host_little_) std::reverse(b, b + n);
    switch (t) {
      case Type::I8: { std::int8_t v; std::memcpy(&v, b, 1); return v; }
      case Type::U8: return b[0];
      case Type::I16: { std::int16_t v; std::memcpy(&v, b, 2); return v; }
      case Type::U16: { std::uint16_t v; std::memcpy(&v, b, 2); return v; }
      case Type::I32: { std::int32_t v; std::memcpy(&v, b, 4); return v; }
      case Type::U32: { std::uint32_t v; std::memcpy(&v, b, 4); return v; }
      case Type::F32: { float v; std::memcpy(&v, b, 4); return v; }
      case Type::F64: { double v; std::memcpy(&v, b, 8); return v; }
    }
    return 0;
  }

 private:
  double read_ascii(Type t, const std::string& element, std::uint64_t index) {
    while (ti_ >= tok_.size()) {
      std::string_view line;
      if (!lines_.next(line)) fail_io(path_, where(element, index), "file ends inside the data (truncated)");
      split_blanks(line, tok_);
      ti_ = 0;
    }
    std::string_view s = tok_[ti_++];
    if (is_float(t)) {
      double v = 0;
      if (!parse_double(s, v)) fail_io(path_, where(element, index), "bad number " + show(s));
      return v;
    }
    std::int64_t v = 0;
    if (!parse_int64(s, v)) fail_io(path_, where(element, index), "bad integer " + show(s));
    return static_cast<double>(v);
  }

  const std::string& path_;
  std::string_view data_;
  std::size_t pos_;
  Encoding enc_;
  bool host_little_ = true;
  TextLines lines_;
  std::vector<std::string_view> tok_;
  std::size_t ti_ = 0;
};

/// The header: the body's encoding, the elements with their properties, and
/// where the body starts (byte offset and line number).
struct PlyHeader {
  Encoding enc = Encoding::Ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0, body_line = 0;
};

/// One 'property' line into the last element (throws IOError when malformed).
void parse_property(const std::string& path, const std::string& where, std::string_view line,
                    const std::vector<std::string_view>& tok, std::vector<Element>& elements) {
  if (elements.empty()) fail_io(path, where, "property before any element");
  Property p;
  if (tok.size() >= 2 && tok[1] == "list") {
    if (tok.size() < 5 || !parse_type(tok[2], p.count_type) || !parse_type(tok[3], p.type))
      fail_io(path, where, "expected 'property list COUNT_TYPE INDEX_TYPE NAME', got " + show(line));
    if (is_float(p.count_type)) fail_io(path, where, "list count type must be an integer type");
    p.is_list = true;
    p.name = std::string(tok[4]);
  } else {
    if (tok.size() < 3 || !parse_type(tok[1], p.type))
      fail_io(path, where, "expected 'property TYPE NAME', got " + show(line));
    p.name = std::string(tok[2]);
  }
  elements.back().props.push_back(std::move(p));
}

/// The header from the magic line to end_header: format, elements and their
/// properties; comments skipped. Throws IOError for anything else.
PlyHeader parse_header(const std::string& path, std::string_view data) {
  TextLines header(path, data, utf8_bom_length(data));
  std::string_view line;
  std::vector<std::string_view> tok;
  // The magic line, blanks around it allowed (an editor may leave them).
  bool magic = header.next(line);
  if (magic) {
    split_blanks(line, tok);
    magic = tok.size() == 1 && tok[0] == "ply";
  }
  if (!magic) fail_io(path, at_line(1), "not a PLY file (no 'ply' magic)");
  PlyHeader h;
  bool have_format = false, ended = false;
  while (header.next(line)) {
    const std::string where = at_line(header.line_no());
    split_blanks(line, tok);
    if (tok.empty()) continue;
    if (tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") {
      ended = true;
      break;
    }
    if (tok[0] == "format") {
      if (tok.size() < 2) fail_io(path, where, "format line without an encoding");
      if (tok[1] == "ascii") h.enc = Encoding::Ascii;
      else if (tok[1] == "binary_little_endian") h.enc = Encoding::Little;
      else if (tok[1] == "binary_big_endian") h.enc = Encoding::Big;
      else fail_io(path, where, "unknown PLY format " + show(tok[1]));
      have_format = true;
    } else if (tok[0] == "element") {
      Element e;
      if (tok.size() < 3 || !parse_uint64(tok[2], e.count))
        fail_io(path, where, "expected 'element NAME COUNT', got " + show(line));
      e.name = std::string(tok[1]);
      e.header_line = header.line_no();
      h.elements.push_back(std::move(e));
    } else if (tok[0] == "property") {
      parse_property(path, where, line, tok, h.elements);
    } else {
      fail_io(path, where, "unexpected header line " + show(line));
    }
  }
  if (!ended) fail_io(path, "", "no 'end_header' (truncated or not a PLY file)");
  if (!have_format) fail_io(path, "", "no 'format' line in the header");
  h.body_offset = header.offset();
  h.body_line = header.line_no() + 1;
  return h;
}

/// Refuses counts the rest of the file cannot hold: binary elements need at
/// least the sum of their fixed sizes (lists: the count), ascii ones two
/// bytes per value.
void check_element_counts(const std::string& path, const PlyHeader& h, std::size_t data_size) {
  const std::uint64_t body = data_size - h.body_offset;
  std::uint64_t total_min = 0;
  for (const Element& e : h.elements) {
    std::uint64_t min_bytes = 0;
    for (const Property& p : e.props)
      min_bytes += h.enc == Encoding::Ascii ? 2 : type_size(p.is_list ? p.count_type : p.type);
    if (min_bytes == 0 || e.count == 0) continue;
    if (e.count > (body + 1) / min_bytes || total_min + e.count * min_bytes > body + 1)
      fail_io(path, at_line(e.header_line),
              "header claims " + std::to_string(e.count) + " '" + e.name + "' elements, but only " +
                  std::to_string(body) + " bytes of data follow (truncated file or corrupt header)");
    total_min += e.count * min_bytes;
  }
}

/// What the body reading has gathered so far.
struct PlyBody {
  PolygonSoup soup;
  std::uint64_t nv = 0;
  bool seen_vertex = false;
  std::vector<std::string> face_where;  // ascii faces: for out-of-range messages
};

/// The properties of an element that surftex reads (-1: absent): x/y/z and
/// colour of the first vertex element, the index list of a face element.
struct ElementRoles {
  bool is_vertex = false, is_face = false, colors = false;
  int ix = -1, iy = -1, iz = -1, ir = -1, ig = -1, ib = -1, ilist = -1;
};

ElementRoles element_roles(const Element& e, bool seen_vertex) {
  ElementRoles r;
  r.is_vertex = e.name == "vertex" && !seen_vertex;
  r.is_face = e.name == "face";
  for (std::size_t k = 0; k < e.props.size(); ++k) {
    const Property& p = e.props[k];
    const int ki = static_cast<int>(k);
    if (r.is_vertex && !p.is_list) {
      if (p.name == "x") r.ix = ki;
      else if (p.name == "y") r.iy = ki;
      else if (p.name == "z") r.iz = ki;
      else if (p.name == "red" || p.name == "diffuse_red") r.ir = ki;
      else if (p.name == "green" || p.name == "diffuse_green") r.ig = ki;
      else if (p.name == "blue" || p.name == "diffuse_blue") r.ib = ki;
    }
    if (r.is_face && p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index") && r.ilist < 0)
      r.ilist = ki;
  }
  r.colors = r.is_vertex && r.ir >= 0 && r.ig >= 0 && r.ib >= 0;
  return r;
}

/// List property k of item i: its length checked against the bytes left;
/// the face list kept as a polygon (a face of fewer than 3 vertices dropped
/// and counted), any other list skipped.
void read_list(const std::string& path, const Element& e, std::size_t k, std::uint64_t i, Encoding enc,
               const ElementRoles& r, BodyReader& in, PlyBody& b) {
  const Property& p = e.props[k];
  PolygonSoup& soup = b.soup;
  const std::string where_count = in.where(e.name, i);
  double cnt = in.read(p.count_type, e.name, i);
  if (cnt < 0) fail_io(path, where_count, "negative list length " + std::to_string(cnt));
  const std::uint64_t n = static_cast<std::uint64_t>(cnt);
  const std::size_t item = enc == Encoding::Ascii ? 2 : type_size(p.type);
  if (n > in.remaining() / item + 1)
    fail_io(path, where_count,
            "list of " + std::to_string(n) + " values does not fit in the " +
                std::to_string(in.remaining()) + " bytes left (truncated or corrupt)");
  if (static_cast<int>(k) != r.ilist) {
    for (std::uint64_t m = 0; m < n; ++m) in.read(p.type, e.name, i);
    return;
  }
  std::vector<std::size_t> poly(n);
  for (std::uint64_t m = 0; m < n; ++m) {
    double v = in.read(p.type, e.name, i);
    if (!(v >= 0) || v != std::floor(v) || v >= 18446744073709551616.0)
      fail_input(path, where_count, "vertex index " + std::to_string(v) + " is negative or not an integer");
    poly[m] = static_cast<std::size_t>(v);
  }
  if (n < 3) {  // bounds no area: dropped and counted (indices checked below only for kept faces)
    for (std::size_t v : poly)
      if (v >= b.nv)
        fail_input(path, where_count, "vertex index " + std::to_string(v) + " out of range");
    if (soup.short_polygons_dropped++ == 0)
      soup.first_short_polygon = where_count + ": " + std::to_string(n) + "-vertex face";
    return;
  }
  soup.polygons.push_back(std::move(poly));
  if (enc == Encoding::Ascii) b.face_where.push_back(where_count);
}

/// Vertex i from its scalar properties: the position (finite) and the colour
/// if any (integers as 0-255, floats as 0-1, clamped).
void append_vertex(const std::string& path, const Element& e, std::uint64_t i, const std::vector<double>& scalar,
                   const ElementRoles& r, BodyReader& in, PolygonSoup& soup) {
  std::array<double, 3> pt{scalar[r.ix], scalar[r.iy], scalar[r.iz]};
  check_finite(path, in.where(e.name, i), pt);
  soup.points.push_back(pt);
  if (!r.colors) return;
  std::array<float, 3> c{};
  const int idx[3] = {r.ir, r.ig, r.ib};
  for (int q = 0; q < 3; ++q) {
    double v = scalar[idx[q]];
    if (!std::isfinite(v)) fail_input(path, in.where(e.name, i), "colour component is not finite");
    if (!is_float(e.props[idx[q]].type)) v /= 255.0;
    c[q] = static_cast<float>(std::clamp(v, 0.0, 1.0));
  }
  soup.colors.push_back(c);
}

/// Every item of one element, in order: the vertices and faces kept, the
/// rest read past.
void read_element(const std::string& path, const Element& e, Encoding enc, BodyReader& in, PlyBody& b) {
  const ElementRoles r = element_roles(e, b.seen_vertex);
  PolygonSoup& soup = b.soup;
  if (r.is_vertex) {
    if (r.ix < 0 || r.iy < 0 || r.iz < 0)
      fail_io(path, at_line(e.header_line), "vertex element lacks an x, y or z property");
    b.seen_vertex = true;
    b.nv = e.count;
    soup.points.reserve(e.count);
  }
  if (r.colors) soup.colors.reserve(e.count);
  if (r.is_face && r.ilist < 0)
    fail_io(path, at_line(e.header_line), "face element has no vertex_indices list");
  if (r.is_face) soup.polygons.reserve(soup.polygons.size() + e.count);

  std::vector<double> scalar(e.props.size(), 0.0);
  for (std::uint64_t i = 0; i < e.count; ++i) {
    for (std::size_t k = 0; k < e.props.size(); ++k) {
      const Property& p = e.props[k];
      if (!p.is_list)
        scalar[k] = in.read(p.type, e.name, i);
      else
        read_list(path, e, k, i, enc, r, in, b);
    }
    if (r.is_vertex) append_vertex(path, e, i, scalar, r, in, soup);
  }
}

}  // namespace

PolygonSoup read_ply(const std::string& path, std::string_view data) {
  const PlyHeader h = parse_header(path, data);
  check_element_counts(path, h, data.size());
  PlyBody b;
  BodyReader in(path, data, h.body_offset, h.enc, h.body_line);
  for (const Element& e : h.elements) {
    if (e.props.empty()) continue;
    read_element(path, e, h.enc, in, b);
  }
  if (!b.seen_vertex) fail_io(path, "", "no vertex element");
  for (std::size_t j = 0; j < b.soup.polygons.size(); ++j)
    for (std::size_t v : b.soup.polygons[j])
      if (v >= b.nv)
        fail_input(path, j < b.face_where.size() ? b.face_where[j] : "face " + std::to_string(j),
                   "vertex index " + std::to_string(v) + " out of range [0, " + std::to_string(b.nv) + ")");
  return std::move(b.soup);
}

}  // namespace surftex::mesh_io
