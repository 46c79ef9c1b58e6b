// SPDX-License-Identifier: AGPL-3.0-or-later
// Mesh input: format dispatch, the helpers shared by the per-format parsers
// (mesh_parsers.h), and soup-to-mesh conversion through CGAL PMP.
#include "geometry/read_mesh.h"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>

#include "geometry/errors.h"
#include "geometry/file_extension.h"
#include "geometry/face_material.h"
#include "geometry/mesh.h"
#include "geometry/mesh_parsers.h"
#include "geometry/properties.h"
#include "geometry/split_pinched_polygons.h"

namespace fs = std::filesystem;
namespace PMP = CGAL::Polygon_mesh_processing;

namespace surftex {

// ---------------------------------------------------------------- helpers
namespace mesh_io {

void fail_io(const std::string& path, const std::string& where, const std::string& msg) {
  throw IOError("'" + path + "'" + (where.empty() ? "" : " " + where) + ": " + msg);
}
void fail_input(const std::string& path, const std::string& where, const std::string& msg) {
  throw InvalidInputError("'" + path + "'" + (where.empty() ? "" : " " + where) + ": " + msg);
}
std::string at_line(std::size_t line) { return "line " + std::to_string(line); }

std::string show(std::string_view token) {
  std::string out = "'";
  std::size_t n = std::min<std::size_t>(token.size(), 40);
  for (std::size_t i = 0; i < n; ++i) {
    unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 32 && c < 127) {
      out += static_cast<char>(c);
    } else {
      static const char* hex = "0123456789abcdef";
      out += "\\x";
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  if (token.size() > n) out += "...";
  return out + "'";
}

bool TextLines::next(std::string_view& line) {
  if (pos_ >= data_.size()) return false;
  std::size_t end = data_.find('\n', pos_);
  std::size_t stop = end == std::string_view::npos ? data_.size() : end;
  line = data_.substr(pos_, stop - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  pos_ = end == std::string_view::npos ? data_.size() : end + 1;
  line_ = next_line_++;
  if (std::memchr(line.data(), '\0', line.size()) != nullptr)
    fail_io(path_, at_line(line_), "binary data (NUL byte) in a text file");
  return true;
}

void split_blanks(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
  std::size_t i = 0, n = line.size();
  while (i < n) {
    while (i < n && blank(line[i])) ++i;
    std::size_t s = i;
    while (i < n && !blank(line[i])) ++i;
    if (i > s) out.push_back(line.substr(s, i - s));
  }
}

std::string_view strip_comment(std::string_view line) {
  std::size_t h = line.find('#');
  return h == std::string_view::npos ? line : line.substr(0, h);
}

bool parse_double(std::string_view tok, double& v) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  const char* b = tok.data();
  const char* e = b + tok.size();
  auto r = std::from_chars(b, e, v, std::chars_format::general);
  if (r.ec == std::errc::result_out_of_range) {
    // Magnitude too large (or too small): decide which by the exponent sign.
    bool tiny = tok.find("e-") != std::string_view::npos || tok.find("E-") != std::string_view::npos;
    v = tiny ? 0.0 : (tok.front() == '-' ? -HUGE_VAL : HUGE_VAL);
    return r.ptr == e;
  }
  return r.ec == std::errc() && r.ptr == e;
}

bool parse_int64(std::string_view tok, std::int64_t& v) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  if (tok.empty()) return false;
  auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  return r.ec == std::errc() && r.ptr == tok.data() + tok.size();
}

bool parse_uint64(std::string_view tok, std::uint64_t& v) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  if (tok.empty() || tok.front() == '-') return false;
  auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  return r.ec == std::errc() && r.ptr == tok.data() + tok.size();
}

/// Refuses a NaN or infinite coordinate, and one beyond the float range
/// (3.4e38): outputs store float32 positions, and a larger one overflows the
/// geometry's products to infinity (CGAL's exact fallback then converts an
/// infinite double to GMP, which raises SIGFPE; fuzz_off found it).
void check_finite(const std::string& path, const std::string& where, const std::array<double, 3>& p) {
  auto text = [](double c) {
    std::ostringstream v;
    v << c;
    return v.str();
  };
  const std::string at = " (" + text(p[0]) + ", " + text(p[1]) + ", " + text(p[2]) + ")";
  for (double c : p) {
    if (!std::isfinite(c))
      fail_input(path, where, "coordinate is " + std::string(std::isnan(c) ? "NaN" : "infinite") + at);
    if (std::abs(c) > double(std::numeric_limits<float>::max()))
      fail_input(path, where, "coordinate " + text(c) + " is beyond the float range (3.4e38)" + at);
  }
}

std::size_t PositionHash::operator()(const std::array<double, 3>& p) const noexcept {
  std::uint64_t h = 0x9e3779b97f4a7c15ull;
  for (double c : p) {
    if (c == 0.0) c = 0.0;
    std::uint64_t b;
    std::memcpy(&b, &c, sizeof b);
    h ^= b + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  }
  return static_cast<std::size_t>(h);
}

bool looks_like_binary_stl(std::string_view data) {
  if (data.size() < 84) return false;
  std::uint32_t n = 0;
  const auto* b = reinterpret_cast<const unsigned char*>(data.data() + 80);
  n = static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
      static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
  return 84 + 50 * static_cast<std::uint64_t>(n) == data.size();
}

}  // namespace mesh_io

// ---------------------------------------------------------------- dispatch
namespace {

using namespace mesh_io;

enum class Format { Off, Obj, Ply, Stl, Glb, Gltf, Unknown };

bool is_off_keyword(std::string_view t) {
  if (t.size() < 3 || t.substr(t.size() - 3) != "OFF") return false;
  std::string_view pre = t.substr(0, t.size() - 3);
  if (pre.substr(0, 2) == "ST") pre.remove_prefix(2);
  for (char c : pre)
    if (c != 'C' && c != 'N' && c != '4' && c != 'n') return false;
  return true;
}

Format sniff(std::string_view data) {
  if (data.substr(0, 4) == "glTF") return Format::Glb;
  if (looks_like_binary_stl(data)) return Format::Stl;
  data.remove_prefix(utf8_bom_length(data));  // the text readers skip it too
  if (data.substr(0, 4) == "ply\n" || data.substr(0, 5) == "ply\r\n") return Format::Ply;
  // First token of the first non-comment line.
  std::size_t pos = 0;
  int lines = 0;
  bool obj_like = false;
  while (pos < data.size() && lines < 2000) {
    std::size_t end = data.find('\n', pos);
    std::string_view line = data.substr(pos, (end == std::string_view::npos ? data.size() : end) - pos);
    pos = end == std::string_view::npos ? data.size() : end + 1;
    ++lines;
    std::vector<std::string_view> tok;
    split_blanks(strip_comment(line), tok);
    if (tok.empty()) continue;
    if (lines <= 50 && is_off_keyword(tok[0])) return Format::Off;
    if (tok[0] == "solid" && lines <= 1) return Format::Stl;
    if (tok[0] == "v" || tok[0] == "f" || tok[0] == "vt" || tok[0] == "vn") obj_like = true;
    if (tok[0] == "f" && obj_like) return Format::Obj;
  }
  return obj_like ? Format::Obj : Format::Unknown;
}

// The image format whose signature starts `data`, or empty: a user may hand
// an image where a mesh is expected (argument order); say so rather than
// report the parse of binary bytes as text.
std::string image_signature(std::string_view d) {
  if (d.substr(0, 8) == std::string_view("\x89PNG\r\n\x1a\n", 8)) return "PNG";
  if (d.substr(0, 3) == std::string_view("\xff\xd8\xff", 3)) return "JPEG";
  if (d.substr(0, 4) == std::string_view("II*\0", 4) || d.substr(0, 4) == std::string_view("MM\0*", 4))
    return "TIFF";
  if (d.substr(0, 4) == std::string_view("\x76\x2f\x31\x01", 4)) return "OpenEXR";
  if (d.substr(0, 6) == "GIF87a" || d.substr(0, 6) == "GIF89a") return "GIF";
  if (d.substr(0, 4) == "RIFF" && d.substr(8, 4) == "WEBP") return "WebP";
  return {};
}

std::string read_whole_file(const std::string& path) {
  std::error_code ec;
  if (path.empty()) throw IOError("mesh path is empty");
  if (!fs::exists(path, ec)) throw IOError("mesh file '" + path + "' does not exist");
  if (!fs::is_regular_file(path, ec)) throw IOError("mesh file '" + path + "' is not a regular file");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IOError("cannot open mesh file '" + path + "'");
  f.seekg(0, std::ios::end);
  std::streamoff size = f.tellg();
  if (size < 0) throw IOError("cannot determine the size of '" + path + "'");
  f.seekg(0, std::ios::beg);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (size > 0 && !f.read(bytes.data(), size))
    throw IOError("cannot read '" + path + "' (" + std::to_string(size) + " bytes)");
  return bytes;
}

}  // namespace

PolygonSoup read_polygon_soup(const std::string& path) {
  std::string bytes = read_whole_file(path);
  if (bytes.empty()) throw IOError("'" + path + "' is empty (0 bytes)");
  std::string ext = lower_extension(path);
  Format fmt = ext == ".off"    ? Format::Off
               : ext == ".obj"  ? Format::Obj
               : ext == ".ply"  ? Format::Ply
               : ext == ".stl"  ? Format::Stl
               : ext == ".glb"  ? Format::Glb
               : ext == ".gltf" ? Format::Gltf
                                : sniff(bytes);
  if (ext != ".off" && ext != ".obj" && ext != ".ply" && ext != ".stl" && ext != ".glb" && ext != ".gltf") {
    const std::string image = image_signature(bytes);
    if (!image.empty())
      throw IOError("'" + path + "' is a " + image + " image, not a mesh (mesh formats: OFF, OBJ, PLY, STL, glTF)");
  }
  PolygonSoup soup;
  switch (fmt) {
    case Format::Off: soup = read_off(path, bytes); break;
    case Format::Obj:
      soup = read_obj(path, bytes);
      read_obj_materials(path, soup);
      break;
    case Format::Ply: soup = read_ply(path, bytes); break;
    case Format::Stl: soup = read_stl(path, bytes); break;
    case Format::Glb: soup = read_gltf(path, bytes, true); break;
    case Format::Gltf: soup = read_gltf(path, bytes, false); break;
    case Format::Unknown:
      throw IOError("'" + path + "': unknown mesh format (extension '" + ext +
                    "' and content is none of OFF, OBJ, PLY, STL, GLB)");
  }
  soup.source = path;
  if (soup.polygons.empty())
    throw InvalidInputError("'" + path + "' has no faces (" + std::to_string(soup.points.size()) + " points" +
                            (soup.short_polygons_dropped
                                 ? ", " + std::to_string(soup.short_polygons_dropped) +
                                       " shorter faces with < 3 vertices, first at " + soup.first_short_polygon
                                 : std::string()) +
                            ")");
  return soup;
}

// ---------------------------------------------------------------- soup -> mesh
namespace {

using Pos = std::array<double, 3>;

/// The distinct positions of a polygon, sorted: identifies it up to rotation,
/// reversal and removal of repeated vertices.
std::vector<Pos> polygon_key(const std::vector<Point3>& pts, const std::vector<std::size_t>& poly) {
  std::vector<Pos> k;
  k.reserve(poly.size());
  for (std::size_t i : poly) k.push_back(canonical_position({pts[i].x(), pts[i].y(), pts[i].z()}));
  std::sort(k.begin(), k.end());
  k.erase(std::unique(k.begin(), k.end()), k.end());
  return k;
}

/// Remembers which original face each triangle of triangulate_faces came from.
struct OriginVisitor {
  std::vector<std::size_t>* origin;  // indexed by face id; SIZE_MAX = untouched
  std::size_t* current;
  std::size_t* split;
  void before_subface_creations(FaceIndex f) {
    *current = static_cast<std::size_t>(f.idx());
    ++*split;
  }
  void after_subface_created(FaceIndex f) {
    std::size_t i = static_cast<std::size_t>(f.idx());
    if (origin->size() <= i) origin->resize(i + 1, SIZE_MAX);
    (*origin)[i] = *current;
  }
  void after_subface_creations() {}
};

/// The soup's per-point colours, per-corner UVs and per-polygon materials,
/// keyed by exact position (polygon keys: polygon_key) so that they survive
/// the repair's renumbering.
struct SoupAttributes {
  bool colors = false, uvs = false, materials = false;
  std::unordered_map<Pos, std::array<float, 3>, PositionHash> color_of;
  /// polygon key -> its corners (position, uv); the first polygon wins.
  std::map<std::vector<Pos>, std::vector<std::pair<Pos, UV>>> uv_source;
  /// polygon key -> its material; the first polygon wins.
  std::map<std::vector<Pos>, int> material_source;
};

/// Checks the soup's indices and attribute arrays (throws TopologyError for
/// no face, InvalidInputError for an index out of range or a size mismatch);
/// counts the input; says which attributes it carries.
SoupAttributes check_soup(const PolygonSoup& soup, const std::string& src, SoupRepairCounts& c) {
  SoupAttributes a;
  c.input_points = soup.points.size();
  c.input_polygons = soup.polygons.size();
  c.short_polygons_dropped = soup.short_polygons_dropped;
  if (soup.polygons.empty())
    throw TopologyError("'" + src + "' has no faces" +
                        (soup.short_polygons_dropped
                             ? " with 3 or more vertices (" + std::to_string(soup.short_polygons_dropped) +
                                   " shorter ones, first at " + soup.first_short_polygon + ")"
                             : std::string()));
  for (std::size_t i = 0; i < soup.polygons.size(); ++i)
    for (std::size_t v : soup.polygons[i])
      if (v >= soup.points.size())
        throw InvalidInputError("'" + src + "' polygon " + std::to_string(i) + ": index " +
                                std::to_string(v) + " out of range (" +
                                std::to_string(soup.points.size()) + " points)");
  a.colors = !soup.colors.empty();
  if (a.colors && soup.colors.size() != soup.points.size())
    throw InvalidInputError("'" + src + "': " + std::to_string(soup.colors.size()) + " colours for " +
                            std::to_string(soup.points.size()) + " points");
  if (!soup.polygon_uvs.empty()) {
    if (soup.polygon_uvs.size() != soup.polygons.size())
      throw InvalidInputError("'" + src + "': polygon_uvs does not match polygons");
    for (std::size_t i = 0; i < soup.polygons.size(); ++i) {
      const auto& pu = soup.polygon_uvs[i];
      if (pu.empty()) continue;
      if (pu.size() != soup.polygons[i].size())
        throw InvalidInputError("'" + src + "' polygon " + std::to_string(i) +
                                ": UV index count differs from its vertex count");
      for (std::size_t t : pu)
        if (t >= soup.uvs.size())
          throw InvalidInputError("'" + src + "' polygon " + std::to_string(i) + ": UV index " +
                                  std::to_string(t) + " out of range");
      a.uvs = true;
    }
  }
  a.materials = !soup.polygon_material.empty();
  if (a.materials) {
    if (soup.polygon_material.size() != soup.polygons.size())
      throw InvalidInputError("'" + src + "': polygon_material does not match polygons");
    for (std::size_t i = 0; i < soup.polygons.size(); ++i)
      if (soup.polygon_material[i] < -1 || soup.polygon_material[i] >= static_cast<int>(soup.materials.size()))
        throw InvalidInputError("'" + src + "' polygon " + std::to_string(i) + ": material " +
                                std::to_string(soup.polygon_material[i]) + " out of range (" +
                                std::to_string(soup.materials.size()) + " materials)");
  }
  return a;
}

/// Keys the soup's attributes by exact position, to map them through the
/// renumbering of the repair.
void key_attributes(const PolygonSoup& soup, const std::vector<Point3>& pts, SoupAttributes& a) {
  if (a.colors)
    for (std::size_t i = 0; i < soup.points.size(); ++i)
      a.color_of.emplace(canonical_position(soup.points[i]), soup.colors[i]);
  if (a.uvs)
    for (std::size_t i = 0; i < soup.polygons.size(); ++i) {
      if (soup.polygon_uvs[i].empty()) continue;
      auto key = polygon_key(pts, soup.polygons[i]);
      if (a.uv_source.count(key)) continue;
      std::vector<std::pair<Pos, UV>> corners;
      for (std::size_t k = 0; k < soup.polygons[i].size(); ++k) {
        const auto& uv = soup.uvs[soup.polygon_uvs[i][k]];
        corners.emplace_back(canonical_position(soup.points[soup.polygons[i][k]]), UV{uv[0], uv[1]});
      }
      a.uv_source.emplace(std::move(key), std::move(corners));
    }
  if (a.materials)
    for (std::size_t i = 0; i < soup.polygons.size(); ++i)
      a.material_source.emplace(polygon_key(pts, soup.polygons[i]), soup.polygon_material[i]);
}

/// The steps of PMP::repair_polygon_soup (CGAL 5.5, Polygon_soup_fixer), in
/// its order, called one by one so that each is counted. Throws TopologyError
/// when no face is left.
void repair_soup(std::vector<Point3>& pts, std::vector<std::vector<std::size_t>>& polys, const std::string& src,
                 SoupRepairCounts& c) {
  c.duplicate_points_merged = PMP::merge_duplicate_points_in_polygon_soup(pts, polys);
  c.polygons_simplified = PMP::internal::simplify_polygons_in_polygon_soup(pts, polys, Kernel());
  std::size_t before_split = polys.size();
  // Linear-time split first (CGAL's is quadratic in a polygon's corners).
  split_pinched_polygons(polys, pts.size());  // a polygon left with no cycle is emptied: removed and counted below
  PMP::internal::split_pinched_polygons_in_polygon_soup(pts, polys, Kernel());
  c.pinched_polygons_split = polys.size() - std::min(before_split, polys.size());
  c.degenerate_polygons_removed = PMP::internal::remove_invalid_polygons_in_polygon_soup(pts, polys);
  c.duplicate_polygons_removed = PMP::merge_duplicate_polygons_in_polygon_soup(pts, polys);
  c.isolated_points_removed = PMP::remove_isolated_points_in_polygon_soup(pts, polys);
  if (polys.empty())
    throw TopologyError("'" + src + "': no valid face left after repair (" +
                        std::to_string(c.input_polygons) + " polygons, " +
                        std::to_string(c.degenerate_polygons_removed) + " degenerate, " +
                        std::to_string(c.duplicate_polygons_removed) + " duplicates)");
}

/// Orients the repaired soup (duplicating the points it must) and converts it
/// into `mesh`: one vertex per point and one face per polygon, in order.
/// Throws TopologyError if it is still not a polygon mesh or loses elements.
void orient_and_convert(std::vector<Point3>& pts, std::vector<std::vector<std::size_t>>& polys,
                        const std::string& src, Mesh& mesh, SoupRepairCounts& c) {
  std::size_t before_orient = pts.size();
  c.oriented = PMP::orient_polygon_soup(pts, polys);
  c.points_duplicated_to_orient = pts.size() - before_orient;
  if (!PMP::is_polygon_soup_a_polygon_mesh(polys))
    throw TopologyError("'" + src + "': the repaired, oriented soup is still not a polygon mesh");
  mesh.clear();
  PMP::polygon_soup_to_polygon_mesh(pts, polys, mesh);
  if (mesh.number_of_vertices() != pts.size() || mesh.number_of_faces() != polys.size())
    throw TopologyError("'" + src + "': soup-to-mesh conversion lost elements (" +
                        std::to_string(mesh.number_of_faces()) + " of " +
                        std::to_string(polys.size()) + " faces)");
  // polygon_soup_to_polygon_mesh adds one vertex per point, in order, and one
  // face per polygon, in order, to the (empty) mesh.
}

/// The keyed attributes onto the mesh: vertex colours, corner UVs (counted:
/// found or dropped) and face materials.
void restore_attributes(const SoupAttributes& a, const std::vector<Point3>& pts,
                        const std::vector<std::vector<std::size_t>>& polys, Mesh& mesh, SoupRepairCounts& c) {
  if (a.colors) {
    auto cmap = get_or_add(mesh, kVertexColor, Color3f{0.f, 0.f, 0.f});
    for (VertexIndex v : mesh.vertices()) {
      const Point3& p = mesh.point(v);
      auto it = a.color_of.find(canonical_position({p.x(), p.y(), p.z()}));
      if (it != a.color_of.end()) cmap[v] = it->second;
    }
  }
  if (a.uvs) {
    auto uvmap = get_or_add(mesh, kCornerUV, UV{0.0, 0.0});
    for (FaceIndex f : mesh.faces()) {
      auto it = a.uv_source.find(polygon_key(pts, polys[f.idx()]));
      for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f))) {
        const Point3& p = mesh.point(mesh.target(h));
        const Pos key = canonical_position({p.x(), p.y(), p.z()});
        bool found = false;
        if (it != a.uv_source.end())
          for (const auto& [pos, uv] : it->second)
            if (pos == key) {
              uvmap[h] = uv;
              found = true;
              break;
            }
        ++(found ? c.uv_corners : c.uv_corners_dropped);
      }
    }
  }
  if (a.materials) {
    auto mat = get_or_add(mesh, kFaceMaterial, -1);
    for (FaceIndex f : mesh.faces()) {
      auto it = a.material_source.find(polygon_key(pts, polys[f.idx()]));
      mat[f] = it == a.material_source.end() ? -1 : it->second;
    }
  }
}

/// Fan triangulation, from its first corner, of every face triangulate_faces
/// left (it tries every face and leaves the ones it cannot split: degenerate
/// projection): possibly folded geometry, but valid topology, and counted so
/// that repair reports it.
void fan_triangulate_left(Mesh& mesh, OriginVisitor& vis, SoupRepairCounts& c) {
  std::vector<FaceIndex> left;
  for (FaceIndex f : mesh.faces())
    if (mesh.degree(f) > 3) left.push_back(f);
  for (FaceIndex f : left) {
    vis.before_subface_creations(f);
    HalfedgeIndex h0 = mesh.halfedge(f);
    while (mesh.next(mesh.next(mesh.next(h0))) != h0) {
      // Cut the triangle (h0's source, target(h0), target(next(h0))) off.
      HalfedgeIndex cut = CGAL::Euler::split_face(mesh.prev(h0), mesh.next(h0), mesh);
      vis.after_subface_created(mesh.face(h0));
      h0 = cut;  // split_face keeps the rest of the polygon on the new halfedge
    }
    vis.after_subface_created(mesh.face(h0));
    ++c.faces_fan_triangulated;
  }
}

/// PMP::triangulate_faces on a copy, then a fan for the faces it left. CGAL
/// 5.5's triangulate_faces can leave a broken halfedge structure (prev/next
/// mismatch) when it fails on a face (fuzz_off found an OFF file whose
/// polygons then sent every face circulator round forever): then the
/// original is fan-triangulated instead, every face from its first corner.
void triangulate_or_fan(Mesh& mesh, OriginVisitor& vis, SoupRepairCounts& c) {
  const auto faces = mesh.faces();
  if (std::all_of(faces.begin(), faces.end(), [&](FaceIndex f) { return mesh.degree(f) == 3; })) return;
  Mesh trial = mesh;  // only meshes with polygons pay for the copy
  const bool done = PMP::triangulate_faces(trial, CGAL::parameters::visitor(vis));
  if (done || CGAL::is_valid_polygon_mesh(trial)) {
    mesh = std::move(trial);
    if (!done) fan_triangulate_left(mesh, vis, c);
    return;
  }
  vis.origin->assign(vis.origin->size(), SIZE_MAX);
  *vis.current = 0;
  *vis.split = 0;
  fan_triangulate_left(mesh, vis, c);
}

/// Triangulates the non-triangular faces (PMP::triangulate_faces, then a fan
/// for those it leaves), each triangle keeping its face's material and
/// corner UVs.
void triangulate_keeping_attributes(Mesh& mesh, bool has_materials, SoupRepairCounts& c) {
  std::vector<std::size_t> origin(mesh.number_of_faces(), SIZE_MAX);
  std::vector<int> material_before;  // by face index, before splitting
  if (has_materials) {
    auto mat = find(mesh, kFaceMaterial).first;
    for (FaceIndex f : mesh.faces()) material_before.push_back(mat[f]);
  }
  std::size_t current = 0, split = 0;
  // UVs of the corners of each non-triangular face, before it is split.
  std::unordered_map<std::size_t, std::vector<std::pair<VertexIndex, UV>>> face_uvs;
  auto uvm = find(mesh, kCornerUV);
  if (uvm.second)
    for (FaceIndex f : mesh.faces()) {
      if (mesh.degree(f) == 3) continue;
      auto& list = face_uvs[f.idx()];
      for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f)))
        list.emplace_back(mesh.target(h), uvm.first[h]);
    }
  OriginVisitor vis{&origin, &current, &split};
  triangulate_or_fan(mesh, vis, c);
  c.faces_triangulated = split;
  uvm = find(mesh, kCornerUV);  // the mesh may be the triangulated copy
  if (has_materials) {
    auto mat = find(mesh, kFaceMaterial).first;
    for (FaceIndex f : mesh.faces()) {
      std::size_t i = f.idx();
      if (i < origin.size() && origin[i] != SIZE_MAX) mat[f] = material_before[origin[i]];
    }
  }
  if (uvm.second)
    for (FaceIndex f : mesh.faces()) {
      std::size_t i = f.idx();
      if (i >= origin.size() || origin[i] == SIZE_MAX) continue;
      const auto& list = face_uvs[origin[i]];
      for (HalfedgeIndex h : mesh.halfedges_around_face(mesh.halfedge(f)))
        for (const auto& [v, uv] : list)
          if (v == mesh.target(h)) {
            uvm.first[h] = uv;
            break;
          }
    }
}

}  // namespace

void soup_to_mesh(PolygonSoup soup, Mesh& mesh, const SoupToMeshOptions& opt, SoupRepairCounts* out) {
  SoupRepairCounts c;
  const std::string& src = soup.source.empty() ? std::string("polygon soup") : soup.source;
  SoupAttributes attributes = check_soup(soup, src, c);
  std::vector<Point3> pts;
  pts.reserve(soup.points.size());
  for (const auto& p : soup.points) pts.emplace_back(p[0], p[1], p[2]);
  key_attributes(soup, pts, attributes);
  auto& polys = soup.polygons;
  repair_soup(pts, polys, src, c);
  orient_and_convert(pts, polys, src, mesh, c);
  restore_attributes(attributes, pts, polys, mesh, c);
  if (opt.triangulate) triangulate_keeping_attributes(mesh, attributes.materials, c);
  c.output_vertices = mesh.number_of_vertices();
  c.output_faces = mesh.number_of_faces();
  if (out) *out = c;
}

void read_mesh(const std::string& path, Mesh& mesh, const SoupToMeshOptions& opt, SoupRepairCounts* counts) {
  soup_to_mesh(read_polygon_soup(path), mesh, opt, counts);
}

MeshFileContents read_mesh_file(const std::string& path, Mesh& mesh, const SoupToMeshOptions& opt) {
  PolygonSoup soup = read_polygon_soup(path);
  MeshFileContents out;
  out.materials = soup.materials;  // (soup_to_mesh checks the indices against them)
  out.files_read.push_back(path);
  for (std::string& f : soup.files_read) out.files_read.push_back(std::move(f));
  out.warnings = std::move(soup.warnings);
  soup_to_mesh(std::move(soup), mesh, opt, &out.counts);
  return out;
}

}  // namespace surftex
