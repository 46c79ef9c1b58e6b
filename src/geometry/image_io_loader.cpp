// SPDX-License-Identifier: AGPL-3.0-or-later
// image_io.h's functions, forwarded to the image IO module loaded on first
// use (geometry/image_io_table.h explains why). The module is looked up at
// $SURFTEX_IMAGE_IO_MODULE, then beside the executable (../lib/ and ./),
// then at its build-tree path.
#include <dlfcn.h>
#include <limits.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/image_io_table.h"
#include "geometry/output_file.h"

namespace surftex {
namespace {

constexpr const char* kModuleName = "libsurftex_image_io.so";

std::vector<std::string> module_candidates() {
  std::vector<std::string> c;
  if (const char* env = std::getenv("SURFTEX_IMAGE_IO_MODULE"); env && *env) c.push_back(env);
  char exe[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  if (n > 0) {
    exe[n] = '\0';
    const std::filesystem::path dir = std::filesystem::path(exe).parent_path();
    c.push_back((dir.parent_path() / "lib" / kModuleName).string());
    c.push_back((dir / kModuleName).string());
  }
  c.push_back(SURFTEX_IMAGE_IO_MODULE_PATH);
  return c;
}

const ImageIoTable* load_module() {
  std::string tried;
  for (const std::string& path : module_candidates()) {
    if (!std::filesystem::exists(path)) {
      tried += "\n  " + path + ": absent";
      continue;
    }
    void* h = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!h) {
      tried += "\n  " + path + ": " + ::dlerror();
      continue;
    }
    using Entry = const ImageIoTable* (*)();
    auto entry = reinterpret_cast<Entry>(::dlsym(h, "surftex_image_io_table"));
    const ImageIoTable* t = entry ? entry() : nullptr;
    if (t && t->version == kImageIoTableVersion) return t;  // kept loaded for the process
    tried += "\n  " + path + ": not a surftex image IO module of this version";
    ::dlclose(h);
  }
  throw IOError("cannot load the image IO module (OpenImageIO); tried:" + tried);
}

const ImageIoTable& table() {
  static const ImageIoTable* t = load_module();  // thread-safe; retried if it threw
  return *t;
}

}  // namespace

// The module calls output_file.h's functions in the executable: this
// reference keeps them linked into every executable that does image IO.
// (Non-const: a const object at namespace scope would have internal linkage
// and be dropped with the reference.)
void (AtomicOutputFile::*image_io_module_needs_commit)() = &AtomicOutputFile::commit;
// The same for the image limits (geometry/image_limits.cpp), which the module reads.
const ImageLimits& (*image_io_module_needs_limits)() = &image_limits;
long long (ImageLimits::*image_io_module_needs_max_side)() const = &ImageLimits::max_side;

Image read_image(const std::string& path) { return table().read_image(path); }

ImageHeader read_image_header(const std::string& path, const ImageLimits& limits) {
  return table().read_image_header(path, limits);
}

std::vector<Image> read_image_layers(const std::string& path) { return table().read_image_layers(path); }

void write_image(const std::string& path, const Image& img, const WriteImageOptions& opt) {
  table().write_image(path, img, opt);
}

void write_image_layers(const std::string& path, const std::vector<Image>& layers, const WriteImageOptions& opt) {
  table().write_image_layers(path, layers, opt);
}

}  // namespace surftex
