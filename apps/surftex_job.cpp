// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex-job`: what each rule of a batch's Snakefile runs (issue 20, item 2):
// one job, staged in OUT/.surftex/stage/NAME and moved to OUT/NAME only when it
// succeeded (apps/batch/batch_job.h). A separate small executable rather than a
// `surftex` subcommand: it starts in milliseconds, where `surftex` itself
// spends about 0.3 s of CPU loading its 270 shared libraries (measured: decision 701).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <filesystem>

#include "batch/batch_job.h"
#include "geometry/errors.h"

int main(int argc, char** argv) {
  CLI::App app{"surftex-job: runs one job of a `surftex batch` (called by the batch's Snakefile, from OUT)"};
  surftex::batch::JobRunOptions o;
  app.add_option("--surftex", o.surftex_exe, "The surftex binary that runs the job")->required();
  app.add_option("--name", o.name, "Job name (its folder in OUT)")->required();
  app.add_option("--workdir", o.workdir, "The job's working folder (the manifest's)")->required();
  app.add_option("--output-file", o.output_file, "-o file name inside the job folder (default: -o is the folder)");
  app.add_option("--threads", o.threads, "--threads for the job (0..1024)")->check(CLI::Range(0, 1024));
  app.add_option("command", o.command, "-- SUBCOMMAND ARGS...")->required();
  app.positionals_at_end();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    o.out_dir = std::filesystem::current_path().string();
    return surftex::batch::run_batch_job(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}
