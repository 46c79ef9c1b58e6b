// SPDX-License-Identifier: AGPL-3.0-or-later
#include "surftex/report.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include "geometry/errors.h"
#include "geometry/output_file.h"
#include "geometry/sha256.h"
#include "surftex/command.h"
#include "surftex_version.h"

namespace fs = std::filesystem;

namespace surftex::cli {

namespace {

struct RunRecord {
  std::vector<std::string> argv;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
};

RunRecord& run_record() {
  static RunRecord r;
  return r;
}

nlohmann::json input_entry(const fs::path& p) {
  std::error_code ec;
  const auto bytes = fs::file_size(p, ec);
  if (ec) throw IOError("cannot read the size of input '" + p.string() + "' for the report");
  return {{"path", p.string()}, {"bytes", bytes}, {"sha256", sha256_file_hex(p.string())}};
}

nlohmann::json hash_inputs(const std::vector<std::string>& inputs) {
  nlohmann::json out = nlohmann::json::array();
  std::vector<std::string> seen;
  auto add = [&](const fs::path& p) {
    if (std::find(seen.begin(), seen.end(), p.string()) != seen.end()) return;
    seen.push_back(p.string());
    out.push_back(input_entry(p));
  };
  for (const std::string& in : inputs) {
    if (in.empty()) continue;
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      for (const std::string& f : files_in_folder(in)) add(f);
    } else {
      add(in);
    }
  }
  return out;
}

}  // namespace

std::vector<std::string> files_in_folder(const std::string& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  // A folder this run wrote is still in its staging folder (output_file.h):
  // listed there, named by where it will be.
  const fs::path where = staged_path(dir);
  for (const auto& e : fs::recursive_directory_iterator(where, ec))
    if (e.is_regular_file(ec)) files.push_back((fs::path(dir) / fs::relative(e.path(), where, ec)).string());
  std::sort(files.begin(), files.end());
  return files;
}

void record_command_line(int argc, const char* const* argv) {
  RunRecord& r = run_record();
  r.argv.assign(argv, argv + argc);
  r.start = std::chrono::steady_clock::now();
}

const char* surftex_version() { return SURFTEX_VERSION; }

nlohmann::json make_report(const CommonOptions& opt, const std::string& command, nlohmann::json fields,
                           const RunFiles& files) {
  if (!fields.is_object()) throw std::logic_error("report of '" + command + "' is not a JSON object");
  for (const char* key : {"surftex_version", "command", "command_line", "seed", "threads", "inputs", "outputs"})
    if (fields.contains(key))
      throw std::logic_error("report of '" + command + "' sets the shared key '" + key + "' itself");
  nlohmann::json seconds = fields.contains("seconds") ? fields["seconds"] : nlohmann::json::object();
  if (!seconds.is_object()) throw std::logic_error("report of '" + command + "': \"seconds\" is not an object");
  for (const auto& [stage, value] : seconds.items())
    if (!value.is_number())
      throw std::logic_error("report of '" + command + "': seconds." + stage + " is not a number");
  seconds["total"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - run_record().start).count();
  nlohmann::json r = std::move(fields);
  r["surftex_version"] = surftex_version();
  r["command"] = command;
  r["command_line"] = run_record().argv;
  r["seed"] = opt.seed;
  r["threads"] = opt.threads;
  r["inputs"] = hash_inputs(files.inputs);
  r["seconds"] = std::move(seconds);
  r["outputs"] = files.outputs;
  return r;
}

void write_report(const CommonOptions& opt, const std::string& command, nlohmann::json fields,
                  const RunFiles& files) {
  if (opt.report_path.empty()) return;
  const nlohmann::json r = make_report(opt, command, std::move(fields), files);
  write_file_atomic(opt.report_path, r.dump(2) + "\n", true);
}

}  // namespace surftex::cli
