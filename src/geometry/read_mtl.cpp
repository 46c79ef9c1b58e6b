// SPDX-License-Identifier: AGPL-3.0-or-later
// The .mtl files of an OBJ (Wavefront "Material Template Library"): newmtl
// starts a material, Kd is its diffuse colour, map_Kd its diffuse texture
// (options such as -s u v, -o u v, -bm b, -clamp on are skipped: surftex maps
// the texture as it is). Other statements (Ka, Ks, Ns, d, illum, map_Bump,
// ...) are ignored. A missing .mtl, or a usemtl name no .mtl defines, leaves
// the material with its name and white colour and adds a warning: real OBJs
// often reference .mtl files that were not shipped with them.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "geometry/errors.h"
#include "geometry/mesh_parsers.h"

namespace fs = std::filesystem;

namespace surftex::mesh_io {

namespace {

// Arguments taken by each map_* option (MTL specification).
int option_arguments(std::string_view opt) {
  static const std::map<std::string_view, int> n = {
      {"-blendu", 1}, {"-blendv", 1}, {"-bm", 1},      {"-boost", 1}, {"-cc", 1},
      {"-clamp", 1},  {"-imfchan", 1}, {"-mm", 2},     {"-o", 3},     {"-s", 3},
      {"-t", 3},      {"-texres", 1}, {"-type", 1}};
  auto it = n.find(opt);
  return it == n.end() ? -1 : it->second;
}

bool is_number(std::string_view t) {
  double v = 0;
  return parse_double(t, v);
}

// The file name of a map_Kd line: the text after the options (it may hold blanks).
std::string map_file_name(std::string_view rest) {
  std::vector<std::string_view> tok;
  split_blanks(rest, tok);
  std::size_t i = 0;
  while (i < tok.size() && tok[i].size() > 1 && tok[i][0] == '-') {
    const int n = option_arguments(tok[i]);
    if (n < 0) break;
    // -o, -s, -t take 1 to 3 numbers; the others exactly n arguments.
    const bool up_to_n_numbers = tok[i] == "-o" || tok[i] == "-s" || tok[i] == "-t";
    ++i;
    for (int k = 0; k < n && i < tok.size(); ++k, ++i)
      if (up_to_n_numbers && k > 0 && !is_number(tok[i])) break;
  }
  if (i >= tok.size()) return {};
  const std::size_t start = static_cast<std::size_t>(tok[i].data() - rest.data());
  std::string name(rest.substr(start));
  while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.pop_back();
  std::replace(name.begin(), name.end(), '\\', '/');  // files written on Windows
  return name;
}

struct MtlEntry {
  std::array<float, 3> kd{1.f, 1.f, 1.f};
  bool has_kd = false;
  std::string map_kd;  // resolved path
  std::string origin;
};

void parse_mtl(const std::string& mtl_path, const std::string& text, std::map<std::string, MtlEntry>& out) {
  TextLines lines(mtl_path, text);
  std::string_view raw;
  std::vector<std::string_view> tok;
  MtlEntry* cur = nullptr;
  const fs::path dir = fs::path(mtl_path).parent_path();
  while (lines.next(raw)) {
    const std::string_view line = strip_comment(raw);
    split_blanks(line, tok);
    if (tok.empty()) continue;
    const std::string_view rest = line.substr(static_cast<std::size_t>(tok[0].data() - line.data()) + tok[0].size());
    if (tok[0] == "newmtl") {
      std::string name(rest);
      name.erase(0, name.find_first_not_of(" \t"));
      while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.pop_back();
      cur = &out[name];  // the first definition of a name wins (later ones refill it)
      *cur = MtlEntry{};
    } else if (cur && tok[0] == "Kd" && tok.size() >= 4) {
      std::array<float, 3> c{};
      bool ok = true;
      for (int k = 0; k < 3; ++k) {
        double v = 0;
        ok = ok && parse_double(tok[1 + k], v) && std::isfinite(v);
        c[k] = static_cast<float>(std::clamp(v, 0.0, 1.0));
      }
      if (!ok) fail_io(mtl_path, at_line(lines.line_no()), "bad Kd colour " + show(raw));
      cur->kd = c;
      cur->has_kd = true;
    } else if (cur && tok[0] == "map_Kd") {
      const std::string name = map_file_name(rest);
      if (name.empty()) fail_io(mtl_path, at_line(lines.line_no()), "map_Kd without a file name");
      const fs::path p(name);
      cur->map_kd = (p.is_absolute() ? p : dir / p).lexically_normal().string();
      cur->origin = "map_Kd in '" + mtl_path + "' " + at_line(lines.line_no());
    }
  }
}

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  if (!f && !f.eof()) throw IOError("cannot read '" + path + "'");
  return ss.str();
}

// The .mtl files of one mtllib statement: the whole text if it names a file,
// else its blank-separated names.
std::vector<fs::path> library_files(const fs::path& dir, const std::string& stmt) {
  std::error_code ec;
  if (fs::is_regular_file(dir / stmt, ec)) return {dir / stmt};
  std::vector<std::string_view> tok;
  split_blanks(stmt, tok);
  std::vector<fs::path> files;
  for (auto t : tok) files.push_back(dir / std::string(t));
  return files;
}

}  // namespace

void read_obj_materials(const std::string& obj_path, PolygonSoup& soup) {
  if (soup.materials.empty() && soup.material_libraries.empty()) return;
  const fs::path dir = fs::path(obj_path).parent_path();
  std::map<std::string, MtlEntry> defined;
  for (const std::string& stmt : soup.material_libraries)
    for (const fs::path& f : library_files(dir, stmt)) {
      std::error_code ec;
      if (!fs::is_regular_file(f, ec)) {
        soup.warnings.push_back("mtllib '" + f.string() + "' does not exist: materials keep their names only");
        continue;
      }
      const std::string text = read_text(f.string());
      if (text.size() > (64u << 20)) throw IOError("'" + f.string() + "' is larger than 64 MiB: not a material library");
      parse_mtl(f.string(), text, defined);
      soup.files_read.push_back(f.string());
    }
  for (MeshMaterial& m : soup.materials) {
    auto it = defined.find(m.name);
    if (it == defined.end()) {
      if (!soup.material_libraries.empty())
        soup.warnings.push_back("material '" + m.name + "' (usemtl) is not defined in any mtllib");
      continue;
    }
    const MtlEntry& e = it->second;
    m.texture_file = e.map_kd;
    m.texture_origin = e.origin;
    // Blender's OBJ importer shows map_Kd alone (Kd ignored) when both are given.
    m.base_color = e.map_kd.empty() && e.has_kd ? e.kd : std::array<float, 3>{1.f, 1.f, 1.f};
  }
}

}  // namespace surftex::mesh_io
