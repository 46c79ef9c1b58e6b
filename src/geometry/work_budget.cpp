// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/work_budget.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "geometry/errors.h"

namespace surftex {

namespace {

constexpr double kMiB = 1024.0 * 1024.0;
constexpr double kGiB = 1024.0 * kMiB;

double physical_memory() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  double ram = pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 8 * kGiB;
  // A cgroup (container) limit below the machine's RAM is the real ceiling.
  std::ifstream cg("/sys/fs/cgroup/memory.max");
  std::string v;
  if (cg >> v && v != "max") {
    const double lim = std::strtod(v.c_str(), nullptr);
    if (lim > 0) ram = std::min(ram, lim);
  }
  return ram;
}

double g_budget = -1;

// The process before any work: the binary and its 271 shared libraries
// (measured: `surftex version`, 136 MB max RSS).
constexpr double kBase = 160 * kMiB;

}  // namespace

double default_memory_budget() { return 0.75 * physical_memory(); }
void set_memory_budget(double bytes) { g_budget = bytes; }
double memory_budget() { return g_budget > 0 ? g_budget : default_memory_budget(); }

double parse_memory_size(const std::string& text, const std::string& option) {
  std::string s;
  for (char c : text)
    if (!std::isspace(static_cast<unsigned char>(c))) s += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const std::string expect = " (a size such as 4G, 512M, 2000000000 or 50%)";
  if (s.empty()) throw InvalidInputError(option + ": an empty string is not a size" + expect);
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end == s.c_str() || !std::isfinite(v) || !(v > 0))
    throw InvalidInputError(option + ": '" + text + "' is not a positive size" + expect);
  std::string unit(end);
  if (unit == "%") {
    if (v > 100) throw InvalidInputError(option + ": '" + text + "' is more than 100% of the memory");
    return v / 100 * physical_memory();
  }
  if (unit.size() > 1 && unit.back() == 'B') unit.pop_back();
  if (unit.size() > 1 && unit.back() == 'I') unit.pop_back();
  double mult = 0;
  if (unit.empty()) mult = 1;
  else if (unit == "K") mult = 1024;
  else if (unit == "M") mult = kMiB;
  else if (unit == "G") mult = kGiB;
  else if (unit == "T") mult = 1024 * kGiB;
  if (mult == 0) throw InvalidInputError(option + ": '" + text + "' has an unknown unit" + expect);
  const double bytes = v * mult;
  if (!std::isfinite(bytes) || bytes > 1e18) throw InvalidInputError(option + ": '" + text + "' is too large");
  return bytes;
}

std::string format_bytes(double b) {
  char buf[48];
  if (b >= kGiB) std::snprintf(buf, sizeof buf, "%.1f GiB", b / kGiB);
  else std::snprintf(buf, sizeof buf, "%.0f MiB", std::ceil(b / kMiB));
  return buf;
}

std::string format_seconds(double s) {
  char buf[48];
  if (s < 90) std::snprintf(buf, sizeof buf, "%.0f s", std::ceil(s));
  else if (s < 5400) std::snprintf(buf, sizeof buf, "%.1f min", s / 60);
  else std::snprintf(buf, sizeof buf, "%.1f h", s / 3600);
  return buf;
}

std::string check_work_budget(const WorkEstimate& e) {
  if (e.max_exemplar_side > 0 && std::max(e.exemplar_width, e.exemplar_height) > e.max_exemplar_side)
    throw InvalidInputError(e.what + ": the exemplar is " + std::to_string(e.exemplar_width) + "x" +
                            std::to_string(e.exemplar_height) + " pixels; this method's search takes at most " +
                            std::to_string(e.max_exemplar_side) +
                            " px a side (its cost grows with the exemplar's width): downscale it first (e.g. "
                            "oiiotool EXEMPLAR --resize 512x0 -o SMALL.png)");
  const double budget = memory_budget();
  if (e.bytes > budget)
    throw InvalidInputError(e.what + " needs about " + format_bytes(e.bytes) + " of memory (estimate; about " +
                            format_seconds(e.seconds) + " of CPU time), over the budget of " + format_bytes(budget) +
                            ": pass --max-memory to raise it, or reduce the work" +
                            (e.shrink.empty() ? std::string() : " (" + e.shrink + ")"));
  return "estimate: " + e.what + ": about " + format_bytes(e.bytes) + " of memory and " + format_seconds(e.seconds) +
         " of CPU time (budget " + format_bytes(budget) + ", --max-memory)";
}

// ---------------------------------------------------------------- estimates
// Coefficients: docs/decisions/602-work-estimates.md (measured, then rounded
// up; each estimate is at or above every measurement of the fit).

// Longest exemplar side a search takes: Efros-Leung-type searches (synth
// el2pass, patches, subdiv, material-tile keys) preselect one candidate per
// exemplar column; graph-cut and tile searches use FFT matching.
constexpr int kElSide = 2048;
constexpr int kGraphcutSide = 4096;

void exemplar(WorkEstimate& e, int w, int h, int max_side) {
  e.exemplar_width = w;
  e.exemplar_height = h;
  e.max_exemplar_side = max_side;
}

WorkEstimate estimate_patches(std::size_t faces, int exemplar_width, int exemplar_height, int exemplars, int patch_res,
                              int max_patch_faces, int window, int rotations, bool exhaustive_search,
                              double min_exemplar_widths) {
  const double exemplar_pixels = static_cast<double>(exemplar_width) * exemplar_height;
  const double F = static_cast<double>(faces);
  const double patches = F / std::max(1, max_patch_faces) * 1.6 + 8;  // greedy patches are smaller than the cap
  const double floor_px = std::min(4096.0 * 4096.0, 12.0 * std::pow(min_exemplar_widths * exemplar_width, 2.0));
  const double res2 = std::max(static_cast<double>(patch_res) * patch_res, floor_px / patches);
  const double ex = static_cast<double>(exemplar_pixels) * std::max(1, exemplars);
  WorkEstimate e;
  e.what = "patches on " + std::to_string(faces) + " faces";
  e.bytes = kBase + 6000.0 * F + patches * res2 * 100.0 + ex * std::max(1, rotations) * 60.0;
  // The exhaustive first pass scans the exemplar per pixel; the approximate
  // one (the default) ranks a short list, and the report's fidelity figure
  // grows with the exemplar (decision 602).
  e.seconds = exhaustive_search ? 1e-4 * F + patches * res2 * (window * window) * ex * 1.9e-11
                                : 1e-4 * F + patches * res2 * (window * window) / 121.0 * 8e-6 + ex * 1e-4;
  e.shrink = "--patch-res, --max-patch-faces, a smaller mesh";
  exemplar(e, exemplar_width, exemplar_height, kElSide);
  return e;
}

WorkEstimate estimate_subdiv(std::size_t faces, int exemplar_width, int exemplar_height, int levels, int atlas) {
  const double exemplar_pixels = static_cast<double>(exemplar_width) * exemplar_height;
  const double F = static_cast<double>(faces) * std::pow(2.0, std::max(0, levels));
  WorkEstimate e;
  e.what = "subdiv on " + std::to_string(faces) + " faces (" + std::to_string(static_cast<long long>(F)) +
           " after " + std::to_string(levels) + " levels)";
  e.bytes = kBase + 3000.0 * F + static_cast<double>(exemplar_pixels) * 200.0 + static_cast<double>(atlas) * atlas * 40.0;
  e.seconds = 6e-5 * F * std::max(1.0, exemplar_pixels / 65536.0);  // decision 602: 4e-5 measured
  e.shrink = "--levels, a smaller mesh";
  exemplar(e, exemplar_width, exemplar_height, kElSide);
  return e;
}

WorkEstimate estimate_material_map(std::size_t faces, std::size_t tile_bytes, int render_size, int atlas_size) {
  const double F = static_cast<double>(faces);
  const double atlas_texels = static_cast<double>(atlas_size) * atlas_size;
  WorkEstimate e;
  e.what = "material-map on " + std::to_string(faces) + " faces with a " + std::to_string(atlas_size) + "^2 atlas";
  // The baked atlas (colour, normal, height, lookup and gutter buffers) costs
  // about 49 bytes per texel; 96 MiB covers the mapping's fixed cost.
  e.bytes = kBase + 96.0 * 1048576.0 + 5000.0 * F + 2.0 * static_cast<double>(tile_bytes) +
            static_cast<double>(render_size) * render_size * 100.0 + 56.0 * atlas_texels;
  e.seconds = 1.0 + 2e-4 * F + 3e-6 * static_cast<double>(render_size) * render_size + 1.2e-6 * atlas_texels;
  e.shrink = "--atlas-size, a smaller mesh";
  return e;
}

WorkEstimate estimate_material_tile(int size, int layers, int keys, int key_width, int key_height) {
  const double key_pixels = static_cast<double>(key_width) * key_height;
  const double px = static_cast<double>(size) * size;
  WorkEstimate e;
  e.what = "material-tile of " + std::to_string(size) + "x" + std::to_string(size) + " with " +
           std::to_string(std::max(1, layers)) + " layers per pair";
  const double L = static_cast<double>(std::max(1, layers)) * std::max(1, keys - 1) + 1;
  e.bytes = kBase + L * px * 128.0 + static_cast<double>(key_pixels) * 128.0;
  e.seconds = L * px * 1e-4;
  e.shrink = "--size, --layers";
  exemplar(e, key_width, key_height, kElSide);
  return e;
}

WorkEstimate estimate_quilt(std::size_t faces, double output_faces) {
  WorkEstimate e;
  e.what = "quilt on " + std::to_string(faces) + " faces (about " + std::to_string(static_cast<long long>(output_faces)) +
           " output faces)";
  e.bytes = kBase + 3000.0 * static_cast<double>(faces) + 800.0 * output_faces;
  e.seconds = 1e-4 * static_cast<double>(faces) + 1.5e-4 * output_faces;
  e.shrink = "a larger element spacing, a smaller mesh";
  return e;
}

WorkEstimate estimate_synth(int width, int height, int exemplar_width, int exemplar_height, int window, int rotations,
                            bool graphcut) {
  const long long exemplar_pixels = static_cast<long long>(exemplar_width) * exemplar_height;
  const double out = static_cast<double>(width) * height;
  const double ex = static_cast<double>(exemplar_pixels);
  WorkEstimate e;
  e.what = std::string("synth (") + (graphcut ? "graphcut" : "el2pass") + ") of " + std::to_string(width) + "x" +
           std::to_string(height) + " from a " + std::to_string(exemplar_pixels) + "-pixel exemplar";
  // Rotated copies of the exemplar (RGB floats) and per-pixel buffers; the
  // search compares every output pixel with the exemplar's candidates.
  e.bytes = kBase + out * 200.0 + ex * std::max(1, rotations) * 12.0 + ex * 64.0;
  e.seconds = graphcut ? out * 2e-5 : out * ex * 1.5e-8 * (window * window) / 121.0;
  e.shrink = graphcut ? "--size" : "--size, a smaller exemplar, --rotations";
  exemplar(e, exemplar_width, exemplar_height, graphcut ? kGraphcutSide : kElSide);
  return e;
}

WorkEstimate estimate_tile(int size, int exemplar_width, int exemplar_height, int passes) {
  const double exemplar_pixels = static_cast<double>(exemplar_width) * exemplar_height;
  const double px = static_cast<double>(size) * size;
  WorkEstimate e;
  e.what = "tile of " + std::to_string(size) + "x" + std::to_string(size);
  e.bytes = kBase + px * 400.0 + static_cast<double>(exemplar_pixels) * 400.0;
  e.seconds = px * std::max(1, passes) * 2e-5;
  e.shrink = "--size";
  exemplar(e, exemplar_width, exemplar_height, kGraphcutSide);
  return e;
}

}  // namespace surftex
