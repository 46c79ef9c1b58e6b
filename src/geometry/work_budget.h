// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Work bounded before it starts (issue 21 item 5): every texturing
// subcommand estimates the peak memory and the time of its run from the
// mesh size, the exemplar size and its options, and refuses a run whose
// estimate is over the memory budget, naming the estimate and the option to
// change (--max-memory), before any of the work is done.
//
// The estimates are upper-bound linear fits of measured peak memory and CPU
// time at the CLI's defaults (docs/decisions/602-work-estimates.md): meant to
// catch runs of many GB or minutes, not to cut close to the limit.

#include <cstddef>
#include <string>

namespace surftex {

struct WorkEstimate {
  std::string what;    ///< "patches on 504000 faces", for messages
  double bytes = 0;    ///< peak resident memory
  double seconds = 0;  ///< CPU time on one core of the reference machine
  /// The options that shrink the work most, named in a refusal
  /// ("--patch-res, --max-patch-faces").
  std::string shrink;
  /// The exemplar and the longest side the method's search takes (candidates
  /// grow with the exemplar's width). 0 = no exemplar.
  int exemplar_width = 0, exemplar_height = 0, max_exemplar_side = 0;
};

/// The memory budget: --max-memory, by default 75% of the machine's RAM
/// (or of the cgroup's memory limit when that is smaller).
double default_memory_budget();
void set_memory_budget(double bytes);
double memory_budget();

/// Parses a size: a number of bytes, or with a suffix K, M, G, T (powers of
/// 1024; "KiB", "MB", ... accepted), or a percentage of the machine's RAM
/// ("50%"). Throws InvalidInputError naming `option`.
double parse_memory_size(const std::string& text, const std::string& option = "--max-memory");

/// "1.4 GiB", "512 MiB".
std::string format_bytes(double bytes);
/// "3 s", "4.2 min", "2.1 h".
std::string format_seconds(double s);

/// Throws InvalidInputError if the exemplar is longer than
/// e.max_exemplar_side ("downscale it"), or if e.bytes > memory_budget():
/// "WHAT needs about X of memory (estimate), over the budget of Y: pass
/// --max-memory to raise it, or reduce the work (SHRINK)". Returns a one-line
/// note with the estimate ("estimate: ...") for the caller to print.
std::string check_work_budget(const WorkEstimate& e);

// The estimates, one per subcommand. Sizes are counts (faces, pixels).
/// estimate_patches: min_exemplar_widths > 0 (PatchSynthesisOptions) may raise
/// the rasters up to about 12 (widths x exemplar width)^2 pixels in all (a
/// closed surface's area over its longest side squared is at most about 6,
/// the square rasters about twice their patches), never past one 4096^2 atlas.
WorkEstimate estimate_patches(std::size_t faces, int exemplar_width, int exemplar_height, int exemplars, int patch_res,
                              int max_patch_faces, int window, int rotations, bool exhaustive_search = false,
                              double min_exemplar_widths = 0);
WorkEstimate estimate_subdiv(std::size_t faces, int exemplar_width, int exemplar_height, int levels, int atlas);
WorkEstimate estimate_material_map(std::size_t faces, std::size_t tile_bytes, int render_size, int atlas_size);
WorkEstimate estimate_material_tile(int size, int layers, int keys, int key_width, int key_height);
WorkEstimate estimate_quilt(std::size_t faces, double output_faces);
WorkEstimate estimate_synth(int width, int height, int exemplar_width, int exemplar_height, int window, int rotations,
                            bool graphcut);
WorkEstimate estimate_tile(int size, int exemplar_width, int exemplar_height, int passes);

}  // namespace surftex
