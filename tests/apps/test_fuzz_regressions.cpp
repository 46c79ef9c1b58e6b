// SPDX-License-Identifier: AGPL-3.0-or-later
// Every input the fuzzers found (fuzz/regressions/TARGET/*, kept forever)
// and every seed input replayed through the same target bodies as the
// libFuzzer binaries (fuzz/fuzz_targets.cpp): none may crash, hang or throw
// anything but a surftex::Error (issue 21 item 6). Under the sanitizer suite
// this is the fuzzers' ASan+UBSan check on the saved inputs.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fuzz_targets.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> bytes_of(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::vector<std::uint8_t>((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

std::size_t replay(const surftex::fuzz::Target& t, const fs::path& folder, std::size_t max_bytes = 1 << 20) {
  std::size_t n = 0;
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return 0;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder)) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& p : files) {
    if (!fs::is_regular_file(p) || fs::file_size(p) > max_bytes) continue;
    SCOPED_TRACE(p.string());
    const auto b = bytes_of(p);
    EXPECT_NO_THROW(t.body(b.data(), b.size()));
    ++n;
  }
  return n;
}

}  // namespace

TEST(FuzzRegressions, EverySavedFinderInputIsHandled) {
  std::size_t n = 0;
  for (const auto& t : surftex::fuzz::targets())
    n += replay(t, fs::path(SURFTEX_SOURCE_DIR) / "fuzz" / "regressions" / t.name);
  RecordProperty("inputs", static_cast<int>(n));
}

TEST(FuzzRegressions, SeedInputsRunThroughEveryTarget) {
  const auto& all = surftex::fuzz::targets();
  auto target = [&](const std::string& name) {
    for (const auto& t : all)
      if (name == t.name) return t;
    ADD_FAILURE() << name;
    return all[0];
  };
  EXPECT_GT(replay(target("fuzz_constraints"), fs::path(SURFTEX_SOURCE_DIR) / "fuzz" / "seeds" / "constraints"), 0u);
  EXPECT_GT(replay(target("fuzz_tile_json"), fs::path(SURFTEX_SOURCE_DIR) / "fuzz" / "seeds" / "tile_json"), 0u);
  EXPECT_GT(replay(target("fuzz_glb"), fs::path(SURFTEX_SOURCE_DIR) / "fuzz" / "seeds" / "glb"), 0u);
  // A few real files per mesh format and an image, from the shared data.
  for (const char* f : {"meshes/spot_quads.obj", "broken/malformed_indices.obj", "broken/truncated.off"}) {
    const fs::path p = surftex::test::shared_data(f);
    const auto b = bytes_of(p);
    EXPECT_NO_THROW(target(p.extension() == ".obj" ? "fuzz_obj" : "fuzz_off").body(b.data(), b.size()));
  }
  const auto png = bytes_of(surftex::test::shared_data("textures/leather_64.png"));
  EXPECT_NO_THROW(target("fuzz_image_header").body(png.data(), png.size()));
}
