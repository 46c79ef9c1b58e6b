// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Steps of `surftex demo`. Each method's subcommand file may add a step with a
// static DemoStepRegistrar, so the demo grows as methods land.
#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"

namespace surftex::cli {

/// What steps share: the output folder, the seed, and results of earlier steps.
struct DemoContext {
  std::string dir;
  std::uint64_t seed = 1;
  ProgressCallback progress;
  Image exemplar;  ///< a generated structured exemplar (step "synthesis")
  Image tile;      ///< a periodic tile (step "synthesis")
  /// DIR/name. Every name asked for is remembered: the files (and the files
  /// of the folders) among them that exist at the end are the demo report's
  /// "outputs".
  std::string path(const std::string& name) const {
    named.push_back(name);
    return (std::filesystem::path(dir) / name).string();
  }
  mutable std::vector<std::string> named;
  /// Files a step wrote besides the names it asked path() for (write_mesh's
  /// list: an OBJ's .mtl and texture), as paths.
  void wrote(const std::vector<std::string>& paths) { written.insert(written.end(), paths.begin(), paths.end()); }
  std::vector<std::string> written;
};

struct DemoStep {
  int order;  ///< steps run in increasing order
  std::string name;
  std::string description;
  std::function<nlohmann::json(DemoContext&)> run;
};

std::vector<DemoStep>& demo_steps();

struct DemoStepRegistrar {
  explicit DemoStepRegistrar(DemoStep s) { demo_steps().push_back(std::move(s)); }
};

}  // namespace surftex::cli
