// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The JSON report of every subcommand (`--report FILE`, and the report.json a
// command writes into its output folder): one schema (README "Reports"). The
// keys every report has:
//   surftex_version  git describe at build time (cmake/GitVersion.cmake)
//   command          the subcommand ("convert", "patches", ...)
//   command_line     argv as given, one string per argument
//   seed, threads    the common options
//   inputs           [{"path", "bytes", "sha256"}] for every input file (the
//                    files of an input folder are listed one by one)
//   seconds          {"total": wall time since start, "<stage>": ...}, numbers only
//   outputs          [paths of every file the run wrote], the report itself excluded
// A subcommand adds its own fields beside these (counts, quality figures,
// each from a to_json next to its Result struct where one exists).

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace surftex::cli {

struct CommonOptions;

/// What a run read and wrote, for its report.
struct RunFiles {
  std::vector<std::string> inputs;   ///< files or folders the run read; empty strings are skipped
  std::vector<std::string> outputs;  ///< files the run wrote (paths as written)
};

/// The regular files under `dir` (recursively), sorted: the outputs of a
/// command that writes a folder.
std::vector<std::string> files_in_folder(const std::string& dir);

/// Records argv and the start time of the run (main.cpp calls it first).
void record_command_line(int argc, const char* const* argv);

/// The version string of this build, e.g. "0.1.0-g2f59b4f" (see the file comment).
const char* surftex_version();

/// `fields` plus the shared keys above. `fields` may carry "seconds" (an
/// object of per-stage numbers; "total" is set here) and must not carry the
/// other shared keys: a subcommand that does is a programming error
/// (std::logic_error). Throws IOError if an input cannot be hashed.
nlohmann::json make_report(const CommonOptions& opt, const std::string& command, nlohmann::json fields,
                           const RunFiles& files);

/// make_report, written atomically to opt.report_path if set.
void write_report(const CommonOptions& opt, const std::string& command, nlohmann::json fields,
                  const RunFiles& files);

}  // namespace surftex::cli
