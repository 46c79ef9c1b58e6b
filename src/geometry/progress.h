// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Progress reporting for long work: algorithms call the callback with a stage
// name and a fraction in [0,1]; the CLI shows it on a terminal, stays quiet in
// pipes. An empty callback costs nothing.

#include <functional>
#include <string_view>

namespace surftex {

using ProgressCallback = std::function<void(std::string_view stage, double fraction)>;

inline void report_progress(const ProgressCallback& cb, std::string_view stage, double fraction) {
  if (cb) cb(stage, fraction);
}

}  // namespace surftex
