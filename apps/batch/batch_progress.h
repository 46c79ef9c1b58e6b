// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Progress of a batch (issue 20, item 5): on a terminal, a line per finished
// job and a status line below them (done / running / failed of total, elapsed,
// ETA) redrawn in place; in a pipe, one line per finished job; with
// --json-progress, newline-delimited JSON events on stdout.
#include <chrono>
#include <cstdio>
#include <string>

#include "batch/batch_job.h"

namespace surftex::batch {

enum class ProgressMode { Terminal, Lines, Json, Quiet };

/// ETA in seconds from the elapsed time and the jobs finished so far (the
/// rate already includes the parallelism); -1 when nothing finished yet.
double estimate_remaining_seconds(double elapsed, int finished, int total);
/// "1:05" or "1:02:03"; "--" for a negative value.
std::string format_clock(double seconds);

class BatchProgress {
 public:
  /// `text` receives the terminal and line output (stderr), `json` the events (stdout).
  BatchProgress(ProgressMode mode, std::FILE* text, std::FILE* json);
  /// The number of jobs this run will execute, of `all` in the manifest.
  void plan(int to_run, int all);
  void started(const std::string& job, const std::string& reason);
  /// A job ended; `st` is its status file (status, seconds, error).
  void finished(const std::string& job, const JobStatus& st);
  /// Redraws the terminal status line (elapsed time moves); no-op otherwise.
  void tick();
  /// The run ended: clears the status line; emits the JSON "end" event.
  void end(int ok, int failed, int other, const std::string& summary_path, const std::string& index_path);
  /// The one-line state: "3/12 done, 2 running, 1 failed, 0:41 elapsed, ETA 1:20".
  std::string status_line() const;

  int finished_count() const { return ok_ + failed_; }
  int failed_count() const { return failed_; }

 private:
  double elapsed() const;
  void clear_line();
  void emit(const std::string& json_line);

  ProgressMode mode_;
  std::FILE* text_;
  std::FILE* json_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  int total_ = 0, all_ = 0, running_ = 0, ok_ = 0, failed_ = 0;
  bool line_shown_ = false;
  std::string last_line_;
};

}  // namespace surftex::batch
