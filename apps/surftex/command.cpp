// SPDX-License-Identifier: AGPL-3.0-or-later
#include "surftex/command.h"

#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>

#include "geometry/cancellation.h"
#include "geometry/errors.h"
#include "geometry/image_io.h"
#include "geometry/output_file.h"
#include "geometry/work_budget.h"
#include "texture/image_ops.h"

namespace surftex::cli {

std::vector<Subcommand>& registry() {
  static std::vector<Subcommand> r;
  return r;
}

namespace {
// `in` read whole as a floating-point number (strtod: also "nan", "inf").
bool parse_whole_number(const std::string& in, double& v) {
  char* end = nullptr;
  v = std::strtod(in.c_str(), &end);
  return end != in.c_str() && *end == '\0';
}
}  // namespace

CLI::Validator whole_unsigned_64() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        const std::string range = "an integer 0..18446744073709551615";
        if (in.empty() || !std::isdigit(static_cast<unsigned char>(in[0])))
          return "must be " + range + " (got '" + in + "')";
        errno = 0;
        char* end = nullptr;
        (void)std::strtoull(in.c_str(), &end, 10);
        if (*end != '\0') return "must be " + range + " (got '" + in + "')";
        if (errno == ERANGE) return "must be " + range + " (got " + in + ", out of range)";
        return "";
      },
      "UINT64");
}

CLI::Validator number_above(double lo, bool strict) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", lo);
  const std::string bound = std::string(strict ? "> " : ">= ") + buf;
  return CLI::Validator(
      [lo, strict, bound](std::string& in) -> std::string {
        double v = 0;
        if (!parse_whole_number(in, v)) return "must be a number " + bound + " (got '" + in + "')";
        if (!(strict ? v > lo : v >= lo)) return "must be " + bound + " (got " + in + ")";
        return "";
      },
      "NUMBER " + bound);
}

CLI::Validator zero_or_range(long long lo, long long hi, const std::string& zero_means) {
  const std::string want =
      "0 (" + zero_means + ") or " + std::to_string(lo) + ".." + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, want](std::string& in) -> std::string {
        double v = 0;
        if (!parse_whole_number(in, v) || v != std::floor(v)) return "must be " + want + " (got '" + in + "')";
        if (v != 0 && (v < lo || v > hi)) return "must be " + want + " (got " + in + ")";
        return "";
      },
      "0 or " + std::to_string(lo) + ".." + std::to_string(hi));
}

CLI::Validator zero_or_between(double lo, double hi, const std::string& zero_means) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g..%g", lo, hi);
  const std::string want = "0 (" + zero_means + ") or " + buf;
  return CLI::Validator(
      [lo, hi, want](std::string& in) -> std::string {
        double v = 0;
        if (!parse_whole_number(in, v)) return "must be " + want + " (got '" + in + "')";
        if (v != 0 && !(v >= lo && v <= hi)) return "must be " + want + " (got " + in + ")";
        return "";
      },
      std::string("0 or ") + buf);
}

void add_common_options(CLI::App& app, CommonOptions& opt) {
  app.add_option("--seed", opt.seed,
                 "Seed for every random choice; the same input and seed give the same output "
                 "(an integer 0..18446744073709551615, default 1)")
      ->check(whole_unsigned_64());
  app.add_option("--threads", opt.threads,
                 "Worker threads (0 = all cores, default 0; 1..1024)")
      ->check(CLI::Range(0, 1024));
  app.add_option("--report", opt.report_path,
                 "Write a JSON report (timings, counts, quality figures) to this file");
  app.add_flag("--force", opt.force, "Replace output files that already exist (default: refuse)");
  app.add_flag("-q,--quiet", opt.quiet, "No progress display, even on a terminal");
  app.add_option("--max-image-pixels", opt.max_image_pixels,
                 "Largest image read, in pixels, checked from its header before decoding (default 16777216 = "
                 "4096x4096, 256 MiB decoded as 4-channel float; no side longer than 16384 px unless this "
                 "asks for more; 1..2^40)")
      ->check(CLI::Range(1LL, 1LL << 40));
  app.add_option("--max-memory", opt.max_memory,
                 "Memory budget: a run whose estimate (printed with the progress) is over it is refused "
                 "before it starts. A size (4G, 512M, bytes) or a share of RAM (50%); default 75% of RAM");
}

std::shared_ptr<void> apply_thread_limit(int threads) {
  std::size_t n = threads > 0 ? static_cast<std::size_t>(threads)
                              : std::max(1u, std::thread::hardware_concurrency());
  return std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism, n);
}

ProgressCallback terminal_progress(bool quiet) {
  // Never empty: every report is a cancellation point (SIGINT/SIGTERM), also
  // in pipes where nothing is drawn.
  if (quiet || !::isatty(STDERR_FILENO)) return [](std::string_view, double) { throw_if_cancelled(); };
  struct State {
    std::string stage;
    int pct = -1;
    long shown_seconds = -1;
    std::chrono::steady_clock::time_point start;
    std::mutex mu;
  };
  auto st = std::make_shared<State>();
  return [st](std::string_view stage, double fraction) {
    throw_if_cancelled();
    std::lock_guard<std::mutex> lock(st->mu);
    const auto now = std::chrono::steady_clock::now();
    const int pct = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0 + 0.5);
    // A new stage, or the same one again after it reached 100% (a scatter
    // pass after the last): its clock starts now.
    if (st->stage != stage || (st->pct >= 100 && pct < 100))
      st->stage = std::string(stage), st->pct = -1, st->start = now;
    const double elapsed = std::chrono::duration<double>(now - st->start).count();
    const long secs = static_cast<long>(elapsed);
    // Redrawn when the percentage changes or a second passes; 100% once.
    if (st->pct == pct && (pct >= 100 || st->shown_seconds == secs)) return;
    st->pct = pct;
    st->shown_seconds = secs;
    std::fprintf(stderr, "\r\033[K%s", progress_line(stage, pct, elapsed).c_str());
    if (pct >= 100) std::fputc('\n', stderr);
    std::fflush(stderr);
  };
}

void require_input_file(const std::string& input, const std::string& what) {
  std::error_code ec;
  if (input.empty()) throw InvalidInputError(what + " path is empty");
  if (!std::filesystem::exists(input, ec)) throw IOError(what + " '" + input + "' does not exist");
  if (!std::filesystem::is_regular_file(input, ec))
    throw IOError(what + " '" + input + "' is not a regular file");
}

LoadInputReport load_method_mesh(const std::string& path, Mesh& mesh, const CommonOptions& opt,
                                 bool keep_polygons) {
  LoadInputOptions lo;
  lo.keep_polygons = keep_polygons;
  lo.progress = terminal_progress(opt.quiet);
  LoadInputReport r = load_input_mesh(path, mesh, lo);
  if (!opt.quiet && !r.summary.empty())
    std::fprintf(stderr, "note: repaired '%s' before use: %s\n", path.c_str(), r.summary.c_str());
  return r;
}

void check_budget(const WorkEstimate& estimate, const CommonOptions& opt) {
  const std::string note = check_work_budget(estimate);
  if (!opt.quiet) std::fprintf(stderr, "note: %s\n", note.c_str());
}

nlohmann::json use_opaque_part(Image& exemplar, const std::vector<Image*>& maps, const CommonOptions& opt,
                               const std::string& which) {
  long long transparent = 0;
  for (int y = 0; y < exemplar.height; ++y)
    for (int x = 0; x < exemplar.width; ++x) transparent += is_transparent(exemplar, x, y);
  if (transparent == 0) return nullptr;
  const double share = static_cast<double>(transparent) / (static_cast<double>(exemplar.width) * exemplar.height);
  const PixelRect r = largest_opaque_rectangle(exemplar);
  const bool crop_it = 4 * r.area() >= static_cast<long long>(exemplar.width) * exemplar.height &&
                       std::min(r.width, r.height) >= 16;
  char msg[512];
  if (crop_it) {
    std::snprintf(msg, sizeof msg,
                  "%s has %.1f%% transparent pixels: its largest opaque block is used, %dx%d at (%d, %d) "
                  "(the output has no alpha)", which.c_str(), 100 * share, r.width, r.height, r.x, r.y);
    exemplar = crop(exemplar, r.x, r.y, r.width, r.height);
    for (Image* m : maps)
      if (m && !m->empty()) *m = crop(*m, r.x, r.y, r.width, r.height);
  } else {
    std::snprintf(msg, sizeof msg,
                  "%s has %.1f%% transparent pixels and no opaque block of a quarter of it: the colours "
                  "stored under them are used (the output has no alpha)", which.c_str(), 100 * share);
  }
  if (!opt.quiet) std::fprintf(stderr, "note: %s\n", msg);
  nlohmann::json j{{"transparent_share", share}, {"cropped", crop_it}};
  if (crop_it) j["opaque_block"] = {r.x, r.y, r.width, r.height};
  return j;
}

namespace {
void check_output_folder(const std::string& output) {
  const std::filesystem::path p(output);
  const std::filesystem::path dir = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw IOError("cannot write '" + output + "': folder '" + dir.string() + "' does not exist");
}
}  // namespace

void check_output(const std::string& output, const std::vector<std::string>& inputs, bool force,
                  bool folder_must_exist) {
  for (const auto& in : inputs)
    if (!in.empty() && same_file(output, in))
      throw InvalidInputError("output '" + output + "' is the input file '" + in +
                              "'; refusing to overwrite an input");
  if (folder_must_exist) check_output_folder(output);
  std::error_code ec;
  if (!force && std::filesystem::exists(output, ec) && !std::filesystem::is_directory(output, ec))
    throw IOError("output '" + output + "' already exists (pass --force to replace it)");
}

namespace {
// Numeric by the option's declared type (CLI11 type names: FLOAT, INT, UINT,
// NUMBER, UINT64, ... optionally followed by ':' and validator descriptions;
// several values as "[FLOAT,FLOAT]").
bool is_numeric_option(const CLI::Option& o) {
  std::string t = o.get_type_name();
  t = t.substr(0, t.find(':'));
  for (const char* k : {"FLOAT", "INT", "NUMBER", "UINT"})
    if (t.find(k) != std::string::npos) return true;
  return false;
}
}  // namespace

// --max-image-pixels and --max-memory for the whole run.
static void apply_limits(const CLI::App& sub) {
  for (const CLI::Option* o : sub.get_options()) {
    if (o->results().empty()) continue;
    const std::string& v = o->results().back();
    if (o->get_name() == "--max-image-pixels") {
      ImageLimits lim;
      lim.max_pixels = std::stoll(v);
      set_image_limits(lim);
    }
    if (o->get_name() == "--max-memory") set_memory_budget(parse_memory_size(v));
  }
}

void sweep_stale_outputs_of_arguments(const CLI::App& sub) {
  namespace fs = std::filesystem;
  std::set<std::string> dirs;
  for (const CLI::Option* o : sub.get_options())
    for (const std::string& r : o->results()) {
      if (r.empty() || r.size() > 4096 || dirs.size() >= 32) continue;
      std::error_code ec;
      const fs::path p(r);
      if (fs::is_directory(p, ec)) dirs.insert(p.string());
      const fs::path parent = p.parent_path().empty() ? fs::path(".") : p.parent_path();
      if (fs::is_directory(parent, ec)) dirs.insert(parent.string());
    }
  for (const std::string& d : dirs) sweep_stale_outputs(d);
}

void check_parsed_arguments(const CLI::App& sub) {
  std::string report;
  const CLI::Option* report_opt = nullptr;
  bool force = false;
  for (const CLI::Option* o : sub.get_options()) {
    const std::string name = o->get_name();
    if (name == "--report" && !o->results().empty()) report = o->results().back(), report_opt = o;
    if (name == "--force" && o->count() > 0) force = true;
    // An empty or blank string given to a numeric option (CLI11 reads it as 0).
    if (is_numeric_option(*o))
      for (const std::string& r : o->results())
        if (r.find_first_not_of(" \t\n\r\f\v") == std::string::npos)
          throw InvalidInputError(name + ": an empty string is not a number");
    // NaN and infinities in floating-point options (CLI11 checks compare with
    // < and >, which NaN passes).
    if (o->get_type_name().rfind("FLOAT", 0) == 0)
      for (const std::string& r : o->results()) {
        double v = 0;
        if (parse_whole_number(r, v) && !std::isfinite(v))
          throw InvalidInputError(name + ": '" + r + "' is not a finite number");
      }
  }
  apply_limits(sub);
  if (report.empty()) return;
  for (const CLI::Option* o : sub.get_options()) {
    if (o == report_opt) continue;
    for (const std::string& r : o->results())
      if (!r.empty() && same_file(report, r))
        throw InvalidInputError("--report '" + report + "' is also given as " + o->get_name() + " '" + r +
                                "'; refusing to overwrite it with the report");
  }
  check_output_folder(report);
  std::error_code ec;
  if (std::filesystem::is_directory(report, ec)) throw IOError("cannot write --report '" + report + "': it is a folder");
  if (!force && std::filesystem::exists(report, ec))
    throw IOError("--report '" + report + "' already exists (pass --force to replace it)");
}

Image read_exemplar_map(const std::string& path, const char* option, const std::string& colour_path,
                        const Image& colour) {
  if (path.empty()) return {};
  Image m = read_image(path);
  if (m.width != colour.width || m.height != colour.height)
    throw InvalidInputError(std::string(option) + " '" + path + "' is " + std::to_string(m.width) + " x " +
                            std::to_string(m.height) + ", the colour exemplar '" + colour_path + "' is " +
                            std::to_string(colour.width) + " x " + std::to_string(colour.height) +
                            " (exemplar maps must match it texel for texel)");
  return m;
}

}  // namespace surftex::cli
