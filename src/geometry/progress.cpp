// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/progress.h"

#include <cmath>
#include <cstdio>

namespace surftex {
namespace {
std::string duration_text(double s) {
  const long r = std::lround(s);
  if (r < 100) return std::to_string(r) + " s";
  return std::to_string(r / 60) + " min " + std::to_string(r % 60) + " s";
}
}  // namespace

std::string progress_line(std::string_view stage, int percent, double elapsed_seconds) {
  char pct[8];
  std::snprintf(pct, sizeof pct, "%3d%%", percent);
  std::string line = std::string(stage) + " " + pct + "  " + duration_text(elapsed_seconds);
  if (percent >= 5 && percent < 100 && elapsed_seconds >= 3)
    line += ", about " + duration_text(elapsed_seconds * (100 - percent) / percent) + " left";
  return line;
}

}  // namespace surftex
