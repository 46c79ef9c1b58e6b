// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Progress reporting for long work: algorithms call the callback with a stage
// name and a fraction in [0,1]; the CLI shows it on a terminal, stays quiet in
// pipes. An empty callback costs nothing.

#include <functional>
#include <string>
#include <string_view>

namespace surftex {

using ProgressCallback = std::function<void(std::string_view stage, double fraction)>;

/// One progress line as the CLI draws it: "quilt  31%  12 s, about 27 s
/// left": the stage, its percentage, the seconds since it began and, from 3 s
/// and 5% on, the time left at its pace so far (minutes from 100 s on, "1 min
/// 40 s"; no estimate at 100%).
std::string progress_line(std::string_view stage, int percent, double elapsed_seconds);

inline void report_progress(const ProgressCallback& cb, std::string_view stage, double fraction) {
  if (cb) cb(stage, fraction);
}

}  // namespace surftex
