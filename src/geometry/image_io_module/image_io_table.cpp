// SPDX-License-Identifier: AGPL-3.0-or-later
// The image IO module's table of entry points (geometry/image_io_table.h);
// linked with -Bsymbolic-functions so that these are the module's own
// definitions, not the executable's forwarding ones.
#include "geometry/image_io_table.h"

extern "C" const surftex::ImageIoTable* surftex_image_io_table() {
  static const surftex::ImageIoTable table{surftex::kImageIoTableVersion, &surftex::read_image,
                                           &surftex::read_image_layers, &surftex::write_image,
                                           &surftex::write_image_layers, &surftex::read_image_header};
  return &table;
}
