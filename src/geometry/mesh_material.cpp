// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/mesh_material.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>

#include "geometry/errors.h"
#include "geometry/image_io.h"

namespace fs = std::filesystem;

namespace surftex {

namespace {

// The file extension OpenImageIO needs for encoded bytes (PNG and JPEG are
// what glTF 2.0 allows in a base-colour texture).
std::string encoded_extension(const std::string& b) {
  if (b.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) == 0) return ".png";
  if (b.compare(0, 3, std::string("\xff\xd8\xff", 3)) == 0) return ".jpg";
  return {};
}

// Decoded through a temporary file, so that the bytes pass the same checks
// as any image a user gives (image_io.h).
Image decode_bytes(const MeshMaterial& m) {
  const std::string ext = encoded_extension(m.texture_bytes);
  if (ext.empty())
    throw IOError("texture of material '" + m.name + "' (" + m.texture_origin +
                  ") is neither PNG nor JPEG: surftex cannot decode it");
  static std::atomic<unsigned> counter{0};
  const fs::path tmp = fs::temp_directory_path() / ("surftex-texture-" + std::to_string(::getpid()) + "-" +
                                                    std::to_string(counter.fetch_add(1)) + ext);
  struct Remove {
    fs::path p;
    ~Remove() {
      std::error_code ec;
      fs::remove(p, ec);
    }
  } remove{tmp};
  {
    std::ofstream f(tmp, std::ios::binary);
    f.write(m.texture_bytes.data(), static_cast<std::streamsize>(m.texture_bytes.size()));
    if (!f) throw IOError("cannot write a temporary file to decode the texture of material '" + m.name + "'");
  }
  try {
    return read_image(tmp.string());
  } catch (const Error& e) {
    throw IOError("texture of material '" + m.name + "' (" + m.texture_origin + ") cannot be decoded: " + e.what());
  }
}

}  // namespace

void load_material_textures(std::vector<MeshMaterial>& materials) {
  for (MeshMaterial& m : materials) {
    if (!m.texture_bytes.empty()) {
      m.texture = decode_bytes(m);
    } else if (!m.texture_file.empty()) {
      std::error_code ec;
      if (!fs::is_regular_file(m.texture_file, ec))
        throw IOError("texture '" + m.texture_file + "' of material '" + m.name + "' (" + m.texture_origin +
                      ") does not exist");
      m.texture = read_image(m.texture_file);
    }
  }
}

}  // namespace surftex
