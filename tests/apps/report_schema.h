// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The checks of the one report schema (apps/surftex/report.h), shared by the
// report tests of every subcommand.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace surftex::test {

/// sha256sum's digest of `path` (independent of surftex's own SHA-256).
inline std::string sha256sum(const std::string& path) {
  FILE* p = ::popen(("sha256sum '" + path + "'").c_str(), "r");
  if (!p) return {};
  char out[65] = {};
  const std::size_t n = std::fread(out, 1, 64, p);
  ::pclose(p);
  return std::string(out, n);
}

/// Every shared key with its type; `inputs` among the hashed inputs (with
/// the right size and digest), `outputs` among the outputs, every output an
/// existing file.
inline void expect_report_schema(const nlohmann::json& j, const std::string& command,
                                 const std::vector<std::string>& inputs, const std::vector<std::string>& outputs) {
  SCOPED_TRACE("report of " + command);
  for (const char* k : {"surftex_version", "command", "command_line", "seed", "threads", "inputs", "seconds", "outputs"})
    ASSERT_TRUE(j.contains(k)) << "missing key " << k;
  EXPECT_TRUE(j["surftex_version"].is_string() && !j["surftex_version"].get<std::string>().empty());
  EXPECT_EQ(j["command"], command);
  ASSERT_TRUE(j["command_line"].is_array());
  ASSERT_GE(j["command_line"].size(), 2u);
  for (const auto& a : j["command_line"]) EXPECT_TRUE(a.is_string());
  EXPECT_EQ(std::filesystem::path(j["command_line"][0].get<std::string>()).filename(), "surftex");
  EXPECT_TRUE(j["seed"].is_number_unsigned());
  EXPECT_TRUE(j["threads"].is_number_integer());
  ASSERT_TRUE(j["inputs"].is_array());
  std::vector<std::string> paths;
  for (const auto& in : j["inputs"]) {
    ASSERT_TRUE(in.contains("path") && in.contains("bytes") && in.contains("sha256")) << in.dump();
    const std::string p = in["path"];
    paths.push_back(p);
    EXPECT_EQ(in["bytes"].get<std::uintmax_t>(), std::filesystem::file_size(p)) << p;
    EXPECT_EQ(in["sha256"].get<std::string>(), sha256sum(p)) << p;
  }
  for (const std::string& p : inputs)
    EXPECT_NE(std::find(paths.begin(), paths.end(), p), paths.end()) << "input not listed: " << p;
  ASSERT_TRUE(j["seconds"].is_object());
  ASSERT_TRUE(j["seconds"].contains("total"));
  const double total = j["seconds"]["total"].get<double>();
  EXPECT_GE(total, 0.0);
  for (const auto& [stage, s] : j["seconds"].items()) {
    ASSERT_TRUE(s.is_number()) << "seconds." << stage;
    EXPECT_LE(s.get<double>(), total + 1e-3) << "seconds." << stage;
  }
  ASSERT_TRUE(j["outputs"].is_array());
  std::vector<std::string> outs;
  for (const auto& o : j["outputs"]) {
    ASSERT_TRUE(o.is_string());
    outs.push_back(o);
    EXPECT_TRUE(std::filesystem::is_regular_file(o.get<std::string>())) << o;
  }
  for (const std::string& p : outputs)
    EXPECT_NE(std::find(outs.begin(), outs.end(), p), outs.end()) << "output not listed: " << p;
}

}  // namespace surftex::test
