// SPDX-License-Identifier: AGPL-3.0-or-later
// Behaviour of the `surftex` command as a user sees it: exit codes, `error:`
// messages, help text.
#include <gtest/gtest.h>

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
