// SPDX-License-Identifier: AGPL-3.0-or-later
// Behaviour of the `surftex` command as a user sees it: exit codes, `error:`
// messages, help text.
#include <gtest/gtest.h>

#include "geometry/progress.h"
#include "test_support.h"

using surftex::test::run_surftex;

TEST(Cli, NoSubcommandIsAnErrorWithExitCode2) {
  auto r = run_surftex("");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("error:"), std::string::npos) << r.err;
}

TEST(Cli, UnknownSubcommandIsAnError) {
  auto r = run_surftex("frobnicate");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("error:"), std::string::npos);
}

TEST(Cli, HelpListsSubcommandsAndExitsZero) {
  auto r = run_surftex("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("version"), std::string::npos);
  EXPECT_NE(r.out.find("surftex"), std::string::npos);
}

TEST(Cli, VersionNamesTheLibraries) {
  auto r = run_surftex("version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("CGAL 5.5"), std::string::npos) << r.out;
}

// The terminal's progress line: stage, percentage, seconds in the stage and,
// once the stage has run 3 s and is 5% done, the time left at its pace.
TEST(ProgressLine, ShowsElapsedAndTheTimeLeftAtThePaceSoFar) {
  using surftex::progress_line;
  EXPECT_EQ(progress_line("quilt", 31, 12.0), "quilt  31%  12 s, about 27 s left");
  EXPECT_EQ(progress_line("quilt", 31, 2.0), "quilt  31%  2 s");        // too early to tell
  EXPECT_EQ(progress_line("repair", 2, 40.0), "repair   2%  40 s");     // too little done
  EXPECT_EQ(progress_line("embed", 100, 7.4), "embed 100%  7 s");       // done: no estimate
  EXPECT_EQ(progress_line("quilt refill 2/6", 50, 130.0), "quilt refill 2/6  50%  2 min 10 s, about 2 min 10 s left");
}
