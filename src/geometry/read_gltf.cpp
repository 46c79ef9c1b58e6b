// SPDX-License-Identifier: AGPL-3.0-or-later
// glTF 2.0 reader (.glb and .gltf), after the Khronos glTF 2.0 specification:
// the GLB container (section 4.4) and the JSON are checked here before
// tinygltf 2.7 parses them (its GLB and image-view checks leave gaps: a BIN
// chunk may run 8 bytes past the file, an image view past its buffer), then
// every accessor is bounds-checked against its buffer view and buffer before
// a byte is read.
//
// What is read: the triangles (modes TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN;
// points and lines are skipped with a warning) of every mesh instance in the
// default scene (scene 0 if none is named; every root node if there are no
// scenes), with the node transforms applied (matrix or T * R * S; a negative
// determinant flips the winding, section 3.7.4); POSITION (float), indices
// (unsigned byte/short/int), the TEXCOORD_n the material's base-colour texture
// uses (float or normalised unsigned byte/short; v flipped to surftex's
// bottom-left origin), COLOR_0 (RGB or RGBA, float or normalised; alpha
// dropped), sparse accessors; materials (name, baseColorFactor RGB,
// baseColorTexture from a buffer view, a data: URI or a file beside the
// .gltf). Required extensions other than KHR_materials_* are refused.
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "geometry/errors.h"
#include "geometry/mesh_parsers.h"

namespace fs = std::filesystem;

namespace surftex::mesh_io {

namespace {

constexpr std::uint32_t kChunkJson = 0x4E4F534A, kChunkBin = 0x004E4942;
// An accessor without a buffer view is all zeros (plus sparse values): bound
// what such a file may make us allocate.
constexpr std::size_t kMaxViewlessElements = std::size_t(1) << 26;
constexpr std::uintmax_t kMaxExternalFile = std::uintmax_t(1) << 31;

std::uint32_t le32(std::string_view d, std::size_t off) {
  const auto* b = reinterpret_cast<const unsigned char*>(d.data() + off);
  return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
}

struct GlbChunks {
  std::string_view json;
  bool has_bin = false;
  std::uint64_t bin_length = 0;
};

// Section 4.4: 12-byte header (magic, version 2, length = file size), a JSON
// chunk, then optionally a BIN chunk; every chunk within the file.
GlbChunks check_glb_container(const std::string& path, std::string_view d) {
  const std::string size = std::to_string(d.size()) + " bytes";
  if (d.size() < 12) fail_io(path, "", "truncated GLB: " + size + ", the header alone needs 12");
  if (d.substr(0, 4) != "glTF") fail_io(path, "", "not a GLB file (no 'glTF' magic)");
  if (le32(d, 4) != 2) fail_io(path, "", "GLB version " + std::to_string(le32(d, 4)) + " (only glTF 2.0 is read)");
  const std::uint64_t length = le32(d, 8);
  if (length != d.size())
    fail_io(path, "", (length > d.size() ? "truncated GLB: the header says " : "the GLB header says ") +
                          std::to_string(length) + " bytes, the file has " + size);
  if (length < 20) fail_io(path, "", "truncated GLB: no JSON chunk");
  const std::uint64_t json_length = le32(d, 12);
  if (le32(d, 16) != kChunkJson) fail_io(path, "byte 16", "the first GLB chunk is not JSON");
  if (20 + json_length > length)
    fail_io(path, "byte 12", "truncated GLB: the JSON chunk of " + std::to_string(json_length) +
                                 " bytes runs past the end of the file");
  GlbChunks c;
  c.json = d.substr(20, static_cast<std::size_t>(json_length));
  const std::uint64_t bin_at = 20 + json_length;
  if (bin_at < length) {
    if (bin_at + 8 > length) fail_io(path, "byte " + std::to_string(bin_at), "truncated GLB chunk header");
    c.bin_length = le32(d, static_cast<std::size_t>(bin_at));
    if (bin_at + 8 + c.bin_length > length)
      fail_io(path, "byte " + std::to_string(bin_at),
              "truncated GLB: the BIN chunk of " + std::to_string(c.bin_length) + " bytes runs past the end of the file");
    c.has_bin = le32(d, static_cast<std::size_t>(bin_at + 4)) == kChunkBin;
  }
  return c;
}

std::uint64_t json_uint(const nlohmann::json& o, const char* key, std::uint64_t dflt) {
  if (!o.contains(key)) return dflt;
  const auto& v = o[key];
  if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0))
    throw std::runtime_error(std::string("\"") + key + "\" is not a non-negative integer");
  return v.get<std::uint64_t>();
}

// The deepest nesting of arrays and objects in a JSON text (strings skipped):
// tinygltf converts "extras" and "extensions" recursively.
std::size_t json_depth(std::string_view t) {
  std::size_t depth = 0, deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const char c = t[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// What tinygltf 2.7 relies on without checking: buffer views inside their
// buffers, GLB buffer 0 inside the BIN chunk, image views inside range.
void check_json(const std::string& path, std::string_view text, const GlbChunks* glb) {
  if (text.size() > (std::size_t(1) << 31)) fail_io(path, "", "the glTF JSON is larger than 2 GiB");
  if (json_depth(text) > 128) fail_io(path, "", "the glTF JSON nests deeper than 128 levels");
  nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded()) fail_io(path, "", "the glTF JSON does not parse");
  if (!j.is_object()) fail_io(path, "", "the glTF JSON is not an object");
  try {
    std::vector<std::uint64_t> buffer_length;
    if (j.contains("buffers")) {
      if (!j["buffers"].is_array()) throw std::runtime_error("\"buffers\" is not an array");
      for (std::size_t b = 0; b < j["buffers"].size(); ++b) {
        const auto& buf = j["buffers"][b];
        if (!buf.is_object()) throw std::runtime_error("buffers[" + std::to_string(b) + "] is not an object");
        buffer_length.push_back(json_uint(buf, "byteLength", 0));
        if (glb && !buf.contains("uri")) {
          if (b != 0) throw std::runtime_error("buffers[" + std::to_string(b) + "] has no uri (only buffer 0 may use the BIN chunk)");
          if (!glb->has_bin) throw std::runtime_error("buffers[0] refers to a BIN chunk the file does not have");
          if (buffer_length[b] > glb->bin_length)
            throw std::runtime_error("buffers[0] is " + std::to_string(buffer_length[b]) + " bytes, the BIN chunk " +
                                     std::to_string(glb->bin_length));
        }
      }
    }
    std::vector<std::uint64_t> view_length;
    if (j.contains("bufferViews")) {
      if (!j["bufferViews"].is_array()) throw std::runtime_error("\"bufferViews\" is not an array");
      for (std::size_t v = 0; v < j["bufferViews"].size(); ++v) {
        const auto& bv = j["bufferViews"][v];
        const std::string name = "bufferViews[" + std::to_string(v) + "]";
        if (!bv.is_object()) throw std::runtime_error(name + " is not an object");
        const std::uint64_t b = json_uint(bv, "buffer", std::numeric_limits<std::uint64_t>::max());
        if (b >= buffer_length.size()) throw std::runtime_error(name + " names a buffer that does not exist");
        const std::uint64_t off = json_uint(bv, "byteOffset", 0), len = json_uint(bv, "byteLength", 0);
        if (off > buffer_length[b] || len > buffer_length[b] - off)
          throw std::runtime_error(name + " (bytes " + std::to_string(off) + " + " + std::to_string(len) +
                                   ") runs past buffer " + std::to_string(b) + " (" + std::to_string(buffer_length[b]) + " bytes)");
        view_length.push_back(len);
      }
    }
    if (j.contains("images") && j["images"].is_array())
      for (std::size_t i = 0; i < j["images"].size(); ++i) {
        const auto& im = j["images"][i];
        if (!im.is_object() || !im.contains("bufferView")) continue;
        const std::uint64_t v = json_uint(im, "bufferView", 0);
        if (v >= view_length.size() || view_length[v] == 0)
          throw std::runtime_error("images[" + std::to_string(i) + "] names an empty or missing buffer view");
      }
  } catch (const std::exception& e) {
    fail_io(path, "", std::string("invalid glTF: ") + e.what());
  }
}

// tinygltf's file callbacks, replaced: no shell expansion of URIs (its
// default runs wordexp on them), regular files only, bounded size, and a note
// of every file read.
struct FileLog {
  std::vector<std::string>* files;
};

std::string existing_path(const std::string& p) {
  std::error_code ec;
  if (fs::is_regular_file(p, ec)) return p;
  // URIs are percent-encoded (a blank is %20).
  std::string d;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p[i] == '%' && i + 2 < p.size() && std::isxdigit(static_cast<unsigned char>(p[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(p[i + 2]))) {
      d += static_cast<char>(std::stoi(p.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      d += p[i];
    }
  }
  return fs::is_regular_file(d, ec) ? d : std::string();
}

bool file_exists(const std::string& p, void*) { return !existing_path(p).empty(); }
std::string expand_path(const std::string& p, void*) { return p; }
bool read_whole(std::vector<unsigned char>* out, std::string* err, const std::string& p, void* user) {
  const std::string f = existing_path(p);
  std::error_code ec;
  if (f.empty() || fs::file_size(f, ec) > kMaxExternalFile) {
    if (err) *err += "'" + p + "' does not exist, is not a regular file or is larger than 2 GiB\n";
    return false;
  }
  std::ifstream in(f, std::ios::binary);
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) {
    if (err) *err += "cannot read '" + p + "'\n";
    return false;
  }
  static_cast<FileLog*>(user)->files->push_back(f);
  return true;
}
bool refuse_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

// Images stay encoded (decoded later by OpenImageIO, load_material_textures).
bool keep_encoded(tinygltf::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                  int size, void*) {
  image->image.assign(bytes, bytes + std::max(size, 0));
  image->as_is = true;
  return true;
}

tinygltf::Model load_model(const std::string& path, std::string_view data, bool binary,
                           std::vector<std::string>& files_read) {
  GlbChunks glb;
  if (binary) glb = check_glb_container(path, data);
  check_json(path, binary ? glb.json : data, binary ? &glb : nullptr);
  tinygltf::TinyGLTF loader;
  FileLog log{&files_read};
  loader.SetFsCallbacks({&file_exists, &expand_path, &read_whole, &refuse_write, &log});
  loader.SetImageLoader(&keep_encoded, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const std::string base = fs::path(path).parent_path().string();
  const bool ok =
      binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(data.data()),
                                           static_cast<unsigned int>(data.size()), base)
             : loader.LoadASCIIFromString(&model, &err, &warn, data.data(), static_cast<unsigned int>(data.size()), base);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    fail_io(path, "", "invalid glTF: " + (err.empty() ? std::string("tinygltf refused it") : err));
  }
  for (const std::string& e : model.extensionsRequired)
    if (e.rfind("KHR_materials_", 0) != 0)
      fail_io(path, "", "requires the glTF extension " + e + ", which surftex does not read");
  return model;
}

// ------------------------------------------------------------------ accessors
std::size_t component_size(int type) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
  }
}

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
  }
}

// One component at p, as a double; normalised integers map to [0,1] / [-1,1]
// (section 3.11).
double component(const unsigned char* p, int type, bool normalized) {
  switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const double v = static_cast<std::int8_t>(p[0]);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
  }
}

/// count x components values of an accessor.
struct Values {
  std::size_t count = 0;
  int components = 0;
  std::vector<double> v;
  double at(std::size_t i, int c) const { return v[i * components + c]; }
};

class AccessorReader {
 public:
  AccessorReader(const std::string& path, const tinygltf::Model& m) : path_(path), m_(m) {}

  /// Accessor `index` (its role, e.g. "POSITION", for messages); `types` and
  /// `components` list what the role allows.
  Values read(int index, const std::string& role, std::initializer_list<int> types,
              std::initializer_list<int> components) const {
    const std::string what = "accessor " + std::to_string(index) + " (" + role + ")";
    if (index < 0 || static_cast<std::size_t>(index) >= m_.accessors.size())
      fail_io(path_, "", what + " does not exist (" + std::to_string(m_.accessors.size()) + " accessors)");
    const tinygltf::Accessor& a = m_.accessors[static_cast<std::size_t>(index)];
    if (std::find(types.begin(), types.end(), a.type) == types.end())
      fail_io(path_, "", what + " has an element type " + std::to_string(a.type) + " this attribute cannot have");
    if (std::find(components.begin(), components.end(), a.componentType) == components.end())
      fail_io(path_, "", what + " has component type " + std::to_string(a.componentType) +
                             ", which surftex does not read for this attribute");
    Values out;
    out.count = a.count;
    out.components = type_components(a.type);
    const std::size_t elem = component_size(a.componentType) * static_cast<std::size_t>(out.components);
    if (a.bufferView >= 0) {
      const Span s = view_span(a.bufferView, a.byteOffset, elem, a.count, what);
      out.v.resize(a.count * static_cast<std::size_t>(out.components));
      for (std::size_t i = 0; i < a.count; ++i)
        for (int c = 0; c < out.components; ++c)
          out.v[i * out.components + c] =
              component(s.data + i * s.stride + c * component_size(a.componentType), a.componentType, a.normalized);
    } else {
      if (a.count > kMaxViewlessElements)
        fail_io(path_, "", what + " has " + std::to_string(a.count) + " elements and no data: refused");
      out.v.assign(a.count * static_cast<std::size_t>(out.components), 0.0);
    }
    if (a.sparse.isSparse) apply_sparse(a, elem, out, what);
    return out;
  }

 private:
  struct Span {
    const unsigned char* data;
    std::size_t stride;
  };

  // `count` elements of `elem` bytes at `offset` in view `view`, checked.
  Span view_span(int view, std::size_t offset, std::size_t elem, std::size_t count, const std::string& what,
                 bool tight = false) const {
    if (view < 0 || static_cast<std::size_t>(view) >= m_.bufferViews.size())
      fail_io(path_, "", what + ": buffer view " + std::to_string(view) + " does not exist");
    const tinygltf::BufferView& bv = m_.bufferViews[static_cast<std::size_t>(view)];
    if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= m_.buffers.size())
      fail_io(path_, "", what + ": buffer " + std::to_string(bv.buffer) + " does not exist");
    const std::vector<unsigned char>& buf = m_.buffers[static_cast<std::size_t>(bv.buffer)].data;
    if (bv.byteOffset > buf.size() || bv.byteLength > buf.size() - bv.byteOffset)
      fail_io(path_, "", what + ": buffer view " + std::to_string(view) + " runs past its buffer");
    const std::size_t stride = (tight || bv.byteStride == 0) ? elem : bv.byteStride;
    if (stride < elem) fail_io(path_, "", what + ": byteStride " + std::to_string(stride) + " is less than an element");
    if (count > 0 && (offset > bv.byteLength || elem > bv.byteLength - offset ||
                      (count - 1) > (bv.byteLength - offset - elem) / stride))
      fail_io(path_, "", what + ": " + std::to_string(count) + " elements of " + std::to_string(elem) +
                             " bytes (stride " + std::to_string(stride) + ") from byte " + std::to_string(offset) +
                             " run past buffer view " + std::to_string(view) + " (" + std::to_string(bv.byteLength) +
                             " bytes)");
    return {buf.data() + bv.byteOffset + offset, stride};
  }

  // Section 3.6.2.3: the listed elements replace those of the base accessor.
  void apply_sparse(const tinygltf::Accessor& a, std::size_t elem, Values& out, const std::string& what) const {
    const auto& sp = a.sparse;
    if (sp.count < 1 || static_cast<std::size_t>(sp.count) > a.count)
      fail_io(path_, "", what + ": sparse count " + std::to_string(sp.count) + " out of range");
    const int it = sp.indices.componentType;
    if (it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        it != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
      fail_io(path_, "", what + ": sparse indices must be unsigned integers");
    const std::size_t n = static_cast<std::size_t>(sp.count);
    const Span idx = view_span(sp.indices.bufferView, static_cast<std::size_t>(std::max(sp.indices.byteOffset, 0)),
                               component_size(it), n, what + " sparse indices", true);
    const Span val = view_span(sp.values.bufferView, static_cast<std::size_t>(std::max(sp.values.byteOffset, 0)), elem,
                               n, what + " sparse values", true);
    const std::size_t cs = component_size(a.componentType);
    for (std::size_t k = 0; k < n; ++k) {
      const double target = component(idx.data + k * idx.stride, it, false);
      if (!(target < static_cast<double>(a.count)))
        fail_io(path_, "", what + ": sparse index " + std::to_string(target) + " out of range");
      const std::size_t t = static_cast<std::size_t>(target);
      for (int c = 0; c < out.components; ++c)
        out.v[t * out.components + c] = component(val.data + k * val.stride + c * cs, a.componentType, a.normalized);
    }
  }

  const std::string& path_;
  const tinygltf::Model& m_;
};

// ------------------------------------------------------------------ scene
using Mat4 = std::array<double, 16>;  // column-major, as glTF

Mat4 identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  return r;
}

// Section 3.7.3: `matrix`, or T * R * S (rotation a unit quaternion x, y, z, w).
Mat4 local_transform(const std::string& path, const tinygltf::Node& n, std::size_t index) {
  Mat4 m = identity();
  if (n.matrix.size() == 16) {
    std::copy(n.matrix.begin(), n.matrix.end(), m.begin());
  } else {
    std::array<double, 3> t{0, 0, 0}, s{1, 1, 1};
    std::array<double, 4> q{0, 0, 0, 1};
    if (n.translation.size() == 3) std::copy(n.translation.begin(), n.translation.end(), t.begin());
    if (n.scale.size() == 3) std::copy(n.scale.begin(), n.scale.end(), s.begin());
    if (n.rotation.size() == 4) std::copy(n.rotation.begin(), n.rotation.end(), q.begin());
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const std::array<double, 9> r{1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),
                                  2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),
                                  2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y)};
    for (int c = 0; c < 3; ++c)
      for (int row = 0; row < 3; ++row) m[c * 4 + row] = r[c * 3 + row] * s[c];
    m[12] = t[0], m[13] = t[1], m[14] = t[2];
  }
  for (double v : m)
    if (!std::isfinite(v)) fail_input(path, "", "node " + std::to_string(index) + " has a non-finite transform");
  return m;
}

double det3(const Mat4& m) {
  return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
         m[8] * (m[1] * m[6] - m[5] * m[2]);
}

struct Instance {
  int mesh;
  Mat4 world;
};

// Depth-first over the hierarchy below `root` (an explicit stack: a file may
// nest nodes deeply).
void visit(const std::string& path, const tinygltf::Model& m, int root, std::vector<char>& seen,
           std::vector<Instance>& out) {
  std::vector<std::pair<int, Mat4>> stack{{root, identity()}};
  while (!stack.empty()) {
    const auto [node, parent] = stack.back();
    stack.pop_back();
    if (node < 0 || static_cast<std::size_t>(node) >= m.nodes.size())
      fail_io(path, "", "node " + std::to_string(node) + " does not exist");
    if (seen[static_cast<std::size_t>(node)])
      fail_io(path, "", "node " + std::to_string(node) + " appears twice in the node hierarchy (it must be a tree)");
    seen[static_cast<std::size_t>(node)] = 1;
    const tinygltf::Node& n = m.nodes[static_cast<std::size_t>(node)];
    const Mat4 world = multiply(parent, local_transform(path, n, static_cast<std::size_t>(node)));
    if (n.mesh >= 0) out.push_back({n.mesh, world});
    for (auto c = n.children.rbegin(); c != n.children.rend(); ++c) stack.emplace_back(*c, world);
  }
}

std::vector<Instance> mesh_instances(const std::string& path, const tinygltf::Model& m) {
  std::vector<Instance> out;
  std::vector<char> seen(m.nodes.size(), 0);
  std::vector<int> roots;
  if (!m.scenes.empty()) {
    const int s = m.defaultScene >= 0 ? m.defaultScene : 0;
    if (static_cast<std::size_t>(s) >= m.scenes.size()) fail_io(path, "", "the default scene does not exist");
    roots = m.scenes[static_cast<std::size_t>(s)].nodes;
  } else {
    std::vector<char> child(m.nodes.size(), 0);
    for (const auto& n : m.nodes)
      for (int c : n.children)
        if (c >= 0 && static_cast<std::size_t>(c) < child.size()) child[static_cast<std::size_t>(c)] = 1;
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      if (!child[i]) roots.push_back(static_cast<int>(i));
  }
  for (int r : roots) visit(path, m, r, seen, out);
  for (const Instance& i : out)
    if (static_cast<std::size_t>(i.mesh) >= m.meshes.size())
      fail_io(path, "", "a node names mesh " + std::to_string(i.mesh) + ", which does not exist");
  return out;
}

// ------------------------------------------------------------------ materials
MeshMaterial::Wrap wrap_mode(const std::string& path, int sampler, const char* axis, int code) {
  switch (code) {
    case TINYGLTF_TEXTURE_WRAP_REPEAT: return MeshMaterial::Wrap::Repeat;
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return MeshMaterial::Wrap::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return MeshMaterial::Wrap::MirroredRepeat;
    default:
      fail_io(path, "", "sampler " + std::to_string(sampler) + " has " + axis + " " + std::to_string(code) +
                            ", not a glTF wrap mode (10497, 33071 or 33648)");
  }
  return MeshMaterial::Wrap::Repeat;
}

// The texture's sampler wrap modes (none: REPEAT on both axes).
void read_sampler_wrap(const std::string& path, const tinygltf::Model& m, const tinygltf::Texture& tex, MeshMaterial& mm) {
  if (tex.sampler < 0) return;
  if (static_cast<std::size_t>(tex.sampler) >= m.samplers.size())
    fail_io(path, "", "a texture names sampler " + std::to_string(tex.sampler) + ", which does not exist");
  const tinygltf::Sampler& s = m.samplers[static_cast<std::size_t>(tex.sampler)];
  mm.wrap_s = wrap_mode(path, tex.sampler, "wrapS", s.wrapS);
  mm.wrap_t = wrap_mode(path, tex.sampler, "wrapT", s.wrapT);
}

std::vector<MeshMaterial> read_materials(const std::string& path, const tinygltf::Model& m,
                                         std::vector<int>& texcoord) {
  std::vector<MeshMaterial> out;
  for (std::size_t i = 0; i < m.materials.size(); ++i) {
    const tinygltf::Material& g = m.materials[i];
    MeshMaterial mm;
    mm.name = g.name.empty() ? "material_" + std::to_string(i) : g.name;
    const auto& f = g.pbrMetallicRoughness.baseColorFactor;
    for (int c = 0; c < 3 && c < static_cast<int>(f.size()); ++c)
      mm.base_color[c] = static_cast<float>(std::clamp(std::isfinite(f[c]) ? f[c] : 1.0, 0.0, 1.0));
    const auto& bt = g.pbrMetallicRoughness.baseColorTexture;
    texcoord.push_back(bt.index >= 0 ? bt.texCoord : -1);
    if (bt.index >= 0) {
      if (static_cast<std::size_t>(bt.index) >= m.textures.size())
        fail_io(path, "", "material '" + mm.name + "' names texture " + std::to_string(bt.index) + ", which does not exist");
      const tinygltf::Texture& tex = m.textures[static_cast<std::size_t>(bt.index)];
      read_sampler_wrap(path, m, tex, mm);
      const int src = tex.source;
      if (src < 0 || static_cast<std::size_t>(src) >= m.images.size())
        fail_io(path, "", "texture " + std::to_string(bt.index) + " of material '" + mm.name + "' has no image surftex can read");
      const tinygltf::Image& im = m.images[static_cast<std::size_t>(src)];
      mm.texture_origin = "image " + std::to_string(src) + " of '" + path + "'";
      if (!im.uri.empty() && im.uri.rfind("data:", 0) != 0) {  // a file beside the .gltf
        mm.texture_file = existing_path((fs::path(path).parent_path() / im.uri).lexically_normal().string());
        if (mm.texture_file.empty())
          throw IOError("'" + path + "': texture image '" + im.uri + "' of material '" + mm.name + "' does not exist");
        mm.texture_origin = "'" + im.uri + "', image " + std::to_string(src) + " of '" + path + "'";
      }
      if (!im.image.empty()) mm.texture_bytes.assign(im.image.begin(), im.image.end());
      else if (mm.texture_file.empty())
        fail_io(path, "", "image " + std::to_string(src) + " of material '" + mm.name + "' holds no data");
    }
    out.push_back(std::move(mm));
  }
  return out;
}

// ------------------------------------------------------------------ primitives
/// The triangles of a primitive as vertex-index triples (section 3.7.2.1).
std::vector<std::array<std::size_t, 3>> primitive_triangles(int mode, const std::vector<std::size_t>& idx) {
  std::vector<std::array<std::size_t, 3>> t;
  const std::size_t n = idx.size();
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    for (std::size_t i = 0; i + 2 < n; i += 3) t.push_back({idx[i], idx[i + 1], idx[i + 2]});
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (std::size_t i = 0; i + 2 < n; ++i)
      t.push_back(i % 2 == 0 ? std::array<std::size_t, 3>{idx[i], idx[i + 1], idx[i + 2]}
                             : std::array<std::size_t, 3>{idx[i + 1], idx[i], idx[i + 2]});
  } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
    for (std::size_t i = 1; i + 1 < n; ++i) t.push_back({idx[i], idx[i + 1], idx[0]});
  }
  return t;
}

struct SoupBuilder {
  const std::string& path;
  const AccessorReader& reader;
  const std::vector<int>& texcoord;  // per material, -1 = no texture
  PolygonSoup& soup;
  bool any_colors = false;
  std::vector<char> colored;  // per point: from a primitive with COLOR_0
  std::size_t skipped_primitives = 0;

  void add(const tinygltf::Primitive& p, const Mat4& world, const std::string& name) {
    if (p.mode != TINYGLTF_MODE_TRIANGLES && p.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        p.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      ++skipped_primitives;
      return;
    }
    auto pos_it = p.attributes.find("POSITION");
    if (pos_it == p.attributes.end()) fail_io(path, "", name + " has no POSITION attribute");
    const Values pos = reader.read(pos_it->second, name + " POSITION", {TINYGLTF_TYPE_VEC3},
                                   {TINYGLTF_COMPONENT_TYPE_FLOAT});
    std::vector<std::size_t> idx;
    if (p.indices >= 0) {
      const Values iv = reader.read(p.indices, name + " indices", {TINYGLTF_TYPE_SCALAR},
                                    {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT});
      idx.reserve(iv.count);
      for (double v : iv.v) {
        if (!(v < static_cast<double>(pos.count)))
          fail_input(path, "", name + " index " + std::to_string(static_cast<std::uint64_t>(v)) + " out of range (" +
                                   std::to_string(pos.count) + " vertices)");
        idx.push_back(static_cast<std::size_t>(v));
      }
    } else {
      for (std::size_t i = 0; i < pos.count; ++i) idx.push_back(i);
    }
    const auto tris = primitive_triangles(p.mode, idx);
    if (tris.empty()) return;
    const int material = p.material >= 0 && static_cast<std::size_t>(p.material) < soup.materials.size() ? p.material : -1;
    if (p.material >= 0 && material < 0) fail_io(path, "", name + " names material " + std::to_string(p.material) + ", which does not exist");
    const std::size_t base = soup.points.size();
    add_points(pos, world, name);
    const bool with_uv = add_uvs(p, material, pos.count, name);
    add_colors(p, pos.count, name);
    const bool flip = det3(world) < 0;
    for (const auto& t : tris) {
      std::vector<std::size_t> poly{base + t[0], flip ? base + t[2] : base + t[1], flip ? base + t[1] : base + t[2]};
      soup.polygons.push_back(poly);
      soup.polygon_material.push_back(material);
      soup.polygon_uvs.push_back(with_uv ? poly : std::vector<std::size_t>{});
    }
  }

  void add_points(const Values& pos, const Mat4& w, const std::string& name) {
    for (std::size_t i = 0; i < pos.count; ++i) {
      const double x = pos.at(i, 0), y = pos.at(i, 1), z = pos.at(i, 2);
      std::array<double, 3> q{w[0] * x + w[4] * y + w[8] * z + w[12], w[1] * x + w[5] * y + w[9] * z + w[13],
                              w[2] * x + w[6] * y + w[10] * z + w[14]};
      check_finite(path, name + " vertex " + std::to_string(i), q);
      soup.points.push_back(q);
    }
  }

  // TEXCOORD_n of the material's base-colour texture (n = its texCoord), or
  // TEXCOORD_0 without one; one UV per point (soup.uvs parallel to points).
  bool add_uvs(const tinygltf::Primitive& p, int material, std::size_t count, const std::string& name) {
    const int n = material >= 0 && texcoord[static_cast<std::size_t>(material)] >= 0
                      ? texcoord[static_cast<std::size_t>(material)] : 0;
    auto it = p.attributes.find("TEXCOORD_" + std::to_string(n));
    soup.uvs.resize(soup.points.size() - count, {0.0, 0.0});
    if (it == p.attributes.end()) {
      soup.uvs.resize(soup.points.size(), {0.0, 0.0});
      return false;
    }
    const Values uv = reader.read(it->second, name + " TEXCOORD_" + std::to_string(n), {TINYGLTF_TYPE_VEC2},
                                  {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (uv.count != count) fail_io(path, "", name + " TEXCOORD_" + std::to_string(n) + " has " + std::to_string(uv.count) + " elements for " + std::to_string(count) + " vertices");
    for (std::size_t i = 0; i < count; ++i) {
      std::array<double, 3> c{uv.at(i, 0), uv.at(i, 1), 0.0};
      check_finite(path, name + " TEXCOORD vertex " + std::to_string(i), c);
      soup.uvs.push_back({c[0], 1.0 - c[1]});  // glTF's v runs down the image, surftex's up
    }
    return true;
  }

  void add_colors(const tinygltf::Primitive& p, std::size_t count, const std::string& name) {
    colored.resize(soup.points.size() - count, 0);
    soup.colors.resize(soup.points.size() - count, {1.f, 1.f, 1.f});
    auto it = p.attributes.find("COLOR_0");
    if (it == p.attributes.end()) {
      colored.resize(soup.points.size(), 0);
      soup.colors.resize(soup.points.size(), {1.f, 1.f, 1.f});
      return;
    }
    const Values c = reader.read(it->second, name + " COLOR_0", {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4},
                                 {TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE,
                                  TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT});
    if (c.count != count) fail_io(path, "", name + " COLOR_0 has " + std::to_string(c.count) + " elements for " + std::to_string(count) + " vertices");
    for (std::size_t i = 0; i < count; ++i) {
      std::array<float, 3> col{};
      for (int k = 0; k < 3; ++k) {
        const double v = c.at(i, k);
        if (!std::isfinite(v)) fail_input(path, "", name + " COLOR_0 of vertex " + std::to_string(i) + " is not finite");
        col[k] = static_cast<float>(std::clamp(v, 0.0, 1.0));
      }
      soup.colors.push_back(col);
      colored.push_back(1);
    }
    any_colors = true;
  }
};

}  // namespace

PolygonSoup read_gltf(const std::string& path, std::string_view data, bool binary) {
  PolygonSoup soup;
  const tinygltf::Model model = load_model(path, data, binary, soup.files_read);
  std::vector<int> texcoord;
  soup.materials = read_materials(path, model, texcoord);
  const AccessorReader reader(path, model);
  SoupBuilder b{path, reader, texcoord, soup, false, {}, 0};
  for (const Instance& inst : mesh_instances(path, model)) {
    const tinygltf::Mesh& mesh = model.meshes[static_cast<std::size_t>(inst.mesh)];
    for (std::size_t k = 0; k < mesh.primitives.size(); ++k)
      b.add(mesh.primitives[k], inst.world,
            "mesh " + std::to_string(inst.mesh) + " primitive " + std::to_string(k));
  }
  if (soup.polygons.empty())
    throw InvalidInputError("'" + path + "' has no triangles (" + std::to_string(model.meshes.size()) + " meshes" +
                            (b.skipped_primitives ? ", " + std::to_string(b.skipped_primitives) + " point or line primitives"
                                                  : std::string()) +
                            ")");
  if (b.skipped_primitives)
    soup.warnings.push_back(std::to_string(b.skipped_primitives) + " point or line primitives skipped");
  if (!b.any_colors) soup.colors.clear();
  bool any_uv = false;
  for (const auto& pu : soup.polygon_uvs) any_uv = any_uv || !pu.empty();
  if (!any_uv) {
    soup.uvs.clear();
    soup.polygon_uvs.clear();
  }
  if (soup.materials.empty()) soup.polygon_material.clear();
  return soup;
}

}  // namespace surftex::mesh_io
