// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The Snakefile of a batch (issue 20, item 1): one rule per manifest job, its
// output the folder OUT/NAME (written whole by `surftex-job`, which
// stages it and renames it into place), its log OUT/.surftex/logs/NAME.log and
// status OUT/.surftex/status/NAME.json. The Snakefile runs from OUT (snakemake
// -d OUT) and holds absolute paths of the surftex binary, the manifest folder
// and the inputs, so Snakemake runs it unchanged locally, through --cluster or
// --slurm on a shared file system, or from a profile.
#include <string>
#include <vector>

#include "batch/batch_manifest.h"

namespace surftex::batch {

/// Paths inside OUT, relative to it.
std::string job_log_path(const std::string& name);     ///< .surftex/logs/NAME.log
std::string job_status_path(const std::string& name);  ///< .surftex/status/NAME.json
std::string job_stage_path(const std::string& name);   ///< .surftex/stage/NAME

/// One Snakemake rule name per job, in manifest order: "job_" + the name with
/// '-' and '.' as '_', made unique with a suffix when two names map alike.
std::vector<std::string> job_rule_names(const BatchManifest& m);

/// The existing files a job reads, as absolute paths: each argument (or the
/// value of --opt=VALUE) that names an existing file relative to the manifest
/// folder, and the files directly inside an argument that names a folder
/// (a material tile). Paths inside `out_dir` are not inputs. A missing input
/// is not declared: the job then fails with its own error, alone.
std::vector<std::string> job_input_files(const BatchJob& job, const std::string& manifest_dir,
                                         const std::string& out_dir);

/// A hex digest of the job's command and of the path, size and modification
/// time of each of its input files (job_input_files): equal digests mean the
/// job would run the same command on the same files. A job that failed with
/// exit code 2 (bad input, surftex's deterministic refusal) is not retried
/// while its digest is unchanged.
std::string job_fingerprint(const BatchJob& job, const std::string& manifest_dir, const std::string& out_dir);

/// The threads a job's rule declares: its --threads value if given (0 = all
/// cores: "workflow.cores"), else 1 (batch jobs run side by side).
std::string job_threads_expression(const BatchJob& job);

/// The Snakefile text; each rule runs `job_exe` (surftex-job) on `surftex_exe`.
/// All paths absolute.
std::string snakefile_text(const BatchManifest& m, const std::string& surftex_exe, const std::string& job_exe,
                           const std::string& out_dir);

/// `s` as a Python string literal (double quotes, UTF-8 kept).
std::string python_string(const std::string& s);

}  // namespace surftex::batch
