// SPDX-License-Identifier: AGPL-3.0-or-later
#include "surftex/command.h"

#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <thread>

#include "geometry/errors.h"
#include "geometry/output_file.h"

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

void add_common_options(CLI::App& app, CommonOptions& opt) {
  app.add_option("--seed", opt.seed,
                 "Seed for every random choice; the same input and seed give the same output "
                 "(any non-negative integer, default 1)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--threads", opt.threads,
                 "Worker threads (0 = all cores, default 0; 1..1024)")
      ->check(CLI::Range(0, 1024));
  app.add_option("--report", opt.report_path,
                 "Write a JSON report (timings, counts, quality figures) to this file");
  app.add_flag("--force", opt.force, "Replace output files that already exist (default: refuse)");
  app.add_flag("-q,--quiet", opt.quiet, "No progress display, even on a terminal");
}

std::shared_ptr<void> apply_thread_limit(int threads) {
  std::size_t n = threads > 0 ? static_cast<std::size_t>(threads)
                              : std::max(1u, std::thread::hardware_concurrency());
  return std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism, n);
}

ProgressCallback terminal_progress(bool quiet) {
  if (quiet || !::isatty(STDERR_FILENO)) return {};
  auto last = std::make_shared<std::pair<std::string, int>>("", -1);
  auto mu = std::make_shared<std::mutex>();
  return [last, mu](std::string_view stage, double fraction) {
    std::lock_guard<std::mutex> lock(*mu);
    int pct = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0 + 0.5);
    if (last->first == stage && last->second == pct) return;
    last->first = std::string(stage);
    last->second = pct;
    std::fprintf(stderr, "\r\033[K%.*s %3d%%", static_cast<int>(stage.size()), stage.data(), pct);
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

void check_parsed_arguments(const CLI::App& sub) {
  std::string report;
  const CLI::Option* report_opt = nullptr;
  bool force = false;
  for (const CLI::Option* o : sub.get_options()) {
    const std::string name = o->get_name();
    if (name == "--report" && !o->results().empty()) report = o->results().back(), report_opt = o;
    if (name == "--force" && o->count() > 0) force = true;
    // NaN and infinities in floating-point options (CLI11 checks compare with
    // < and >, which NaN passes).
    if (o->get_type_name().rfind("FLOAT", 0) == 0)
      for (const std::string& r : o->results()) {
        double v = 0;
        if (parse_whole_number(r, v) && !std::isfinite(v))
          throw InvalidInputError(name + ": '" + r + "' is not a finite number");
      }
  }
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

}  // namespace surftex::cli
