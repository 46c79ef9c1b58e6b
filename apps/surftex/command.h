// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The subcommand registry of the `surftex` command. Each apps/surftex/cmd_*.cpp
// defines one subcommand and registers it with a static SubcommandRegistrar;
// main.cpp needs no edit when a subcommand is added. Apps are thin: parse,
// validate, call the library, report (docs/STYLE.md 7).

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "geometry/load_input_mesh.h"
#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "surftex/report.h"
#include "geometry/image.h"
#include "geometry/work_budget.h"

namespace surftex::cli {

/// Options every subcommand takes (issue 2, item 7).
struct CommonOptions {
  std::uint64_t seed = 1;
  int threads = 0;          // 0 = all cores
  std::string report_path;  // JSON report, empty = none
  bool force = false;       // replace existing outputs
  bool quiet = false;       // no progress even on a terminal
  long long max_image_pixels = 1LL << 24;  // --max-image-pixels (geometry/image_io.h ImageLimits)
  std::string max_memory;                  // --max-memory, empty = 75% of RAM (geometry/work_budget.h)
};

/// A CLI11 check: a number > lo (strict) or >= lo; the message reads
/// "must be > 0 (got -1)" (CLI11's PositiveNumber prints a 300-digit range).
CLI::Validator number_above(double lo, bool strict);

/// A CLI11 check: 0 (meaning `zero_means`) or a whole number in lo..hi; the
/// message reads "must be 0 (from the vertices) or 64..8192 (got 10)".
CLI::Validator zero_or_range(long long lo, long long hi, const std::string& zero_means);

/// A CLI11 check: 0 (meaning `zero_means`) or a number in lo..hi; the
/// message reads "must be 0 (never) or 1.5..1e+06 (got 1)".
CLI::Validator zero_or_between(double lo, double hi, const std::string& zero_means);

/// A CLI11 check: a whole unsigned 64-bit integer ("18446744073709551616"
/// and "-1" are refused, not saturated or wrapped).
CLI::Validator whole_unsigned_64();

/// Adds --seed, --threads, --report, --force, --quiet, --max-image-pixels
/// and --max-memory to `app` (check_parsed_arguments applies the last two).
void add_common_options(CLI::App& app, CommonOptions& opt);

/// Applies --threads to TBB/OpenMP-style pools for the rest of the run; the
/// returned object keeps the limit alive.
std::shared_ptr<void> apply_thread_limit(int threads);

/// A progress callback that draws on stderr when it is a terminal and
/// !quiet, and does nothing in pipes. Each line shows the stage, its
/// percentage, the seconds since the stage began and, once a stage has run
/// 3 s and is 5% done, the time it has left at its pace so far
/// (progress_line).
ProgressCallback terminal_progress(bool quiet);

/// Throws InvalidInputError if `input` does not exist or is not a regular file.
void require_input_file(const std::string& input, const std::string& what);

/// Throws if `output` is one of `inputs`, exists while !force, or (when
/// folder_must_exist) its folder does not exist: before any work.
void check_output(const std::string& output, const std::vector<std::string>& inputs, bool force,
                  bool folder_must_exist = true);

/// Removes what killed runs left in the folders the arguments name
/// (sweep_stale_outputs), before the arguments are checked.
void sweep_stale_outputs_of_arguments(const CLI::App& sub);

/// Checks every subcommand's parsed arguments (main.cpp): applies the image
/// and memory limits, refuses empty numeric strings, NaN and infinities, and a
/// --report path that is another argument, exists without --force or lacks its
/// folder. Throws InvalidInputError / IOError.
void check_parsed_arguments(const CLI::App& sub);

/// Reads and repairs a method's input mesh (geometry/load_input_mesh.h): a
/// mesh that cannot be repaired is refused (TopologyError); what was repaired
/// is said in one "note:" line on stderr unless opt.quiet. Put the returned
/// report in the command's JSON report under "input_mesh" (to_json).
LoadInputReport load_method_mesh(const std::string& path, Mesh& mesh, const CommonOptions& opt,
                                 bool keep_polygons = false);

/// Refuses the run if its estimate (geometry/work_budget.h) is over the
/// memory budget or its exemplar over the method's size; otherwise prints
/// the estimate in one "note:" line on stderr unless opt.quiet.
void check_budget(const WorkEstimate& estimate, const CommonOptions& opt);

/// An exemplar for a method whose outputs have no alpha (subdiv, patches). With
/// transparent pixels (alpha < 0.5: a hole, a cut-out) it is cropped to its
/// largest opaque block when that holds at least a quarter of it and 16 pixels
/// a side, as the colours stored under the transparent pixels (often black)
/// would otherwise be copied onto the surface; `maps` (each the exemplar's
/// size, or empty) are cropped with it. Says what it did in a "note:" line
/// naming the image (`which`) unless opt.quiet; returns the report's record
/// (null when all is opaque).
nlohmann::json use_opaque_part(Image& exemplar, const std::vector<Image*>& maps, const CommonOptions& opt,
                               const std::string& which = "the exemplar");

/// An exemplar map given beside the colour exemplar (--exemplar-normal, ...):
/// empty when `path` is empty; refused (InvalidInputError naming `option`
/// and both sizes) unless it has the colour exemplar's size.
Image read_exemplar_map(const std::string& path, const char* option, const std::string& colour_path,
                        const Image& colour);

struct Subcommand {
  std::string name;
  std::string description;
  /// Declares the options on `app`; returns the function to run after parsing.
  std::function<std::function<int()>(CLI::App& app)> setup;
};

std::vector<Subcommand>& registry();

struct SubcommandRegistrar {
  explicit SubcommandRegistrar(Subcommand s) { registry().push_back(std::move(s)); }
};

}  // namespace surftex::cli
