// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
#include <chrono>

namespace surftex {

/// Wall-clock stopwatch for reports and benchmarks.
class Timer {
 public:
  Timer() : start_(std::chrono::steady_clock::now()) {}
  void reset() { start_ = std::chrono::steady_clock::now(); }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace surftex
