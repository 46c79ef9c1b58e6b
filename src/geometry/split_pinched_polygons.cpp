// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/split_pinched_polygons.h"

#include <limits>

namespace surftex {

namespace {
constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
}

PinchedSplitCounts split_pinched_polygons(std::vector<std::vector<std::size_t>>& polygons, std::size_t points) {
  PinchedSplitCounts c;
  // Stamp per point: the polygon that saw it last, and its position on the stack.
  std::vector<std::size_t> seen_in(points, kNone), at(points, kNone);
  std::vector<std::size_t> stack;
  std::vector<std::vector<std::size_t>> added;
  const std::size_t n = polygons.size();
  for (std::size_t i = 0; i < n; ++i) {
    bool repeated = false;
    for (std::size_t v : polygons[i]) {
      if (seen_in[v] == i) {
        repeated = true;
        break;
      }
      seen_in[v] = i;
    }
    if (!repeated) continue;
    ++c.polygons_split;
    // Second pass with a fresh stamp (i + n cannot collide with a polygon index).
    const std::size_t stamp = i + n;
    stack.clear();
    std::vector<std::vector<std::size_t>> cycles;
    for (std::size_t v : polygons[i]) {
      if (seen_in[v] == stamp && at[v] != kNone) {
        const std::size_t p = at[v];
        std::vector<std::size_t> cyc(stack.begin() + static_cast<std::ptrdiff_t>(p), stack.end());
        for (std::size_t k = p + 1; k < stack.size(); ++k) at[stack[k]] = kNone;
        stack.resize(p + 1);  // v stays on top: the path continues from it
        if (cyc.size() >= 3) cycles.push_back(std::move(cyc));
        else ++c.cycles_dropped;
        continue;
      }
      seen_in[v] = stamp;
      at[v] = stack.size();
      stack.push_back(v);
    }
    for (std::size_t v : stack) at[v] = kNone;
    // What remains closes back to the first corner.
    std::vector<std::size_t> rest = stack;
    if (rest.size() >= 3) cycles.push_back(std::move(rest));
    else if (!rest.empty()) ++c.cycles_dropped;
    if (cycles.empty()) {
      polygons[i].clear();  // nothing with area: left empty for the degenerate-polygon removal
      continue;
    }
    polygons[i] = std::move(cycles[0]);
    for (std::size_t k = 1; k < cycles.size(); ++k) added.push_back(std::move(cycles[k]));
  }
  c.polygons_added = added.size();
  for (auto& p : added) polygons.push_back(std::move(p));
  return c;
}

}  // namespace surftex
