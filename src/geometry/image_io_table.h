// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Internal: the entry points of the image IO module. OpenImageIO and the ~260
// shared libraries it pulls in (codecs, OpenCV, GDAL, ...) cost about 0.4 s
// of symbol relocation at process start, so they are not linked into the
// executables: image_io.cpp is built as a loadable module
// (libsurftex_image_io.so, image_io_module/) that image_io_loader.cpp opens
// on the first image read or write. The module resolves the rest of surftex
// (output_file.h, ...) against the executable, which exports its surftex::
// symbols (cmake/surftex_exports.list), so there is one copy of that code
// and its state. Adding a function to image_io.h means adding it here, in
// image_io_module/image_io_table.cpp and in image_io_loader.cpp.
// docs/decisions/503-lazy-image-io.md has the measurements.

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
