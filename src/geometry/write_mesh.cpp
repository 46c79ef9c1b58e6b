// SPDX-License-Identifier: AGPL-3.0-or-later
// Mesh output: OBJ (+MTL +PNG), binary little-endian PLY, OFF, glTF 2.0 binary.
#include "geometry/write_mesh.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <unordered_map>

#include "geometry/errors.h"
#include "geometry/file_extension.h"
#include "geometry/face_material.h"
#include "geometry/gltf_vertex_frames.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/output_file.h"
#include "geometry/properties.h"

namespace fs = std::filesystem;

namespace surftex {

namespace {

/// Shortest decimal that reads back to the same double.
void append_num(std::string& out, double v) {
  char buf[32];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

/// What every writer needs, gathered once: compact vertex numbering, faces
/// as vertex lists, optional normals / colours / corner UVs / scalar.
struct Gathered {
  std::vector<std::array<double, 3>> pos;
  std::vector<std::vector<std::size_t>> faces;     // compact vertex ids
  std::vector<std::vector<HalfedgeIndex>> corners;  // halfedge per face corner
  std::vector<std::array<float, 3>> normals;        // empty = none
  std::vector<std::array<float, 3>> colors;         // empty = none
  std::vector<double> scalar;                       // empty = none
  PropertyMap<HalfedgeIndex, UV> uv;
  bool has_uv = false;
};

Gathered gather(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt, bool want_normals) {
  Gathered g;
  if (mesh.number_of_faces() == 0)
    throw InvalidInputError("cannot write '" + path + "': the mesh has no faces");
  std::vector<std::size_t> id(mesh.num_vertices(), SIZE_MAX);
  g.pos.reserve(mesh.number_of_vertices());
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw InvalidInputError("cannot write '" + path + "': vertex " + std::to_string(v.idx()) +
                              " has a non-finite coordinate");
    id[v.idx()] = g.pos.size();
    g.pos.push_back({p.x(), p.y(), p.z()});
  }
  g.faces.reserve(mesh.number_of_faces());
  g.corners.reserve(mesh.number_of_faces());
  for (FaceIndex f : mesh.faces()) {
    std::vector<std::size_t> fv;
    std::vector<HalfedgeIndex> fh;
    for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
      fv.push_back(id[mesh.target(h).idx()]);
      fh.push_back(h);
    }
    g.faces.push_back(std::move(fv));
    g.corners.push_back(std::move(fh));
  }
  if (opt.write_uvs) {
    auto m = find(mesh, kCornerUV);
    if (m.second) {
      g.uv = m.first;
      g.has_uv = true;
    }
  }
  if (opt.write_colors) {
    auto m = find(mesh, kVertexColor);
    if (m.second) {
      g.colors.reserve(g.pos.size());
      for (VertexIndex v : mesh.vertices()) g.colors.push_back(m.first[v]);
    }
  }
  if (!opt.vertex_scalar_property.empty()) {
    auto m = mesh.property_map<VertexIndex, double>(opt.vertex_scalar_property);
    if (!m.second)
      throw InvalidInputError("cannot write '" + path + "': the mesh has no per-vertex double property '" +
                              opt.vertex_scalar_property + "' (vertex_scalar_property)");
    for (VertexIndex v : mesh.vertices()) g.scalar.push_back(m.first[v]);
  }
  if (want_normals && opt.write_normals) g.normals = export_vertex_normals(mesh);  // compact order
  return g;
}

void write_bytes(std::ofstream& f, const std::string& path) {
  f.flush();
  if (!f) throw IOError("write to '" + path + "' failed (disk full?)");
}

// ------------------------------------------------------------------ materials
/// A material as written: WriteMeshOptions::materials, or the one material
/// of WriteMeshOptions::texture.
struct OutMaterial {
  std::string name;
  std::array<float, 3> color{1.f, 1.f, 1.f};
  const Image* texture = nullptr;
};

struct MaterialGroups {
  std::vector<OutMaterial> materials;  // empty: no material at all (OBJ without .mtl)
  std::vector<std::size_t> face;       // per gathered face: index into materials
};

// OBJ names end at a blank for many readers: blanks become '_', and repeated
// names get a suffix.
std::string unique_name(std::string name, const std::vector<OutMaterial>& taken) {
  if (name.empty()) name = "material";
  for (char& c : name)
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n') c = '_';
  std::string n = name;
  for (int k = 2;; ++k) {
    bool used = false;
    for (const auto& t : taken) used = used || t.name == n;
    if (!used) return n;
    n = name + "_" + std::to_string(k);
  }
}

MaterialGroups material_groups(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt) {
  MaterialGroups g;
  const bool listed = opt.materials != nullptr && !opt.materials->empty();
  if (listed && opt.texture != nullptr)
    throw InvalidInputError("cannot write '" + path + "': both a texture and a material list given");
  g.face.assign(mesh.number_of_faces(), 0);
  if (!listed) {
    if (opt.texture != nullptr && !opt.texture->empty()) g.materials.push_back({"surftex_material", {1.f, 1.f, 1.f}, opt.texture});
    return g;
  }
  for (const MeshMaterial& m : *opt.materials)
    g.materials.push_back({unique_name(m.name, g.materials), m.base_color, m.texture.empty() ? nullptr : &m.texture});
  auto fm = find(mesh, kFaceMaterial);
  std::size_t k = 0, fallback = SIZE_MAX;
  for (FaceIndex f : mesh.faces()) {
    const int id = fm.second ? fm.first[f] : 0;
    if (id >= 0 && static_cast<std::size_t>(id) < opt.materials->size()) {
      g.face[k++] = static_cast<std::size_t>(id);
      continue;
    }
    if (fallback == SIZE_MAX) {
      fallback = g.materials.size();
      g.materials.push_back({unique_name("surftex_default", g.materials), {1.f, 1.f, 1.f}, nullptr});
    }
    g.face[k++] = fallback;
  }
  return g;
}

// The texture file of material k beside an OBJ: <stem>.png when one material
// has a texture, else <stem>_<k>.png.
std::vector<std::string> texture_names(const std::string& stem, const MaterialGroups& g) {
  std::size_t textured = 0;
  for (const auto& m : g.materials) textured += m.texture != nullptr;
  std::vector<std::string> names(g.materials.size());
  for (std::size_t k = 0; k < g.materials.size(); ++k)
    if (g.materials[k].texture)
      names[k] = textured == 1 ? stem + ".png" : stem + "_" + std::to_string(k) + ".png";
  return names;
}

// ------------------------------------------------------------------ OBJ
std::string obj_mtl_text(const MaterialGroups& g, const std::vector<std::string>& png) {
  std::string m = "# written by surftex\n";
  for (std::size_t k = 0; k < g.materials.size(); ++k) {
    const auto& c = g.materials[k].color;
    m += "newmtl " + g.materials[k].name + "\nKa 1 1 1\nKd ";
    for (int i = 0; i < 3; ++i) {
      append_num(m, c[i]);
      m += i < 2 ? " " : "\n";
    }
    m += "Ks 0 0 0\nd 1\nillum 1\n";
    if (!png[k].empty()) m += "map_Kd " + png[k] + "\n";
  }
  return m;
}

/// The PBR maps of an OBJ's material (write_mesh.h): staged files beside the
/// OBJ and their MTL lines.
struct ObjPbrMap {
  std::unique_ptr<AtomicOutputFile> file;
  const Image* image = nullptr;
  bool sixteen_bit = false;
  void write() const {
    WriteImageOptions io;
    io.sixteen_bit = sixteen_bit;
    write_image(file->temp_path(), *image, io);
  }
};
struct ObjPbrMaps {
  std::vector<ObjPbrMap> maps;
  std::string mtl_lines;
};

ObjPbrMaps obj_pbr_maps(const fs::path& dir, const std::string& stem, const WriteMeshOptions& opt, bool textured) {
  ObjPbrMaps r;
  if (!textured) return r;
  auto add = [&](const Image* img, const std::string& suffix, bool wide, const std::string& lines) {
    if (img == nullptr || img->empty()) return;
    const std::string name = stem + suffix;
    ObjPbrMap m;
    m.file = std::make_unique<AtomicOutputFile>((dir / name).string(), opt.overwrite);
    m.image = img;
    m.sixteen_bit = wide;
    r.maps.push_back(std::move(m));
    std::string l = lines;
    for (std::size_t at; (at = l.find('@')) != std::string::npos;) l.replace(at, 1, name);
    r.mtl_lines += l;
  };
  // `norm` (tangent-space normal map) and `map_Bump` with the same file:
  // Blender's importer reads map_Bump as a normal map.
  add(opt.normal_texture, "_normal.png", false, "norm @\nmap_Bump @\n");
  add(opt.height_texture, "_height.png", true, "disp @\n");
  add(opt.metallic_roughness_texture, "_roughness.png", false, "map_Pr -imfchan g @\n");
  return r;
}

// Writes the bytes opt.encoded_png holds for `img` to `path`; false when it
// holds none.
bool write_encoded(const std::string& path, const Image* img, const WriteMeshOptions& opt) {
  if (opt.encoded_png == nullptr || img == nullptr) return false;
  const auto it = opt.encoded_png->find(img);
  if (it == opt.encoded_png->end()) return false;
  std::ofstream f(path, std::ios::binary);
  if (!f) throw IOError("cannot open '" + path + "' for writing");
  f.write(it->second.data(), static_cast<std::streamsize>(it->second.size()));
  write_bytes(f, path);
  return true;
}

// Lines 0..n-1 written by line(i, out) in chunks side by side, joined in order.
std::string parallel_lines(std::size_t n, const std::function<void(std::size_t, std::string&)>& line) {
  constexpr std::size_t kChunk = 8192;
  std::vector<std::string> part((n + kChunk - 1) / kChunk);
  tbb::parallel_for(std::size_t(0), part.size(), [&](std::size_t k) {
    for (std::size_t i = k * kChunk; i < std::min(n, (k + 1) * kChunk); ++i) line(i, part[k]);
  });
  std::size_t total = 0;
  for (const auto& t : part) total += t.size();
  std::string s;
  s.reserve(total);
  for (const auto& t : part) s += t;
  return s;
}

void append_index(std::string& out, std::size_t v) {
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

// Distinct UV values numbered in first-use order (corner by corner, face by
// face): the "vt" lines and each face's vt numbers.
std::string obj_uv_lines(const Gathered& g, std::vector<std::vector<std::size_t>>& face_vt) {
  struct Key {
    std::size_t operator()(const std::array<double, 2>& k) const {
      std::uint64_t a, b;
      std::memcpy(&a, &k[0], 8);
      std::memcpy(&b, &k[1], 8);
      return std::hash<std::uint64_t>()(a * 0x9E3779B97F4A7C15ull ^ b);
    }
  };
  std::unordered_map<std::array<double, 2>, std::size_t, Key> vt_id;
  vt_id.reserve(g.faces.size() * 2);
  std::string s;
  face_vt.resize(g.faces.size());
  for (std::size_t f = 0; f < g.faces.size(); ++f)
    for (HalfedgeIndex h : g.corners[f]) {
      const UV& uv = g.uv[h];
      // + 0.0 makes -0 and +0 one key, as they compare equal
      auto [it, inserted] = vt_id.emplace(std::array<double, 2>{uv[0] + 0.0, uv[1] + 0.0}, vt_id.size());
      if (inserted) {
        s += "vt ";
        append_num(s, uv[0]);
        s += ' ';
        append_num(s, uv[1]);
        s += '\n';
      }
      face_vt[f].push_back(it->second);
    }
  return s;
}

// The OBJ's text: vertices (with colours), distinct UVs, normals, faces
// grouped by material.
std::string obj_text(const Gathered& g, const MaterialGroups& groups, const std::string& mtl_name) {
  const bool with_mtl = !groups.materials.empty();
  std::string s = "# written by surftex\n";
  if (with_mtl) s += "mtllib " + mtl_name + "\n";
  s += parallel_lines(g.pos.size(), [&](std::size_t i, std::string& o) {
    o += "v ";
    append_num(o, g.pos[i][0]);
    o += ' ';
    append_num(o, g.pos[i][1]);
    o += ' ';
    append_num(o, g.pos[i][2]);
    if (!g.colors.empty())
      for (int c = 0; c < 3; ++c) {
        o += ' ';
        append_num(o, g.colors[i][c]);
      }
    o += '\n';
  });
  std::vector<std::vector<std::size_t>> face_vt;
  if (g.has_uv) s += obj_uv_lines(g, face_vt);
  s += parallel_lines(g.normals.size(), [&](std::size_t i, std::string& o) {
    const auto& n = g.normals[i];
    o += "vn ";
    append_num(o, n[0]);
    o += ' ';
    append_num(o, n[1]);
    o += ' ';
    append_num(o, n[2]);
    o += '\n';
  });
  // Faces grouped by material (file order within a group).
  for (std::size_t k = 0; k < std::max<std::size_t>(groups.materials.size(), 1); ++k) {
    if (with_mtl) s += "usemtl " + groups.materials[k].name + "\n";
    s += parallel_lines(g.faces.size(), [&](std::size_t f, std::string& o) {
      if (with_mtl && groups.face[f] != k) return;
      o += 'f';
      for (std::size_t c = 0; c < g.faces[f].size(); ++c) {
        o += ' ';
        append_index(o, g.faces[f][c] + 1);
        if (g.has_uv) {
          o += '/';
          append_index(o, face_vt[f][c] + 1);
        }
        if (!g.normals.empty()) {
          o += g.has_uv ? "/" : "//";
          append_index(o, g.faces[f][c] + 1);
        }
      }
      o += '\n';
    });
  }
  return s;
}

std::vector<std::string> write_obj(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt) {
  Gathered g = gather(path, mesh, opt, true);
  const MaterialGroups groups = material_groups(path, mesh, opt);
  fs::path p(path);
  const std::string stem = p.stem().string();
  const bool with_mtl = !groups.materials.empty();
  const fs::path dir = p.parent_path();
  const std::string mtl_name = stem + ".mtl";
  const std::vector<std::string> png_names = texture_names(stem, groups);
  // Every file is prepared as a temporary first and renamed at the end, so a
  // failure leaves none of them (and !overwrite refuses before writing).
  AtomicOutputFile obj_out(path, opt.overwrite);
  std::unique_ptr<AtomicOutputFile> mtl_out;
  std::vector<std::unique_ptr<AtomicOutputFile>> png_out(groups.materials.size());
  if (with_mtl) mtl_out = std::make_unique<AtomicOutputFile>((dir / mtl_name).string(), opt.overwrite);
  for (std::size_t k = 0; k < png_names.size(); ++k)
    if (!png_names[k].empty()) png_out[k] = std::make_unique<AtomicOutputFile>((dir / png_names[k]).string(), opt.overwrite);
  const bool pbr_textured = opt.texture != nullptr && !opt.texture->empty();
  ObjPbrMaps pbr = obj_pbr_maps(dir, stem, opt, pbr_textured);

  std::vector<std::string> written{path};
  // The textures and PBR maps (PNG encoding is most of an asset's write
  // time: seven 2048 px maps took 3.5 s one after the other) side by side,
  // and beside the text.
  std::vector<std::function<void()>> encodes;
  for (std::size_t k = 0; k < png_out.size(); ++k)
    if (png_out[k])
      encodes.emplace_back([&, k] {
        if (!write_encoded(png_out[k]->temp_path(), groups.materials[k].texture, opt))
          write_image(png_out[k]->temp_path(), *groups.materials[k].texture);
      });
  for (const ObjPbrMap& m : pbr.maps)
    encodes.emplace_back([&] {
      if (m.sixteen_bit || !write_encoded(m.file->temp_path(), m.image, opt)) m.write();
    });
  std::string s;
  tbb::parallel_invoke([&] { s = obj_text(g, groups, mtl_name); },
                       [&] { tbb::parallel_for(std::size_t(0), encodes.size(), [&](std::size_t i) { encodes[i](); }); });
  if (with_mtl) {
    std::ofstream f(mtl_out->temp_path(), std::ios::binary);
    if (!f) throw IOError("cannot open '" + mtl_out->temp_path() + "' for writing");
    f << obj_mtl_text(groups, png_names) << pbr.mtl_lines;
    write_bytes(f, mtl_out->destination());
  }
  {
    std::ofstream f(obj_out.temp_path(), std::ios::binary);
    if (!f) throw IOError("cannot open '" + obj_out.temp_path() + "' for writing");
    f.write(s.data(), static_cast<std::streamsize>(s.size()));
    write_bytes(f, path);
  }
  for (auto& out : png_out)
    if (out) {
      out->commit();
      written.push_back(out->destination());
    }
  if (with_mtl) {
  for (auto& m : pbr.maps) {
    m.file->commit();
    written.push_back(m.file->destination());
  }
    mtl_out->commit();
    written.insert(written.begin() + 1, mtl_out->destination());
  }
  obj_out.commit();
  return written;
}

// ------------------------------------------------------------------ PLY
template <class T>
void put_le(std::string& s, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  if (first != 1) std::reverse(b, b + sizeof(T));
  s.append(reinterpret_cast<const char*>(b), sizeof(T));
}

void write_ply(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt) {
  Gathered g = gather(path, mesh, opt, false);
  std::size_t max_deg = 0;
  for (const auto& f : g.faces) max_deg = std::max(max_deg, f.size());
  const bool wide = max_deg > 255;
  std::string s = "ply\nformat binary_little_endian 1.0\ncomment written by surftex\n";
  s += "element vertex " + std::to_string(g.pos.size()) + "\n";
  s += "property float x\nproperty float y\nproperty float z\n";
  if (!g.colors.empty()) s += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  if (!g.scalar.empty()) s += "property float " + opt.vertex_scalar_property + "\n";
  s += "element face " + std::to_string(g.faces.size()) + "\n";
  s += std::string("property list ") + (wide ? "uint" : "uchar") + " int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < g.pos.size(); ++i) {
    for (int c = 0; c < 3; ++c) put_le<float>(s, static_cast<float>(g.pos[i][c]));
    if (!g.colors.empty())
      for (int c = 0; c < 3; ++c)
        put_le<std::uint8_t>(s, static_cast<std::uint8_t>(std::lround(std::clamp(g.colors[i][c], 0.f, 1.f) * 255.f)));
    if (!g.scalar.empty()) put_le<float>(s, static_cast<float>(g.scalar[i]));
  }
  for (const auto& f : g.faces) {
    if (wide) put_le<std::uint32_t>(s, static_cast<std::uint32_t>(f.size()));
    else put_le<std::uint8_t>(s, static_cast<std::uint8_t>(f.size()));
    for (std::size_t v : f) put_le<std::int32_t>(s, static_cast<std::int32_t>(v));
  }
  write_file_atomic(path, s, opt.overwrite);
}

// ------------------------------------------------------------------ OFF
void write_off(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt) {
  Gathered g = gather(path, mesh, opt, false);
  const bool col = !g.colors.empty();
  std::string s = col ? "COFF\n" : "OFF\n";
  s += std::to_string(g.pos.size()) + " " + std::to_string(g.faces.size()) + " 0\n";
  for (std::size_t i = 0; i < g.pos.size(); ++i) {
    append_num(s, g.pos[i][0]);
    s += ' ';
    append_num(s, g.pos[i][1]);
    s += ' ';
    append_num(s, g.pos[i][2]);
    if (col) {
      for (int c = 0; c < 3; ++c)
        s += " " + std::to_string(std::lround(std::clamp(g.colors[i][c], 0.f, 1.f) * 255.f));
      s += " 255";
    }
    s += '\n';
  }
  for (const auto& f : g.faces) {
    s += std::to_string(f.size());
    for (std::size_t v : f) s += " " + std::to_string(v);
    s += '\n';
  }
  write_file_atomic(path, s, opt.overwrite);
}

// ------------------------------------------------------------------ glTF
std::string png_bytes(const std::string& beside, const Image& img, std::size_t slot) {
  // Encoded through OpenImageIO into a temporary that is never committed
  // (one name per slot: a run refuses two staged outputs of the same name).
  AtomicOutputFile tmp(beside + ".texture_" + std::to_string(slot) + ".png", true);
  write_image(tmp.temp_path(), img);
  std::ifstream f(tmp.temp_path(), std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  if (!f && !f.eof()) throw IOError("cannot read back the encoded texture for '" + beside + "'");
  return ss.str();
}

// The triangles of every material (one glTF primitive each), as indices of
// glTF vertices: one per distinct (vertex, uv) pair, so that vertices are
// split at UV seams; polygons are fanned.
std::vector<std::vector<std::uint32_t>> gltf_triangles(const Gathered& g, const MaterialGroups& groups,
                                                       GltfVertexSplit& split) {
  std::vector<std::vector<std::uint32_t>> indices(groups.materials.size());
  auto vid = [&](std::size_t v, HalfedgeIndex h) -> std::uint32_t {
    std::array<double, 2> uv{0.0, 0.0};
    if (g.has_uv) uv = {g.uv[h][0], g.uv[h][1]};
    return split.id(v, uv);
  };
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const auto& fv = g.faces[f];
    const std::uint32_t a = vid(fv[0], g.corners[f][0]);
    std::vector<std::uint32_t>& out = indices[groups.face[f]];
    for (std::size_t k = 1; k + 1 < fv.size(); ++k) {  // fan over polygons
      out.push_back(a);
      out.push_back(vid(fv[k], g.corners[f][k]));
      out.push_back(vid(fv[k + 1], g.corners[f][k + 1]));
    }
  }
  return indices;
}

// A glTF model over one buffer: views (4-byte aligned), accessors and
// embedded PNG textures appended in call order.
struct GlbBuilder {
  tinygltf::Model model;
  std::map<const Image*, std::string> encoded;  ///< PNG bytes encoded ahead (encode_textures)

  GlbBuilder() {
    model.asset.version = "2.0";
    model.asset.generator = "surftex";
    model.buffers.emplace_back();
  }
  std::vector<unsigned char>& buf() { return model.buffers[0].data; }
  void align() {
    while (buf().size() % 4) buf().push_back(0);
  }
  int add_view(const void* data, std::size_t bytes, int target) {
    align();
    tinygltf::BufferView bv;
    bv.buffer = 0;
    bv.byteOffset = buf().size();
    bv.byteLength = bytes;
    bv.target = target;
    const auto* b = static_cast<const unsigned char*>(data);
    buf().insert(buf().end(), b, b + bytes);
    model.bufferViews.push_back(bv);
    return static_cast<int>(model.bufferViews.size() - 1);
  }
  int add_accessor(int view, int comp, int type, std::size_t count, std::vector<double> mn = {},
                   std::vector<double> mx = {}) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = comp;
    a.type = type;
    a.count = count;
    a.minValues = std::move(mn);
    a.maxValues = std::move(mx);
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size() - 1);
  }
  // A float vertex attribute of `count` elements of glTF type `type`.
  int add_float_attribute(const void* data, std::size_t bytes, int type, std::size_t count) {
    const int view = add_view(data, bytes, TINYGLTF_TARGET_ARRAY_BUFFER);
    return add_accessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, type, count);
  }
  // One embedded PNG per map (its bytes from `encoded`), all through one
  // sampler.
  int add_texture(const Image& img, const char* name, bool repeat) {
    if (model.samplers.empty()) {
      tinygltf::Sampler smp;
      smp.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
      smp.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
      smp.wrapS = smp.wrapT = repeat ? TINYGLTF_TEXTURE_WRAP_REPEAT : TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      model.samplers.push_back(smp);
    }
    const std::string& png = encoded.at(&img);
    int view = add_view(png.data(), png.size(), 0);
    model.bufferViews[view].target = 0;
    tinygltf::Image im;
    im.name = name;
    im.mimeType = "image/png";
    im.bufferView = view;
    model.images.push_back(im);
    tinygltf::Texture tex;
    tex.source = static_cast<int>(model.images.size() - 1);
    tex.sampler = 0;
    model.textures.push_back(tex);
    return static_cast<int>(model.textures.size() - 1);
  }
};

// POSITION (with its bounds) and NORMAL of the glTF vertices.
void add_position_normal(GlbBuilder& b, const Gathered& g, const std::vector<std::size_t>& src,
                         tinygltf::Primitive& prim) {
  std::vector<float> p(src.size() * 3);
  std::vector<double> mn(3, HUGE_VAL), mx(3, -HUGE_VAL);
  for (std::size_t i = 0; i < src.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      float v = static_cast<float>(g.pos[src[i]][c]);
      p[3 * i + c] = v;
      mn[c] = std::min<double>(mn[c], v);
      mx[c] = std::max<double>(mx[c], v);
    }
  int view = b.add_view(p.data(), p.size() * 4, TINYGLTF_TARGET_ARRAY_BUFFER);
  prim.attributes["POSITION"] =
      b.add_accessor(view, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, src.size(), mn, mx);
  if (g.normals.empty()) return;
  std::vector<float> n(src.size() * 3);
  for (std::size_t i = 0; i < src.size(); ++i)
    for (int c = 0; c < 3; ++c) n[3 * i + c] = g.normals[src[i]][c];
  prim.attributes["NORMAL"] = b.add_float_attribute(n.data(), n.size() * 4, TINYGLTF_TYPE_VEC3, src.size());
}

// The vertex attributes every primitive shares: POSITION, NORMAL,
// TEXCOORD_0, TANGENT (for a normal map, geometry/gltf_vertex_frames.h),
// the colour attribute and the scalar (as "_<name>").
tinygltf::Primitive vertex_attributes(GlbBuilder& b, const Gathered& g, const GltfVertexSplit& split,
                                      const std::vector<std::vector<std::uint32_t>>& indices,
                                      const WriteMeshOptions& opt) {
  const std::vector<std::size_t>& src = split.source();            // glTF vertex -> mesh vertex (compact id)
  const std::vector<std::array<float, 2>>& tc = split.texcoord();  // glTF TEXCOORD_0 (v flipped)
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  add_position_normal(b, g, src, prim);
  if (g.has_uv)
    prim.attributes["TEXCOORD_0"] =
        b.add_float_attribute(tc.data(), tc.size() * 8, TINYGLTF_TYPE_VEC2, src.size());
  if (opt.texture != nullptr && !opt.texture->empty() && g.has_uv && !g.normals.empty() &&
      opt.normal_texture != nullptr && !opt.normal_texture->empty()) {
    std::vector<std::uint32_t> all;
    for (const auto& part : indices) all.insert(all.end(), part.begin(), part.end());
    const std::vector<std::array<float, 4>> tan = gltf_vertex_tangents(g.pos, g.normals, split, all);
    prim.attributes["TANGENT"] =
        b.add_float_attribute(tan.data(), tan.size() * 16, TINYGLTF_TYPE_VEC4, src.size());
  }
  if (!g.colors.empty()) {
    std::vector<float> c(src.size() * 3);
    for (std::size_t i = 0; i < src.size(); ++i)
      for (int k = 0; k < 3; ++k) c[3 * i + k] = std::clamp(g.colors[src[i]][k], 0.f, 1.f);
    prim.attributes[opt.color_attribute] =
        b.add_float_attribute(c.data(), c.size() * 4, TINYGLTF_TYPE_VEC3, src.size());
  }
  if (!g.scalar.empty()) {
    std::vector<float> sv(src.size());
    for (std::size_t i = 0; i < src.size(); ++i) sv[i] = static_cast<float>(g.scalar[src[i]]);
    prim.attributes["_" + opt.vertex_scalar_property] =
        b.add_float_attribute(sv.data(), sv.size() * 4, TINYGLTF_TYPE_SCALAR, src.size());
  }
  return prim;
}

// The PNG bytes of each image, encoded side by side (temporaries named
// after `beside` and the image's slot).
std::map<const Image*, std::string> encode_each(const std::string& beside, const std::vector<const Image*>& images) {
  std::vector<std::string> bytes(images.size());
  tbb::parallel_for(std::size_t(0), images.size(), [&](std::size_t i) { bytes[i] = png_bytes(beside, *images[i], i); });
  std::map<const Image*, std::string> r;
  for (std::size_t i = 0; i < images.size(); ++i) r.emplace(images[i], std::move(bytes[i]));
  return r;
}

// The PNG bytes of every map add_materials embeds, encoded side by side
// (the same images, in the same conditions, as add_materials takes them).
std::map<const Image*, std::string> encode_textures(const std::string& path, const MaterialGroups& groups,
                                                    const WriteMeshOptions& opt) {
  std::vector<const Image*> images;
  auto want = [&](const Image* im) {
    if (std::find(images.begin(), images.end(), im) == images.end()) images.push_back(im);
  };
  for (const OutMaterial& om : groups.materials) {
    if (om.texture) want(om.texture);
    if (om.texture == nullptr || om.texture != opt.texture) continue;
    for (const Image* im : {opt.normal_texture, opt.metallic_roughness_texture})
      if (im != nullptr && !im->empty()) want(im);
  }
  std::vector<const Image*> missing;
  for (const Image* im : images)
    if (opt.encoded_png == nullptr || opt.encoded_png->count(im) == 0) missing.push_back(im);
  std::map<const Image*, std::string> r = encode_each(path, missing);
  for (const Image* im : images)
    if (r.count(im) == 0) r.emplace(im, opt.encoded_png->at(im));
  return r;
}

// One glTF material per material (metallic 0, roughness 1, double-sided),
// its texture embedded as PNG. The PBR maps go with WriteMeshOptions::texture.
void add_materials(GlbBuilder& b, const std::string& path, const MaterialGroups& groups,
                   const WriteMeshOptions& opt) {
  b.encoded = encode_textures(path, groups, opt);
  for (std::size_t k = 0; k < groups.materials.size(); ++k) {
    const OutMaterial& om = groups.materials[k];
    tinygltf::Material mat;
    mat.name = om.name;
    mat.pbrMetallicRoughness.baseColorFactor = {om.color[0], om.color[1], om.color[2], 1.0};
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 1.0;
    mat.doubleSided = true;
    if (om.texture) {
      const std::string name =
          b.model.images.empty() ? "texture" : "texture_" + std::to_string(b.model.images.size());
      mat.pbrMetallicRoughness.baseColorTexture.index =
          b.add_texture(*om.texture, name.c_str(), opt.texture_repeat);
    }
    if (om.texture != nullptr && om.texture == opt.texture) {
      if (opt.normal_texture != nullptr && !opt.normal_texture->empty())
        mat.normalTexture.index = b.add_texture(*opt.normal_texture, "normal", opt.texture_repeat);
      if (opt.metallic_roughness_texture != nullptr && !opt.metallic_roughness_texture->empty())
        mat.pbrMetallicRoughness.metallicRoughnessTexture.index =
            b.add_texture(*opt.metallic_roughness_texture, "metallic_roughness", opt.texture_repeat);
    }
    b.model.materials.push_back(mat);
  }
}

// One primitive per non-empty material (the shared attributes, its own
// indices), the mesh in one node of the default scene.
void add_mesh_and_scene(GlbBuilder& b, const std::vector<std::vector<std::uint32_t>>& indices,
                        const tinygltf::Primitive& prim) {
  tinygltf::Mesh gm;
  gm.name = "surftex_mesh";
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (indices[k].empty()) continue;
    int view = b.add_view(indices[k].data(), indices[k].size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Primitive p = prim;
    p.indices =
        b.add_accessor(view, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices[k].size());
    p.material = static_cast<int>(k);
    gm.primitives.push_back(p);
  }
  b.align();
  b.model.meshes.push_back(gm);
  tinygltf::Node node;
  node.mesh = 0;
  b.model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  b.model.scenes.push_back(scene);
  b.model.defaultScene = 0;
}

void write_glb(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt) {
  Gathered g = gather(path, mesh, opt, true);
  MaterialGroups groups = material_groups(path, mesh, opt);
  if (groups.materials.empty()) groups.materials.push_back({"surftex_material", {1.f, 1.f, 1.f}, nullptr});
  for (const auto& m : groups.materials)
    if (m.texture && !g.has_uv)
      throw InvalidInputError("cannot write '" + path + "': material '" + m.name +
                              "' has a texture but the mesh has no texture coordinates to map it with");
  GltfVertexSplit split;
  const std::vector<std::vector<std::uint32_t>> indices = gltf_triangles(g, groups, split);
  if (split.source().size() > 0xffffffffu)
    throw InvalidInputError("cannot write '" + path + "': too many vertices for glTF");
  GlbBuilder b;
  const tinygltf::Primitive prim = vertex_attributes(b, g, split, indices, opt);
  add_materials(b, path, groups, opt);
  add_mesh_and_scene(b, indices, prim);
  tinygltf::TinyGLTF writer;
  std::ostringstream os;
  if (!writer.WriteGltfSceneToStream(&b.model, os, false, true))
    throw IOError("cannot encode glTF for '" + path + "'");
  write_file_atomic(path, os.str(), opt.overwrite);
}

}  // namespace

std::map<const Image*, std::string> encode_png(const std::string& beside, const std::vector<const Image*>& images) {
  for (const Image* im : images)
    if (im == nullptr || im->empty()) throw InvalidInputError("encode_png: an empty image");
  return encode_each(beside + ".ahead", images);
}

std::vector<std::string> write_mesh(const std::string& path, const Mesh& mesh, const WriteMeshOptions& opt) {
  const std::string ext = lower_extension(path);
  if (ext == ".obj") return write_obj(path, mesh, opt);
  if (ext == ".ply") write_ply(path, mesh, opt);
  else if (ext == ".off") write_off(path, mesh, opt);
  else if (ext == ".glb") write_glb(path, mesh, opt);
  else
    throw InvalidInputError("cannot write '" + path + "': unknown mesh format '" + ext +
                            "' (supported: .obj, .ply, .off, .glb)");
  return {path};
}

std::vector<std::string> write_obj_and_glb(const std::string& obj, const std::string& glb, const Mesh& mesh,
                                           const WriteMeshOptions& obj_opt, const WriteMeshOptions& glb_opt) {
  std::vector<const Image*> shared;
  for (const Image* im : {obj_opt.texture, obj_opt.normal_texture, obj_opt.metallic_roughness_texture})
    if (im != nullptr && !im->empty() && (obj_opt.encoded_png == nullptr || obj_opt.encoded_png->count(im) == 0))
      shared.push_back(im);
  std::map<const Image*, std::string> pngs = obj_opt.encoded_png ? *obj_opt.encoded_png
                                                                  : std::map<const Image*, std::string>{};
  if (!shared.empty()) pngs.merge(encode_png(glb, shared));
  WriteMeshOptions oo = obj_opt, go = glb_opt;
  oo.encoded_png = go.encoded_png = &pngs;
  std::vector<std::string> obj_files, glb_files;
  tbb::parallel_invoke([&] { obj_files = write_mesh(obj, mesh, oo); }, [&] { glb_files = write_mesh(glb, mesh, go); });
  obj_files.insert(obj_files.end(), glb_files.begin(), glb_files.end());
  return obj_files;
}

}  // namespace surftex
