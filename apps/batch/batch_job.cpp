// SPDX-License-Identifier: AGPL-3.0-or-later
#include "batch/batch_job.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "batch/batch_manifest.h"
#include "batch/batch_snakefile.h"
#include "geometry/errors.h"
#include "geometry/output_file.h"

namespace fs = std::filesystem;

namespace surftex::batch {

nlohmann::json to_json(const JobStatus& s) {
  return {{"name", s.name},       {"command", s.command},         {"status", s.status},
          {"exit_code", s.exit_code}, {"error", s.error},         {"seconds", s.seconds},
          {"cpu_seconds", s.cpu_seconds}, {"max_rss_mb", s.max_rss_mb}, {"started_at", s.started_at},
          {"finished_at", s.finished_at}, {"host", s.host},           {"fingerprint", s.fingerprint}};
}

bool read_job_status(const std::string& path, JobStatus& s) {
  std::ifstream f(path);
  if (!f) return false;
  nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  s.name = j.value("name", "");
  s.command = j.value("command", "");
  s.status = j.value("status", "");
  s.exit_code = j.value("exit_code", 0);
  s.error = j.value("error", "");
  s.seconds = j.value("seconds", 0.0);
  s.cpu_seconds = j.value("cpu_seconds", 0.0);
  s.max_rss_mb = j.value("max_rss_mb", 0.0);
  s.started_at = j.value("started_at", "");
  s.finished_at = j.value("finished_at", "");
  s.host = j.value("host", "");
  s.fingerprint = j.value("fingerprint", "");
  return !s.status.empty();
}

std::string last_error_line(const std::string& log_text) {
  std::string last;
  std::istringstream in(log_text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("error:", 0) == 0) last = line;
  }
  if (last.size() > 1000) last = last.substr(0, 1000) + "...";
  return last;
}

namespace {

volatile std::sig_atomic_t g_signal = 0;
volatile pid_t g_child = 0;

void on_signal(int sig) {
  if (g_signal == 0) g_signal = sig;
  if (g_child > 0) ::kill(g_child, SIGTERM);
}

std::string signal_name(int sig) {
  const char* a = sigabbrev_np(sig);
  return a ? std::string("SIG") + a : "signal " + std::to_string(sig);
}

std::string utc_now() {
  std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Subcommands that write OUTDIR/report.json themselves: --report naming it
// too would be two outputs of one run naming one file (refused).
bool writes_own_report(const std::string& subcommand) {
  return subcommand == "patches" || subcommand == "subdiv" || subcommand == "material-map" || subcommand == "demo";
}

// The child's argv: SUBCOMMAND -o OUTPUT [--report STAGE/report.json]
// [--threads N] ARGS... (options first: a "--" among ARGS stays last).
std::vector<std::string> child_argv(const JobRunOptions& o, const fs::path& stage) {
  std::vector<std::string> argv{o.surftex_exe, o.command.at(0), "-o",
                                (o.output_file.empty() ? stage : stage / o.output_file).string()};
  if (!(o.output_file.empty() && writes_own_report(o.command.at(0))))
    argv.insert(argv.end(), {"--report", (stage / "report.json").string()});
  if (o.threads >= 0) argv.insert(argv.end(), {"--threads", std::to_string(o.threads)});
  argv.insert(argv.end(), o.command.begin() + 1, o.command.end());
  return argv;
}

struct ChildResult {
  int exit_code = 0;
  int signal = 0;
  std::string spawn_error;
  rusage usage{};
};

ChildResult run_child(const std::vector<std::string>& args, const std::string& workdir, const std::string& log) {
  ChildResult r;
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    r.spawn_error = "cannot write the job log '" + log + "': " + std::strerror(errno);
    return r;
  }
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) ::dup2(devnull, 0);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    if (::chdir(workdir.c_str()) != 0) {
      std::fprintf(stderr, "error: cannot enter the manifest folder '%s': %s\n", workdir.c_str(), std::strerror(errno));
      ::_exit(2);
    }
    ::execv(argv[0], argv.data());
    std::fprintf(stderr, "error: cannot run '%s': %s\n", argv[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(fd);
  if (pid < 0) {
    r.spawn_error = std::string("cannot start the job: ") + std::strerror(errno);
    return r;
  }
  g_child = pid;
  if (g_signal != 0) ::kill(pid, SIGTERM);  // a signal before g_child was set
  int status = 0;
  while (::wait4(pid, &status, 0, &r.usage) < 0 && errno == EINTR) {
  }
  g_child = 0;
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status), r.exit_code = 128 + r.signal;
  return r;
}

// Moves the finished stage to OUT/NAME; an older folder of that name (a run
// outside Snakemake, which removes outputs before a job) is moved aside first.
void move_into_place(const fs::path& stage, const fs::path& dest, const fs::path& out) {
  std::error_code ec;
  if (fs::exists(dest, ec)) {
    const fs::path trash = out / ".surftex" / "trash" / (dest.filename().string() + "." + std::to_string(::getpid()));
    fs::create_directories(trash.parent_path(), ec);
    fs::rename(dest, trash, ec);
    if (ec) throw IOError("cannot move the old '" + dest.string() + "' aside: " + ec.message());
    fs::remove_all(trash, ec);
  }
  fs::rename(stage, dest, ec);
  if (ec) throw IOError("cannot move the job's folder into place at '" + dest.string() + "': " + ec.message());
}

void install_handlers() {
  struct sigaction sa{};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: wait4 returns EINTR
  for (int s : {SIGTERM, SIGINT, SIGHUP}) ::sigaction(s, &sa, nullptr);
}

}  // namespace

int run_batch_job(const JobRunOptions& o) {
  if (o.command.empty()) throw InvalidInputError("surftex-job: no subcommand given");
  install_handlers();
  const fs::path out(o.out_dir);
  const fs::path stage = out / job_stage_path(o.name);
  const std::string log = (out / job_log_path(o.name)).string();
  const std::string status_path = (out / job_status_path(o.name)).string();
  std::error_code ec;
  fs::remove_all(stage, ec);  // left by a killed run
  fs::create_directories(stage, ec);
  if (ec) throw IOError("cannot create the job's stage folder '" + stage.string() + "': " + ec.message());
  ensure_directory(fs::path(log).parent_path().string());
  ensure_directory(fs::path(status_path).parent_path().string());

  JobStatus s;
  s.name = o.name;
  s.command = "surftex";
  for (const std::string& a : o.command) s.command += " " + shell_quote(a);
  char host[256] = {0};
  if (::gethostname(host, sizeof host - 1) == 0) s.host = host;
  BatchJob job;
  job.subcommand = o.command[0];
  job.args.assign(o.command.begin() + 1, o.command.end());
  s.fingerprint = job_fingerprint(job, o.workdir, o.out_dir);  // before the job: a change while it runs counts
  s.started_at = utc_now();
  const auto t0 = std::chrono::steady_clock::now();
  const ChildResult r = run_child(child_argv(o, stage), o.workdir, log);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.finished_at = utc_now();
  s.exit_code = r.exit_code;
  s.cpu_seconds = r.usage.ru_utime.tv_sec + r.usage.ru_utime.tv_usec * 1e-6 + r.usage.ru_stime.tv_sec +
                  r.usage.ru_stime.tv_usec * 1e-6;
  s.max_rss_mb = r.usage.ru_maxrss / 1024.0;  // Linux: kilobytes
  const bool produced = fs::is_directory(stage, ec) && !fs::is_empty(stage, ec);
  if (g_signal != 0) {
    s.status = "interrupted";
    s.error = "interrupted by " + signal_name(g_signal);
    if (s.exit_code == 0) s.exit_code = 128 + g_signal;
  } else if (!r.spawn_error.empty()) {
    s.status = "failed", s.error = "error: " + r.spawn_error, s.exit_code = 2;
  } else if (r.exit_code == 0 && produced) {
    s.status = "ok";
  } else {
    s.status = "failed";
    s.error = last_error_line(read_text(log));
    if (s.error.empty() && r.signal != 0)
      s.error = "error: killed by " + signal_name(r.signal);
    if (s.error.empty() && r.exit_code == 0) s.error = "error: the job wrote no output", s.exit_code = 1;
    if (s.error.empty()) s.error = "error: exit code " + std::to_string(r.exit_code) + " (see " + job_log_path(o.name) + ")";
  }
  if (s.status == "ok") {
    move_into_place(stage, out / o.name, out);
  } else {
    fs::remove_all(stage, ec);
  }
  write_file_atomic(status_path, to_json(s).dump(2) + "\n", true);
  return s.status == "ok" ? 0 : (s.exit_code != 0 ? s.exit_code : 1);
}

}  // namespace surftex::batch
