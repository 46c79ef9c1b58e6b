// SPDX-License-Identifier: AGPL-3.0-or-later
#include "test_support.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace surftex::test {

namespace {
std::string read_all(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}
}  // namespace

std::string shared_data(const std::string& rel) {
  const char* env = std::getenv("SURFTEX_SHARED_DATA");
  fs::path p = fs::path(env ? env : SURFTEX_SHARED_DATA_DIR) / rel;
  if (!fs::exists(p)) {
    ADD_FAILURE() << "shared test data missing: " << p
                  << " (clone surftex beside shared/, or set SURFTEX_SHARED_DATA)";
  }
  return p.string();
}

std::string cgal_data(const std::string& name) {
  fs::path p = fs::path(SURFTEX_CGAL_DATA_DIR) / name;
  if (!fs::exists(p))
    ADD_FAILURE() << "CGAL data file missing: " << p << " (install libcgal-demo, reconfigure)";
  return p.string();
}

std::string temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  fs::path p = fs::temp_directory_path() /
               ("surftex-test-" + tag + "-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter.fetch_add(1)));
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

RunResult run_surftex(const std::string& args) {
  std::string dir = temp_dir("run");
  std::string out = dir + "/stdout", err = dir + "/stderr";
  std::string cmd = std::string("'") + SURFTEX_BINARY + "' " + args + " >'" + out + "' 2>'" + err + "' </dev/null";
  int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  r.out = read_all(out);
  r.err = read_all(err);
  fs::remove_all(dir);
  return r;
}

}  // namespace surftex::test
