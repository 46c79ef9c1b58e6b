// SPDX-License-Identifier: AGPL-3.0-or-later
#include "fuzz_targets.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string_view>

#include "geometry/errors.h"
#include "geometry/image.h"
#include "geometry/image_io.h"
#include "texture/material_space/material_constraints.h"
#include "geometry/mesh.h"
#include "geometry/mesh_parsers.h"
#include "geometry/primitive_meshes.h"
#include "geometry/read_mesh.h"
#include "texture/material_space/material_tile_io.h"

namespace fs = std::filesystem;

namespace surftex::fuzz {

namespace {

// A private scratch folder for inputs that the readers take as files.
const std::string& scratch() {
  static const std::string dir = [] {
    const fs::path p = fs::temp_directory_path() / ("surftex-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(p);
    return p.string();
  }();
  return dir;
}

void write_bytes(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// Parse, then (for small soups) turn into a mesh: the repair of a hostile
// soup is exercised too.
using Parser = PolygonSoup (*)(const std::string&, std::string_view);
int parse_mesh(Parser parse, const char* name, const std::uint8_t* data, std::size_t size) {
  try {
    PolygonSoup soup = parse(name, std::string_view(reinterpret_cast<const char*>(data), size));
    soup.source = name;
    std::size_t corners = 0;
    for (const auto& p : soup.polygons) corners += p.size();
    if (!soup.polygons.empty() && corners <= 4096) {
      Mesh m;
      soup_to_mesh(std::move(soup), m);
    }
  } catch (const Error&) {
  }
  return 0;
}

// The image limits of one input (restored after it: the test suite replays
// the bodies in a process that reads other images too).
struct SmallImages {
  ImageLimits saved = image_limits();
  SmallImages() {
    ImageLimits small;
    small.max_pixels = 1 << 16;
    set_image_limits(small);
  }
  ~SmallImages() { set_image_limits(saved); }
};

// A binary glTF from bytes (the reader's external-file paths are not taken:
// a GLB carries its buffers).
PolygonSoup read_glb_bytes(const std::string& path, std::string_view data) {
  return mesh_io::read_gltf(path, data, true);
}

}  // namespace

int one_obj(const std::uint8_t* d, std::size_t n) { return parse_mesh(mesh_io::read_obj, "fuzz.obj", d, n); }
int one_off(const std::uint8_t* d, std::size_t n) { return parse_mesh(mesh_io::read_off, "fuzz.off", d, n); }
int one_ply(const std::uint8_t* d, std::size_t n) { return parse_mesh(mesh_io::read_ply, "fuzz.ply", d, n); }
int one_stl(const std::uint8_t* d, std::size_t n) { return parse_mesh(mesh_io::read_stl, "fuzz.stl", d, n); }
int one_glb(const std::uint8_t* d, std::size_t n) { return parse_mesh(read_glb_bytes, "fuzz.glb", d, n); }

// The header check on any bytes (as PNG, JPEG, TIFF, EXR: OpenImageIO picks
// the reader from the content for a file without extension); an image that
// passes it at a small limit is decoded too.
int one_image_header(const std::uint8_t* d, std::size_t n) {
  const std::string path = scratch() + "/image";
  write_bytes(path, d, n);
  SmallImages limits;
  try {
    (void)read_image_header(path);
    (void)read_image(path);
  } catch (const Error&) {
  }
  return 0;
}

int one_constraints(const std::uint8_t* d, std::size_t n) {
  static const Mesh mesh = [] {
    Mesh m;
    make_icosphere(m, 2);
    return m;
  }();
  try {
    (void)parse_material_constraints(std::string(reinterpret_cast<const char*>(d), n), mesh, "fuzz.json");
  } catch (const Error&) {
  }
  return 0;
}

// tile.json in a folder holding two small valid layers (layer_000.png,
// layer_001.png, 8x8 RGB) that a hostile description may point at.
int one_tile_json(const std::uint8_t* d, std::size_t n) {
  static const std::string dir = [] {
    const std::string t = scratch() + "/tile";
    fs::create_directories(t);
    write_image(t + "/layer_000.png", Image(8, 8, 3, 0.25f));
    write_image(t + "/layer_001.png", Image(8, 8, 3, 0.75f));
    return t;
  }();
  write_bytes(dir + "/tile.json", d, n);
  SmallImages limits;
  try {
    (void)read_material_tile(dir);
  } catch (const Error&) {
  }
  return 0;
}

const std::vector<Target>& targets() {
  static const std::vector<Target> t{{"fuzz_obj", one_obj},
                                     {"fuzz_off", one_off},
                                     {"fuzz_ply", one_ply},
                                     {"fuzz_stl", one_stl},
                                     {"fuzz_glb", one_glb},
                                     {"fuzz_image_header", one_image_header},
                                     {"fuzz_constraints", one_constraints},
                                     {"fuzz_tile_json", one_tile_json}};
  return t;
}

}  // namespace surftex::fuzz
