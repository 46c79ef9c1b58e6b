// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Shared helpers for the test suites: where the real data lives, temporary
// folders, running the surftex binary.
#include <nlohmann/json_fwd.hpp>

#include <string>
#include <vector>

namespace surftex::test {

/// ../shared/data (meshes/, broken/, textures/, swatches/), or $SURFTEX_SHARED_DATA.
/// Fails the test (never skips) if absent.
std::string shared_data(const std::string& rel);
/// A file from CGAL's data set (extracted from Debian's libcgal-demo at configure time).
std::string cgal_data(const std::string& name);
/// A fresh empty temporary folder, unique per call.
std::string temp_dir(const std::string& tag);
/// The whole file, bytes as they are ("" if it cannot be read).
std::string file_bytes(const std::string& path);
/// Writes `text` to `path`, creating its folders.
void write_text_file(const std::string& path, const std::string& text);
/// Writes `bytes` to dir/name (as they are) and returns that path.
std::string write_file(const std::string& dir, const std::string& name, const std::string& bytes);
/// The JSON document in `path` (throws if it cannot be parsed).
nlohmann::json read_json(const std::string& path);
/// `s` in single quotes, for a shell command line (paths without quotes).
std::string q(const std::string& s);
/// True in the sanitizer suite (SURFTEX_SANITIZED set): tests shrink their work.
bool sanitized();
/// Coefficient of variation (standard deviation over mean) of counts.
double cv(const std::vector<long long>& counts);

struct RunResult {
  int exit_code = -1;
  std::string out, err;
};
/// Runs the built `surftex` binary with `args` (shell-quoted by the caller).
RunResult run_surftex(const std::string& args);

/// The Khronos glTF-Validator's counts for one file (tests/tools/validate_glb.js).
struct GlbValidation {
  std::string file;
  int errors = -1, warnings = -1, infos = -1, hints = -1;
  std::string messages;  ///< the errors and warnings, one per line
};
/// Validates `files` in one run of the validator (scripts/setup.sh installs it
/// into BUILD/tools/gltf-validator). Fails the test if it cannot run.
std::vector<GlbValidation> validate_glbs(const std::vector<std::string>& files);

/// Every GLB file (a .glb starting with the "glTF" magic) in the temporary
/// folders a test made with temp_dir() is validated when the test ends: any
/// error or warning fails the test. A test that writes a broken GLB on
/// purpose names it here to leave it out.
void skip_glb_validation(const std::string& path);

}  // namespace surftex::test
