// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Shared helpers for the test suites: where the real data lives, temporary
// folders, running the surftex binary.
#include <string>

namespace surftex::test {

/// ../shared/data (meshes/, broken/, textures/, swatches/), or $SURFTEX_SHARED_DATA.
/// Fails the test (never skips) if absent.
std::string shared_data(const std::string& rel);
/// A file from CGAL's data set (extracted from Debian's libcgal-demo at configure time).
std::string cgal_data(const std::string& name);
/// A fresh empty temporary folder, unique per call.
std::string temp_dir(const std::string& tag);

struct RunResult {
  int exit_code = -1;
  std::string out, err;
};
/// Runs the built `surftex` binary with `args` (shell-quoted by the caller).
RunResult run_surftex(const std::string& args);

}  // namespace surftex::test
