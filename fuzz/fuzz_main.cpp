// SPDX-License-Identifier: AGPL-3.0-or-later
// libFuzzer entry point of one target: compiled once per target with
// -DSURFTEX_FUZZ_BODY=one_NAME (fuzz/CMakeLists.txt).
#include <cstddef>
#include <cstdint>

#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return surftex::fuzz::SURFTEX_FUZZ_BODY(data, size);
}
