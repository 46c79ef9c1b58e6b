// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The bodies of the libFuzzer targets (issue 21 item 6), one per hostile
// input family surftex reads. Each takes one input, runs the reader on it and
// returns 0; a surftex::Error is the expected outcome of a bad input, any
// other exception, a crash, a sanitizer report, a hang or an allocation
// over the fuzzer's limit is a finding. The same bodies run in the test
// suite over every saved crasher (fuzz/regressions/TARGET/*) and over the
// seed inputs, so a fixed crash stays fixed (tests/apps/test_fuzz_regressions.cpp).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace surftex::fuzz {

using Body = int (*)(const std::uint8_t* data, std::size_t size);

struct Target {
  const char* name;  ///< fuzz_obj, ... (binary fuzz/build/NAME, regressions in fuzz/regressions/NAME)
  Body body;
};

/// Every target, in a fixed order.
const std::vector<Target>& targets();

int one_obj(const std::uint8_t* data, std::size_t size);
int one_off(const std::uint8_t* data, std::size_t size);
int one_glb(const std::uint8_t* data, std::size_t size);
int one_ply(const std::uint8_t* data, std::size_t size);
int one_stl(const std::uint8_t* data, std::size_t size);
int one_image_header(const std::uint8_t* data, std::size_t size);
int one_constraints(const std::uint8_t* data, std::size_t size);
int one_tile_json(const std::uint8_t* data, std::size_t size);

}  // namespace surftex::fuzz
