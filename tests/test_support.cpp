// SPDX-License-Identifier: AGPL-3.0-or-later
#include "test_support.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

namespace fs = std::filesystem;

namespace surftex::test {

std::string file_bytes(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_text_file(const std::string& path, const std::string& text) {
  const fs::path p(path);
  if (p.has_parent_path()) fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

std::string write_file(const std::string& dir, const std::string& name, const std::string& bytes) {
  const std::string p = dir + "/" + name;
  write_text_file(p, bytes);
  return p;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::string q(const std::string& s) { return "'" + s + "'"; }

bool sanitized() { return std::getenv("SURFTEX_SANITIZED") != nullptr; }

double cv(const std::vector<long long>& counts) {
  double mean = 0, var = 0;
  for (long long v : counts) mean += static_cast<double>(v);
  mean /= static_cast<double>(counts.size());
  for (long long v : counts) var += (v - mean) * (v - mean);
  return std::sqrt(var / static_cast<double>(counts.size())) / mean;
}

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

namespace {
// The temporary folders of the running test, and the GLBs to leave out.
struct TestFolders {
  std::mutex mu;
  std::vector<std::string> dirs, skipped;
};
TestFolders& test_folders() {
  static TestFolders t;
  return t;
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

bool starts_with_gltf_magic(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  char m[4] = {};
  return f.read(m, 4) && std::string(m, 4) == "glTF";
}

// Validates the GLBs of the test that just ended (gtest calls the listeners'
// OnTestEnd in reverse order, so a failure added here still counts for it).
class GlbValidationListener : public testing::EmptyTestEventListener {
  void OnTestStart(const testing::TestInfo&) override {
    std::lock_guard<std::mutex> lock(test_folders().mu);
    test_folders().dirs.clear();
    test_folders().skipped.clear();
  }
  void OnTestEnd(const testing::TestInfo&) override {
    std::vector<std::string> files;
    {
      std::lock_guard<std::mutex> lock(test_folders().mu);
      for (const std::string& d : test_folders().dirs) {
        std::error_code ec;
        for (auto it = fs::recursive_directory_iterator(d, ec); !ec && it != fs::recursive_directory_iterator();
             it.increment(ec)) {
          const fs::path p = it->path();
          std::string ext = p.extension().string();
          std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
          if (ext != ".glb" || !it->is_regular_file(ec) || !starts_with_gltf_magic(p)) continue;
          const auto& sk = test_folders().skipped;
          if (std::find(sk.begin(), sk.end(), p.string()) == sk.end()) files.push_back(p.string());
        }
      }
    }
    if (files.empty()) return;
    std::sort(files.begin(), files.end());
    const std::vector<GlbValidation> results = validate_glbs(files);
    // SURFTEX_GLB_VALIDATION_LOG=FILE appends every file's counts (to total
    // them over a whole test run).
    if (const char* log = std::getenv("SURFTEX_GLB_VALIDATION_LOG")) {
      std::ofstream out(log, std::ios::app);
      for (const GlbValidation& v : results)
        out << v.file << " errors " << v.errors << " warnings " << v.warnings << " infos " << v.infos << " hints "
            << v.hints << "\n";
    }
    for (const GlbValidation& v : results)
      if (v.errors != 0 || v.warnings != 0)
        ADD_FAILURE() << "glTF-Validator: " << v.file << ": " << v.errors << " errors, " << v.warnings
                      << " warnings\n" << v.messages;
  }
};

struct RegisterListener {
  RegisterListener() { testing::UnitTest::GetInstance()->listeners().Append(new GlbValidationListener); }
} register_listener;
}  // namespace

void skip_glb_validation(const std::string& path) {
  std::lock_guard<std::mutex> lock(test_folders().mu);
  test_folders().skipped.push_back(fs::path(path).string());
}

std::vector<GlbValidation> validate_glbs(const std::vector<std::string>& files) {
  std::vector<GlbValidation> out;
  if (files.empty()) return out;
  std::string cmd = quote(SURFTEX_NODE) + " " + quote(std::string(SURFTEX_SOURCE_DIR) + "/tests/tools/validate_glb.js") +
                    " " + quote(SURFTEX_GLTF_VALIDATOR_DIR);
  for (const std::string& f : files) cmd += " " + quote(f);
  cmd += " 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  if (!p) {
    ADD_FAILURE() << "cannot run the glTF-Validator: " << cmd;
    return out;
  }
  std::string text;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
  const int status = ::pclose(p);
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || !j.is_object() || !j.contains("file")) continue;
    GlbValidation v;
    v.file = j["file"].get<std::string>();
    v.errors = j["errors"].get<int>();
    v.warnings = j["warnings"].get<int>();
    v.infos = j["infos"].get<int>();
    v.hints = j["hints"].get<int>();
    for (const auto& m : j["messages"])
      v.messages += "  " + m["severity"].get<std::string>() + " " + m["code"].get<std::string>() + " " +
                    m["message"].get<std::string>() + " " + m["pointer"].get<std::string>() + "\n";
    out.push_back(v);
  }
  if (out.size() != files.size())
    ADD_FAILURE() << "the glTF-Validator did not report on every file (exit status " << status
                  << "; run scripts/setup.sh to install it into " << SURFTEX_GLTF_VALIDATOR_DIR << "):\n"
                  << text;
  return out;
}

std::string temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  fs::path p = fs::temp_directory_path() /
               ("surftex-test-" + tag + "-" + std::to_string(::getpid()) + "-" +
                std::to_string(counter.fetch_add(1)));
  fs::remove_all(p);
  fs::create_directories(p);
  std::lock_guard<std::mutex> lock(test_folders().mu);
  test_folders().dirs.push_back(p.string());
  return p.string();
}

RunResult run_surftex(const std::string& args) {
  std::string dir = temp_dir("run");
  std::string out = dir + "/stdout", err = dir + "/stderr";
  std::string cmd = std::string("'") + SURFTEX_BINARY + "' " + args + " >'" + out + "' 2>'" + err + "' </dev/null";
  int status = std::system(cmd.c_str());
  RunResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  r.out = file_bytes(out);
  r.err = file_bytes(err);
  fs::remove_all(dir);
  return r;
}

}  // namespace surftex::test
