// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// What a batch produced (issue 20, item 3): OUT/summary.json, one entry per
// manifest job, built from each job's status file and its report. Reports are
// read tolerantly: the report schema is being unified (`seconds.total`,
// `outputs`) and older keys (`seconds` as a number, `seconds_total`, `files`)
// are read too.
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

#include "batch/batch_manifest.h"

namespace surftex::batch {

struct JobSummary {
  std::string name, command;
  /// "ok", "failed", "interrupted" (stopped by a signal), or "not_run" (no
  /// outcome for the job's current command: a dry run, or the engine stopped).
  std::string status;
  std::string error;              ///< the job's "error: ..." line when it failed
  int exit_code = 0;
  double seconds = -1;            ///< wall-clock time of the job, -1 unknown
  double cpu_seconds = -1;        ///< its user + system CPU time, -1 unknown
  double report_seconds = -1;     ///< the total time its report states, -1 none
  std::vector<std::pair<std::string, double>> figures;  ///< key quality figures of its report
  std::vector<std::string> outputs;  ///< files of OUT/NAME, relative to OUT
  std::vector<std::string> images;   ///< the PNG/JPEG among them, renders first
  std::string log;                ///< its log, relative to OUT
  std::string finished_at;
};

/// The total seconds a report states: seconds.total, a number "seconds",
/// seconds_total; -1 if none.
double report_total_seconds(const nlohmann::json& report);
/// The key quality figures of a subcommand's report (label, value), in a fixed
/// order; figures the report lacks are left out.
std::vector<std::pair<std::string, double>> report_figures(const std::string& subcommand,
                                                           const nlohmann::json& report);
/// Image files first those named render*, then the others, by name.
std::vector<std::string> order_images(std::vector<std::string> images);

/// Summarises one job from OUT (absolute or relative).
JobSummary summarize_job(const BatchJob& job, const std::string& out_dir);

/// summary.json: {"manifest", "jobs": [...], "counts": {...}, "seconds_sum", ...}.
nlohmann::json summary_json(const BatchManifest& m, const std::vector<JobSummary>& jobs);

}  // namespace surftex::batch
