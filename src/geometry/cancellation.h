// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Cancellation of a run by SIGINT / SIGTERM / SIGHUP (issue 21 item 3). The
// signal handler only records the signal; the main thread notices it at the
// next check (every progress report, every output written, before the
// outputs are moved into place), unwinds with Cancelled, and removes what
// the run staged (geometry/output_file.h). A second signal while the first
// is being handled takes the default action (the process ends at once; the
// next run removes the staging folder it left, see sweep_stale_outputs).

#include "geometry/errors.h"

namespace surftex {

/// Thrown at a check after a signal arrived. Derives from Error so every
/// handler that cleans up on errors cleans up on a cancellation too.
class Cancelled : public Error {
 public:
  explicit Cancelled(int signo);
  int signal_number() const { return signo_; }

 private:
  int signo_;
};

/// Installs the flag-setting handler for SIGINT, SIGTERM and SIGHUP (the CLI
/// calls it once in main); a signal ignored on entry (nohup) stays ignored.
void install_cancel_handlers();

/// The signal that asked the run to stop, or 0.
int cancel_signal() noexcept;

/// Throws Cancelled if a signal arrived. Cheap (one atomic load).
void throw_if_cancelled();

}  // namespace surftex
