// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// One batch job as Snakemake runs it (`surftex-job`, issue 20 item 2):
// runs `surftex SUBCOMMAND ARGS -o STAGE --report STAGE/report.json` in its
// own process with the manifest folder as working folder, output and errors
// into the job's log; moves the staged folder to OUT/NAME only when the job
// succeeded, so that a failed or killed job leaves no partial folder; records
// the outcome (exit code, `error:` line, seconds) in the job's status file.
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace surftex::batch {

struct JobRunOptions {
  std::string name;                  ///< the job name (its folder in OUT)
  std::string out_dir;               ///< OUT, absolute (Snakemake's working folder)
  std::string workdir;               ///< the child's working folder (the manifest's folder)
  std::string output_file;           ///< the -o file name inside the folder; "" = -o is the folder
  int threads = -1;                  ///< passed as --threads when >= 0
  std::vector<std::string> command;  ///< SUBCOMMAND ARGS...
  std::string surftex_exe;           ///< the binary that runs the job
};

/// The outcome of a job, as in OUT/.surftex/status/NAME.json.
struct JobStatus {
  std::string name;
  std::string command;        ///< as a user would type it
  std::string status;         ///< "ok", "failed" or "interrupted"
  int exit_code = 0;          ///< the child's exit code; 128 + signal when killed by one
  std::string error;          ///< its last "error: ..." line, or what went wrong
  double seconds = 0;         ///< wall-clock time of the child
  double cpu_seconds = 0;     ///< its user + system CPU time
  double max_rss_mb = 0;      ///< its peak resident memory
  std::string started_at, finished_at;  ///< UTC, ISO 8601
  std::string host;
  std::string fingerprint;    ///< job_fingerprint() when the job started
};

nlohmann::json to_json(const JobStatus& s);
/// Reads a status file; false if absent or unreadable.
bool read_job_status(const std::string& path, JobStatus& s);

/// Runs the job and writes its status file; returns the exit code for
/// `surftex-job` (0 only when the job succeeded and its folder is in
/// place). SIGTERM, SIGINT or SIGHUP stop the child, remove the stage and
/// record "interrupted".
int run_batch_job(const JobRunOptions& o);

/// The last line of `log_text` that starts with "error:", or "".
std::string last_error_line(const std::string& log_text);

}  // namespace surftex::batch
