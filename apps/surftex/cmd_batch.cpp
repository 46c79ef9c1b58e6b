// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex batch MANIFEST -o OUT`: many jobs on Snakemake (issue 20). Writes
// OUT/Snakefile (one rule per manifest job), runs snakemake on it (local cores,
// or a cluster through --engine-args), and writes OUT/summary.json and the
// contact sheet OUT/index.html. Each rule runs `surftex-job` (beside the
// surftex binary): one job, staged, moved into OUT/NAME only when it succeeded.
#include <CLI/CLI.hpp>
#include <sys/file.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "batch/batch_job.h"
#include "batch/batch_manifest.h"
#include "batch/batch_progress.h"
#include "batch/batch_snakefile.h"
#include "batch/batch_summary.h"
#include "batch/contact_sheet.h"
#include "batch/snakemake_engine.h"
#include "geometry/errors.h"
#include "geometry/output_file.h"
#include "surftex/command.h"

namespace fs = std::filesystem;

namespace surftex::cli {
namespace {
namespace batch_command {  // named: the unity build joins these files

using namespace surftex::batch;

struct BatchArgs {
  std::string manifest, out, engine_args;
  int jobs = 0;
  bool dry_run = false, json_progress = false, force = false, quiet = false, retry_failed = false;
};

std::string self_exe() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw IOError("cannot find the surftex binary (/proc/self/exe): " + ec.message());
  return p.string();
}

// surftex-job, installed beside surftex.
std::string job_runner(const std::string& surftex) {
  const fs::path p = fs::path(surftex).parent_path() / "surftex-job";
  if (::access(p.c_str(), X_OK) != 0)
    throw IOError("'" + p.string() + "' is missing: `surftex batch` needs surftex-job beside surftex (build it)");
  return p.string();
}

// OUT/summary.json: the jobs' summary with the keys every report has
// (surftex/report.h): version, command line, the manifest's hash, seconds.total,
// and as outputs the contact sheet and every job's outputs (paths under OUT);
// "seed" is the default (each job has its own), "threads" the jobs at once.
void write_summary(const fs::path& out, const BatchManifest& m, const std::vector<JobSummary>& jobs, int parallel) {
  nlohmann::json fields = summary_json(m, jobs);
  RunFiles files{{m.path}, {(out / "index.html").string()}};
  for (const JobSummary& s : jobs)
    for (const std::string& f : s.outputs) files.outputs.push_back((out / f).string());
  CommonOptions opt;
  opt.threads = parallel;
  const nlohmann::json r = make_report(opt, "batch", std::move(fields), files);
  write_file_atomic((out / "summary.json").string(), r.dump(2) + "\n", true);
}

std::string read_text(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// OUT belongs to the batch once OUT/.surftex exists; a non-empty folder
// without it is the user's and is refused unless --force.
void prepare_out(const fs::path& out, bool force) {
  std::error_code ec;
  if (fs::exists(out, ec)) {
    if (!fs::is_directory(out, ec)) throw IOError("batch output '" + out.string() + "' exists and is not a folder");
    if (!fs::is_empty(out, ec) && !fs::is_directory(out / ".surftex", ec) && !force)
      throw IOError("batch folder '" + out.string() +
                    "' is not empty and was not made by `surftex batch` (pass --force or choose another -o)");
  }
  ensure_directory((out / ".surftex").string());
}

// An exclusive lock on OUT for this process's life (released by the kernel
// even when the batch is killed, unlike Snakemake's lock files, so the batch
// runs Snakemake with --nolock).
int lock_out(const fs::path& out) {
  const std::string p = (out / ".surftex" / "lock").string();
  const int fd = ::open(p.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw IOError("cannot create the lock file '" + p + "'");
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0)
    throw IOError("another `surftex batch` is running on '" + out.string() + "' (lock " + p + ")");
  return fd;
}

void write_if_changed(const fs::path& p, const std::string& text) {
  std::error_code ec;
  if (fs::exists(p, ec) && read_text(p) == text) return;
  write_file_atomic(p.string(), text, true);
}

std::vector<std::string> engine_words(const std::string& engine_args) {
  std::vector<std::string> w = split_shell_words(engine_args);
  for (const std::string& a : w)
    for (const char* own : {"-s", "--snakefile", "-d", "--directory", "--log-handler-script"})
      if (a == own || a.rfind(std::string(own) + "=", 0) == 0)
        throw InvalidInputError("--engine-args: " + std::string(own) +
                                " is set by the batch (the Snakefile and working folder are OUT)");
  return w;
}

ProgressMode progress_mode(const BatchArgs& a) {
  if (a.json_progress) return ProgressMode::Json;
  if (a.quiet) return ProgressMode::Quiet;
  return ::isatty(STDERR_FILENO) ? ProgressMode::Terminal : ProgressMode::Lines;
}

// Follows Snakemake's events: rule names map back to job names.
struct EventFollower {
  const BatchManifest& m;
  const fs::path out;
  BatchProgress& progress;
  bool dry_run;
  std::map<std::string, std::string> job_of_rule;
  std::map<long, std::string> job_of_id;
  std::vector<std::pair<std::string, std::string>> would_run;  // dry run: job, reason
  bool planned = false;
  int failed_events = 0;

  void operator()(const nlohmann::json& e) {
    const std::string ev = e.value("event", "");
    if (ev == "plan" && !planned) {
      int n = 0;
      for (const auto& [rule, count] : parse_job_stats(e.value("text", "")))
        if (job_of_rule.count(rule)) n += count;
      planned = true;
      if (!dry_run) progress.plan(n, static_cast<int>(m.jobs.size()));
    } else if (ev == "start") {
      auto it = job_of_rule.find(e.value("rule", ""));
      if (it == job_of_rule.end()) return;
      job_of_id[e.value("jobid", -1L)] = it->second;
      if (dry_run) would_run.emplace_back(it->second, e.value("reason", ""));
      else progress.started(it->second, e.value("reason", ""));
    } else if (ev == "finish" || ev == "error") {
      auto it = job_of_id.find(e.value("jobid", -1L));
      if (it == job_of_id.end() || dry_run) return;
      JobStatus st;
      if (!read_job_status((out / job_status_path(it->second)).string(), st)) {
        st.status = ev == "finish" ? "ok" : "failed";
        if (ev == "error") st.error = "error: the job failed before it could record why (see " + job_log_path(it->second) + ")";
      }
      if (ev == "error" && st.status == "ok") st.status = "failed";  // e.g. Snakemake missed the output
      if (st.status != "ok") ++failed_events;
      progress.finished(it->second, st);
      job_of_id.erase(it);
    }
  }
};

int print_dry_run(const BatchManifest& m, const EventFollower& f, bool fresh, std::size_t not_retried) {
  if (fresh) {
    for (const BatchJob& j : m.jobs) std::printf("would run %s: no output yet\n", j.name.c_str());
  } else {
    for (const auto& [job, reason] : f.would_run) {
      std::string r = reason;
      std::replace(r.begin(), r.end(), '\n', ' ');
      std::printf("would run %s: %s\n", job.c_str(), r.c_str());
    }
  }
  const std::size_t n = fresh ? m.jobs.size() : f.would_run.size();
  std::printf("dry run: %zu of %zu jobs would run, %zu up to date", n, m.jobs.size(), m.jobs.size() - n - not_retried);
  if (not_retried > 0) std::printf(", %zu failed and not retried", not_retried);
  std::printf(" (no job run, summary.json and index.html unchanged)\n");
  return 0;
}

// Jobs that failed with exit code 2 (bad input: surftex refuses it the same
// way every time) and whose command and input files are unchanged since: not
// run again unless --retry-failed.
std::vector<std::string> jobs_not_retried(const BatchManifest& m, const fs::path& out, bool retry_failed) {
  std::vector<std::string> names;
  if (retry_failed) return names;
  for (const BatchJob& j : m.jobs) {
    JobStatus st;
    if (read_job_status((out / job_status_path(j.name)).string(), st) && st.status == "failed" && st.exit_code == 2 &&
        !st.fingerprint.empty() && st.fingerprint == job_fingerprint(j, m.dir, out.string()))
      names.push_back(j.name);
  }
  return names;
}

std::vector<std::string> snakemake_argv(const std::string& snakemake, const fs::path& snakefile, const fs::path& out,
                                        const BatchArgs& a, const std::vector<std::string>& engine,
                                        const std::vector<std::string>& targets) {
  const int jobs = a.jobs > 0 ? a.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<std::string> argv{snakemake,
                                "--snakefile", snakefile.string(),
                                "--directory", out.string()};
  // Targets right after a one-value option: engine options that take a list
  // (--default-resources a=1 b=2) would swallow them at the end.
  argv.insert(argv.end(), targets.begin(), targets.end());
  argv.insert(argv.end(), {
                              "--jobs", std::to_string(jobs),
                              "--keep-going", "--rerun-incomplete", "--nolock",
                              "--scheduler", "greedy",
                              "--log-handler-script", (out / ".surftex" / "snakemake_events.py").string()});
  if (a.dry_run) argv.push_back("--dry-run");
  argv.insert(argv.end(), engine.begin(), engine.end());
  return argv;
}

int run_batch(const BatchArgs& a) {
  // A closed stdout (--json-progress | head) must not kill the batch before
  // it has stopped Snakemake and written the summary.
  std::signal(SIGPIPE, SIG_IGN);
  const BatchManifest m = read_batch_manifest(a.manifest);
  const std::vector<std::string> engine = engine_words(a.engine_args);
  const std::string snakemake = find_snakemake();
  if (snakemake.empty())
    throw IOError("snakemake is not installed (Debian package `snakemake`; scripts/setup.sh installs it)");
  const fs::path out = fs::absolute(a.out).lexically_normal();
  std::error_code ec;
  const fs::path manifest_abs = fs::absolute(a.manifest).lexically_normal();
  if (std::mismatch(out.begin(), out.end(), manifest_abs.begin(), manifest_abs.end()).first == out.end())
    throw InvalidInputError("the manifest '" + a.manifest + "' is inside the output folder '" + a.out + "'");
  const std::string exe = self_exe();
  const std::string text = snakefile_text(m, exe, job_runner(exe), out.string());
  const bool fresh = !fs::is_directory(out / ".surftex", ec);
  BatchProgress progress(progress_mode(a), stderr, stdout);
  EventFollower follow{m, out, progress, a.dry_run, {}, {}, {}, false, 0};
  const std::vector<std::string> rules = job_rule_names(m);
  for (std::size_t i = 0; i < m.jobs.size(); ++i) follow.job_of_rule[rules[i]] = m.jobs[i].name;

  if (a.dry_run && fresh) return print_dry_run(m, follow, true, 0);  // nothing to compare with: all would run
  if (!a.dry_run) prepare_out(out, a.force);
  const int lock = lock_out(out);
  const fs::path snakefile = a.dry_run ? out / ".surftex" / "Snakefile.dry-run" : out / "Snakefile";
  write_if_changed(snakefile, text);
  write_if_changed(out / ".surftex" / "snakemake_events.py", snakemake_event_handler_script());
  const std::string log = (out / ".surftex" / (a.dry_run ? "snakemake.dry-run.log" : "snakemake.log")).string();
  const std::vector<std::string> skipped = jobs_not_retried(m, out, a.retry_failed);
  std::vector<std::string> targets;  // empty: the Snakefile's default, every job
  for (const BatchJob& j : m.jobs)
    if (!skipped.empty() && std::find(skipped.begin(), skipped.end(), j.name) == skipped.end()) targets.push_back(j.name);
  if (!skipped.empty() && !a.json_progress && !a.quiet)
    std::fprintf(stderr, "batch: %zu failed job%s not retried (exit code 2 on the same command and inputs; "
                 "--retry-failed runs them): %s%s\n", skipped.size(), skipped.size() == 1 ? "" : "s",
                 skipped.front().c_str(), skipped.size() > 1 ? ", ..." : "");
  if (!skipped.empty() && a.json_progress) {
    std::printf("%s\n", nlohmann::json{{"event", "not_retried"}, {"jobs", skipped}}.dump().c_str());
    std::fflush(stdout);
  }
  EngineResult r;
  if (skipped.size() < m.jobs.size())
    r = run_snakemake(snakemake_argv(snakemake, snakefile, out, a, engine, targets), log, std::ref(follow),
                      [&] { progress.tick(); });
  if (a.dry_run) {
    fs::remove(snakefile, ec);
    ::close(lock);
    if (r.exit_code != 0)
      throw IOError("snakemake failed on the dry run (exit code " + std::to_string(r.exit_code) + "):\n" +
                    snakemake_error_excerpt(read_text(log)));
    return print_dry_run(m, follow, false, skipped.size());
  }
  std::vector<JobSummary> summaries;
  for (const BatchJob& j : m.jobs) summaries.push_back(summarize_job(j, out.string()));
  write_contact_sheet((out / "index.html").string(), batch_contact_sheet("surftex batch: " + m.path, summaries));
  write_summary(out, m, summaries, a.jobs);  // after index.html: it lists it
  ::close(lock);
  int ok = 0, failed = 0, other = 0;
  for (const JobSummary& s : summaries) (s.status == "ok" ? ok : s.status == "failed" ? failed : other)++;
  progress.end(ok, failed, other, (out / "summary.json").string(), (out / "index.html").string());
  if (!a.quiet && !a.json_progress)
    std::fprintf(stderr, "batch: %d ok, %d failed%s of %zu jobs; %s\n", ok, failed,
                 other ? (", " + std::to_string(other) + " not finished").c_str() : "", m.jobs.size(),
                 (fs::path(a.out) / "index.html").string().c_str());
  if (r.signal != 0) {
    std::fprintf(stderr, "error: batch stopped by signal %d; run it again to finish the remaining jobs\n", r.signal);
    return 128 + r.signal;
  }
  if (r.exit_code != 0 && failed == 0 && follow.failed_events == 0) {
    std::fprintf(stderr, "error: snakemake failed (exit code %d, log %s):\n%s", r.exit_code, log.c_str(),
                 snakemake_error_excerpt(read_text(log)).c_str());
    return 2;
  }
  return failed + other > 0 ? 1 : 0;
}

SubcommandRegistrar reg_batch{
    {"batch",
     "Run many jobs (one a line of a manifest) on Snakemake, locally or on a cluster; summary and contact sheet",
     [](CLI::App& app) -> std::function<int()> {
       auto a = std::make_shared<BatchArgs>();
       app.add_option("MANIFEST", a->manifest,
                      "Job list: one job a line, 'NAME: SUBCOMMAND ARGS...' without -o (the batch gives job NAME "
                      "the folder OUT/NAME/ and OUT/NAME/report.json); blank lines and # comments allowed; quotes "
                      "as in a shell; paths relative to the manifest's folder")
           ->required();
       app.add_option("-o,--output", a->out,
                      "Batch folder: Snakefile, one folder per job, summary.json, index.html (created if absent; "
                      "a later run re-runs only jobs whose output is missing or whose inputs or arguments changed)")
           ->required();
       app.add_option("-j,--jobs", a->jobs,
                      "Jobs at once: local cores, or cluster jobs with --engine-args --slurm/--cluster "
                      "(1..100000; default: the number of cores)")
           ->check(CLI::Range(1, 100000));
       app.add_option("--engine-args", a->engine_args,
                      "More snakemake options, as one string: e.g. \"--slurm --default-resources "
                      "slurm_account=A slurm_partition=P\", \"--profile DIR\", \"--cluster 'qsub'\"");
       app.add_flag("-n,--dry-run", a->dry_run, "Print which jobs would run and why (Snakemake's reason); run no job, leave summary and page as they are");
       app.add_flag("--json-progress", a->json_progress,
                    "Progress as newline-delimited JSON events on stdout (not_retried, plan, start, finish, end)");
       app.add_flag("--retry-failed", a->retry_failed,
                    "Run again jobs that failed with exit code 2 (bad input) although their command and input files "
                    "did not change (default: they are not retried; other failures always are)");
       app.add_flag("--force", a->force, "Use an output folder that exists and was not made by `surftex batch`");
       app.add_flag("-q,--quiet", a->quiet, "No progress lines");
       return [a] { return run_batch(*a); };
     }}};

}  // namespace batch_command
}  // namespace
}  // namespace surftex::cli
