// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/output_file.h"

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>

#include "geometry/errors.h"

namespace fs = std::filesystem;

namespace surftex {

namespace {
std::string make_temp_name(const fs::path& dest) {
  static std::atomic<unsigned> counter{0};
  fs::path dir = dest.parent_path();
  std::string stem = ".surftex-tmp-" + std::to_string(::getpid()) + "-" +
                     std::to_string(counter.fetch_add(1)) + "-" + dest.stem().string();
  return (dir / (stem + dest.extension().string())).string();
}
}  // namespace

AtomicOutputFile::AtomicOutputFile(std::string destination, bool overwrite)
    : dest_(std::move(destination)) {
  if (dest_.empty()) throw IOError("output path is empty");
  fs::path d(dest_);
  std::error_code ec;
  fs::path dir = d.parent_path().empty() ? fs::path(".") : d.parent_path();
  if (!fs::is_directory(dir, ec))
    throw IOError("cannot write '" + dest_ + "': folder '" + dir.string() + "' does not exist");
  if (fs::exists(d, ec)) {
    if (fs::is_directory(d, ec))
      throw IOError("cannot write '" + dest_ + "': it is a folder");
    if (!overwrite)
      throw IOError("output '" + dest_ + "' already exists (pass --force to replace it)");
  }
  temp_ = make_temp_name(d);
}

AtomicOutputFile::~AtomicOutputFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
}

void AtomicOutputFile::commit() {
  std::error_code ec;
  if (!fs::exists(temp_, ec))
    throw IOError("internal: temporary for '" + dest_ + "' was not written");
  fs::rename(temp_, dest_, ec);
  if (ec) throw IOError("cannot rename temporary onto '" + dest_ + "': " + ec.message());
  committed_ = true;
}

void write_file_atomic(const std::string& path, const std::string& bytes, bool overwrite) {
  AtomicOutputFile out(path, overwrite);
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    if (!f) throw IOError("cannot open '" + out.temp_path() + "' for writing");
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) throw IOError("write to '" + path + "' failed (disk full?)");
  }
  out.commit();
}

void ensure_directory(const std::string& dir) {
  std::error_code ec;
  fs::path p(dir);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw IOError("'" + dir + "' exists and is not a folder");
    return;
  }
  fs::create_directories(p, ec);
  if (ec) throw IOError("cannot create folder '" + dir + "': " + ec.message());
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (!fs::exists(a, ec) || !fs::exists(b, ec)) return false;
  return fs::equivalent(a, b, ec);
}

}  // namespace surftex
