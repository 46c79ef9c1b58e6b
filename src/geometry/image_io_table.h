// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Internal: the entry points of the image IO module. OpenImageIO and its
// shared libraries are costly to relocate at start (docs/decisions/503), so
// image_io.cpp is a loadable module (libsurftex_image_io.so) opened on first
// use, resolving the rest of surftex against the executable's exports
// (cmake/surftex_exports.list). A new image_io.h function goes here, in
// image_io_module/image_io_table.cpp and in image_io_loader.cpp.

#include <string>
#include <vector>

#include "geometry/image_io.h"

namespace surftex {

struct ImageIoTable {
  int version;  ///< kImageIoTableVersion of the module
  Image (*read_image)(const std::string&);
  std::vector<Image> (*read_image_layers)(const std::string&);
  void (*write_image)(const std::string&, const Image&, const WriteImageOptions&);
  void (*write_image_layers)(const std::string&, const std::vector<Image>&, const WriteImageOptions&);
  ImageHeader (*read_image_header)(const std::string&, const ImageLimits&);
};

constexpr int kImageIoTableVersion = 2;

}  // namespace surftex

/// Exported by the module (C linkage for dlsym).
extern "C" const surftex::ImageIoTable* surftex_image_io_table();
