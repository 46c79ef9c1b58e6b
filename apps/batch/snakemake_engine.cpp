// SPDX-License-Identifier: AGPL-3.0-or-later
#include "batch/snakemake_engine.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "geometry/errors.h"

namespace surftex::batch {

std::string snakemake_event_handler_script() {
  return R"(# Written by `surftex batch`: forwards Snakemake's job events to surftex, one
# JSON line each, on the file descriptor named by SURFTEX_BATCH_EVENT_FD.
# Without that variable (Snakemake run by hand) it does nothing.
import json
import os

_fd = int(os.environ.get("SURFTEX_BATCH_EVENT_FD", "-1"))


def _send(event):
    try:
        os.write(_fd, (json.dumps(event) + "\n").encode("utf-8"))
    except (OSError, TypeError, ValueError):
        pass


def log_handler(msg):
    if _fd < 0:
        return
    level = msg.get("level")
    if level == "run_info":
        _send({"event": "plan", "text": str(msg.get("msg", ""))})
    elif level == "job_info":
        _send({"event": "start", "rule": msg.get("name"), "jobid": msg.get("jobid"),
               "reason": str(msg.get("reason", ""))})
    elif level == "job_finished":
        _send({"event": "finish", "jobid": msg.get("jobid")})
    elif level == "job_error":
        _send({"event": "error", "rule": msg.get("name"), "jobid": msg.get("jobid")})
    elif level == "progress":
        _send({"event": "progress", "done": msg.get("done"), "total": msg.get("total")})
)";
}

std::string find_snakemake() {
  if (const char* env = std::getenv("SURFTEX_SNAKEMAKE"); env && *env) return ::access(env, X_OK) == 0 ? env : "";
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "/usr/bin:/bin");
  for (std::string dir; std::getline(ss, dir, ':');) {
    if (dir.empty()) continue;
    const std::string p = dir + "/snakemake";
    struct stat st{};
    if (::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0) return p;
  }
  return "";
}

std::vector<std::pair<std::string, int>> parse_job_stats(const std::string& text) {
  std::vector<std::pair<std::string, int>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string rule, count;
    if (!(ls >> rule >> count)) continue;
    if (rule == "job" || rule == "total" || count.find_first_not_of("0123456789") != std::string::npos) continue;
    rows.emplace_back(rule, std::stoi(count));
  }
  return rows;
}

namespace {

volatile std::sig_atomic_t g_signals = 0;
volatile std::sig_atomic_t g_first = 0;

void on_engine_signal(int sig) {
  if (g_first == 0) g_first = sig;
  g_signals = g_signals + 1;
}

struct SignalScope {
  struct sigaction old[3]{};
  const int sigs[3] = {SIGTERM, SIGINT, SIGHUP};
  SignalScope() {
    g_signals = 0, g_first = 0;
    struct sigaction sa{};
    sa.sa_handler = on_engine_signal;
    sigemptyset(&sa.sa_mask);
    for (int i = 0; i < 3; ++i) ::sigaction(sigs[i], &sa, &old[i]);
  }
  ~SignalScope() {
    for (int i = 0; i < 3; ++i) ::sigaction(sigs[i], &old[i], nullptr);
  }
};

pid_t spawn(const std::vector<std::string>& args, const std::string& log_path, int event_fd) {
  const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log < 0) throw IOError("cannot write '" + log_path + "': " + std::strerror(errno));
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);  // its own group: the batch stops Snakemake and its jobs together
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) ::dup2(devnull, 0);
    ::dup2(log, 1);
    ::dup2(log, 2);
    if (event_fd != 3) {
      ::dup2(event_fd, 3);  // dup2 clears close-on-exec
    } else {
      ::fcntl(3, F_SETFD, 0);
    }
    ::setenv("SURFTEX_BATCH_EVENT_FD", "3", 1);
    struct sigaction sa{};
    sa.sa_handler = SIG_DFL;
    for (int s : {SIGTERM, SIGINT, SIGHUP, SIGPIPE}) ::sigaction(s, &sa, nullptr);
    ::execv(argv[0], argv.data());
    std::fprintf(stderr, "cannot run '%s': %s\n", argv[0], std::strerror(errno));
    ::_exit(127);
  }
  ::close(log);
  if (pid < 0) throw IOError(std::string("cannot start snakemake: ") + std::strerror(errno));
  ::setpgid(pid, pid);  // also here, so a signal right after fork reaches the group
  return pid;
}

}  // namespace

EngineResult run_snakemake(const std::vector<std::string>& argv, const std::string& log_path,
                           const std::function<void(const nlohmann::json&)>& on_event,
                           const std::function<void()>& on_tick) {
  SignalScope signals;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw IOError(std::string("cannot create a pipe: ") + std::strerror(errno));
  const pid_t pid = spawn(argv, log_path, fds[1]);
  ::close(fds[1]);
  std::string buf;
  int forwarded = 0;
  bool open = true;
  EngineResult r;
  int status = 0;
  bool exited = false;
  while (!exited) {
    if (g_signals > forwarded) {
      // First signal: SIGTERM to Snakemake and its jobs (each job removes its
      // stage); a second one: SIGKILL.
      ::kill(-pid, forwarded == 0 ? SIGTERM : SIGKILL);
      forwarded = g_signals;
    }
    if (open) {
      pollfd p{fds[0], POLLIN, 0};
      const int n = ::poll(&p, 1, 500);
      if (n > 0) {
        char chunk[4096];
        const ssize_t got = ::read(fds[0], chunk, sizeof chunk);
        if (got > 0) {
          buf.append(chunk, static_cast<std::size_t>(got));
          for (std::size_t nl; (nl = buf.find('\n')) != std::string::npos; buf.erase(0, nl + 1)) {
            nlohmann::json e = nlohmann::json::parse(buf.substr(0, nl), nullptr, false);
            if (!e.is_discarded() && e.is_object()) on_event(e);
          }
        } else if (got == 0 || (errno != EINTR && errno != EAGAIN)) {
          open = false;
        }
      }
    } else {
      ::usleep(200 * 1000);
    }
    on_tick();
    const pid_t w = ::waitpid(pid, &status, WNOHANG);
    exited = w == pid;
    if (exited && open) {
      // Drain what Snakemake wrote before it exited.
      ::fcntl(fds[0], F_SETFL, O_NONBLOCK);
      char chunk[4096];
      for (ssize_t got; (got = ::read(fds[0], chunk, sizeof chunk)) > 0;) buf.append(chunk, static_cast<std::size_t>(got));
      for (std::size_t nl; (nl = buf.find('\n')) != std::string::npos; buf.erase(0, nl + 1)) {
        nlohmann::json e = nlohmann::json::parse(buf.substr(0, nl), nullptr, false);
        if (!e.is_discarded() && e.is_object()) on_event(e);
      }
    }
  }
  ::close(fds[0]);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  r.signal = g_first;
  return r;
}

std::string snakemake_error_excerpt(const std::string& log_text) {
  std::vector<std::string> lines;
  std::istringstream in(log_text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  // From the first line that names an error, else the last 15 lines.
  std::size_t from = lines.size() > 15 ? lines.size() - 15 : 0;
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (lines[i].find("Error") != std::string::npos || lines[i].find("Exception") != std::string::npos ||
        lines[i].find("error:") != std::string::npos) {
      from = i;
      break;
    }
  std::string out;
  for (std::size_t i = from; i < lines.size() && i < from + 25; ++i) out += "  " + lines[i] + "\n";
  return out;
}

}  // namespace surftex::batch
