// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Runs Snakemake on a batch's Snakefile (issue 20, items 1 and 5). Snakemake's
// own output goes to OUT/.surftex/snakemake.log; its job events reach surftex
// through --log-handler-script (a small Python file the batch writes), which
// writes one JSON line per event to a pipe: the plan (jobs per rule), each
// job's start (with Snakemake's reason), finish or error. SIGTERM, SIGINT or
// SIGHUP to the batch stop Snakemake and its running jobs (their process
// group); a second signal kills them.
#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace surftex::batch {

/// The Python log handler Snakemake loads (--log-handler-script).
std::string snakemake_event_handler_script();

/// The path of `snakemake` (the SURFTEX_SNAKEMAKE variable, else PATH), or ""
/// when it is not installed.
std::string find_snakemake();

/// Counts of the rule-table lines of Snakemake's "Job stats" text
/// ("job_cow 1 1 1"): rule -> jobs.
std::vector<std::pair<std::string, int>> parse_job_stats(const std::string& text);

struct EngineResult {
  int exit_code = 0;  ///< Snakemake's exit code (128 + signal if killed)
  int signal = 0;     ///< the signal that stopped the batch, 0 if none
};

/// Runs argv (argv[0] the snakemake binary) with its output in `log_path`,
/// calling `on_event` for each JSON event and `on_tick` about twice a second.
EngineResult run_snakemake(const std::vector<std::string>& argv, const std::string& log_path,
                           const std::function<void(const nlohmann::json&)>& on_event,
                           const std::function<void()>& on_tick);

/// The lines of Snakemake's log worth showing when it failed by itself (not a
/// job): its error block, or the last lines.
std::string snakemake_error_excerpt(const std::string& log_text);

}  // namespace surftex::batch
