// SPDX-License-Identifier: AGPL-3.0-or-later
// A fork server for the hostile-input campaigns (bench/hostile_campaign.py):
// the `surftex` command compiled in (apps/main.cpp, its main renamed), run
// once per input in a forked child, so that a campaign of thousands of runs
// does not pay the command's start-up (271 shared libraries: about 0.4 s of
// CPU and 2 s under load per run) each time. What a run does is exactly what
// `surftex ARGS...` does; the parent only forks, waits and measures.
//
// Protocol: one JSON array per stdin line, [STDERR_FILE, TIMEOUT_S, ARG...];
// one JSON object per stdout line: {"status": exit code | -signal,
// "hang": bool, "seconds": wall, "cpu_seconds": user + system, "max_rss_kb": of the child}.
#define main surftex_cli_main
#include "../apps/main.cpp"
#undef main

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <csignal>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace {

double now() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + t.tv_nsec * 1e-9;
}

}  // namespace

int main() {
  std::string line;
  while (std::getline(std::cin, line)) {
    const nlohmann::json req = nlohmann::json::parse(line, nullptr, false);
    if (!req.is_array() || req.size() < 2) {
      std::cout << "{\"error\":\"bad request\"}" << std::endl;
      continue;
    }
    const std::string err_path = req[0].get<std::string>();
    const double timeout = req[1].get<double>();
    std::vector<std::string> args{"surftex"};
    for (std::size_t i = 2; i < req.size(); ++i) args.push_back(req[i].get<std::string>());
    std::cout.flush();
    const double t0 = now();
    const pid_t pid = fork();
    if (pid == 0) {
      const int null = open("/dev/null", O_RDWR);
      const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(null, 0);
      dup2(null, 1);
      dup2(err, 2);
      const rlimit as{6ull << 30, 6ull << 30};  // protect the shared machine
      setrlimit(RLIMIT_AS, &as);
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      const int rc = surftex_cli_main(static_cast<int>(args.size()), argv.data());
      std::fflush(nullptr);
      _exit(rc);
    }
    int status = 0;
    rusage ru{};
    bool hang = false;
    for (;;) {
      const pid_t r = wait4(pid, &status, WNOHANG, &ru);
      if (r == pid) break;
      if (now() - t0 > timeout) {
        kill(pid, SIGKILL);
        wait4(pid, &status, 0, &ru);
        hang = true;
        break;
      }
      usleep(2000);
    }
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -(WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    const double cpu = ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    nlohmann::json out{{"status", code}, {"hang", hang}, {"seconds", now() - t0}, {"cpu_seconds", cpu},
                       {"max_rss_kb", ru.ru_maxrss}};
    std::cout << out.dump() << std::endl;
  }
  return 0;
}
