// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/cancellation.h"

#include <csignal>
#include <string>

namespace surftex {

namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_cancel_signal(int signo) {
  // Async-signal-safe only: record the signal; a second one ends the process
  // with the default action (the user insists).
  if (g_signal != 0) {
    std::signal(signo, SIG_DFL);
    std::raise(signo);
    return;
  }
  g_signal = signo;
}

const char* signal_name(int s) {
  switch (s) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
  }
}

}  // namespace

Cancelled::Cancelled(int signo)
    : Error(std::string("interrupted by ") + signal_name(signo) + "; nothing was written"), signo_(signo) {}

void install_cancel_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_cancel_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;  // interrupted reads and writes resume; the flag is polled
  for (int s : {SIGINT, SIGTERM, SIGHUP}) {
    // A signal ignored on entry stays ignored (nohup, background jobs of a
    // non-interactive shell): the caller asked not to be stopped by it.
    struct sigaction old {};
    if (sigaction(s, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    sigaction(s, &sa, nullptr);
  }
}

int cancel_signal() noexcept { return g_signal; }

void throw_if_cancelled() {
  if (g_signal != 0) throw Cancelled(g_signal);
}

}  // namespace surftex
