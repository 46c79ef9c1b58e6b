// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Safe output (brief: "no half-written output, nothing the user gave is
// overwritten silently"). Every writer writes to a temporary file beside the
// destination and renames it into place only when complete.

#include <string>

namespace surftex {

class AtomicOutputFile {
 public:
  /// Prepares a temporary path beside `destination` (same folder, same
  /// extension so format-sniffing writers behave). Throws IOError if the
  /// destination exists and !overwrite, or its folder does not exist.
  explicit AtomicOutputFile(std::string destination, bool overwrite = true);
  ~AtomicOutputFile();  // removes the temporary if commit() was not reached
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& destination() const { return dest_; }
  /// Renames the temporary onto the destination. Throws IOError.
  void commit();

 private:
  std::string dest_, temp_;
  bool committed_ = false;
};

/// Writes `bytes` to `path` atomically.
void write_file_atomic(const std::string& path, const std::string& bytes, bool overwrite = true);

/// Creates `dir` (and parents) if absent. Throws IOError if it cannot, or if
/// it exists and is not a folder.
void ensure_directory(const std::string& dir);

/// True when both paths name the same existing file (after resolving links).
bool same_file(const std::string& a, const std::string& b);

}  // namespace surftex
