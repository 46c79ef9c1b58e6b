// SPDX-License-Identifier: AGPL-3.0-or-later
// Start-up of the surftex command (issue 19 item 5): OpenImageIO and its
// ~260 shared libraries are loaded on the first image read or write
// (geometry/image_io_table.h), not at process start. glibc's LD_DEBUG=files
// lists every object the dynamic loader opens.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "test_support.h"

using namespace surftex;

namespace {
bool loads(const std::string& trace, const std::string& lib) {
  return trace.find(lib) != std::string::npos;
}
}  // namespace

TEST(Startup, VersionDoesNotLoadImageIoButReadingAnImageDoes) {
  const test::RunResult v = test::run_surftex("--version");
  ASSERT_EQ(v.exit_code, 0) << v.err;
  // run_surftex runs "BIN ARGS >out 2>err" in a shell: the traced run is the
  // second command of ARGS, whose output the redirections capture.
  const test::RunResult traced = test::run_surftex("--version >/dev/null 2>&1; LD_DEBUG=files '" +
                                                   std::string(SURFTEX_BINARY) + "' --version");
  ASSERT_EQ(traced.exit_code, 0) << traced.err;
  ASSERT_TRUE(loads(traced.err, "libtbb")) << "no loader trace: " << traced.err.substr(0, 400);
  // Sanitized builds (SURFTEX_SANITIZED, set by scripts/test.sh) link OpenImageIO
  // at start-up (src/geometry/CMakeLists.txt).
  if (std::getenv("SURFTEX_SANITIZED") != nullptr)
    EXPECT_TRUE(loads(traced.err, "libOpenImageIO"));
  else
    EXPECT_FALSE(loads(traced.err, "libOpenImageIO")) << "--version loaded OpenImageIO";
  EXPECT_FALSE(loads(traced.err, "libsurftex_image_io")) << "--version loaded the image IO module";
  // A command that reads an image loads the module (and OpenImageIO with it).
  const std::string dir = test::temp_dir("startup");
  const test::RunResult synth = test::run_surftex(
      "--version >/dev/null 2>&1; LD_DEBUG=files '" + std::string(SURFTEX_BINARY) + "' synth '" +
      test::shared_data("textures/leather_64.png") + "' -o '" + dir + "/out.png' --size 16x16 --quiet");
  ASSERT_EQ(synth.exit_code, 0) << synth.err.substr(synth.err.size() > 2000 ? synth.err.size() - 2000 : 0);
  EXPECT_TRUE(loads(synth.err, "libsurftex_image_io"));
  EXPECT_TRUE(loads(synth.err, "libOpenImageIO"));
}
