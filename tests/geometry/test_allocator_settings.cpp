// SPDX-License-Identifier: AGPL-3.0-or-later
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <vector>

#include "geometry/allocator_settings.h"

namespace surftex {
namespace {

volatile unsigned sink = 0;

// Minor page faults of allocating `n` blocks of `size` bytes, touching every
// byte, then freeing them all.
std::size_t faults_of_allocating(std::size_t n, std::size_t size) {
  const std::size_t before = minor_page_faults();
  std::vector<char*> blocks(n);
  for (char*& b : blocks) {
    b = static_cast<char*>(std::malloc(size));
    std::memset(b, 1, size);
  }
  unsigned sum = 0;  // read back, so that the writes cannot be optimised away
  for (char* b : blocks)
    for (std::size_t i = 0; i < size; i += 4096) sum += static_cast<unsigned char>(b[i]);
  for (char* b : blocks) std::free(b);
  sink = sum;
  return minor_page_faults() - before;
}

// 192 MB in 64 KB blocks, twice, then in 1 MB blocks: the later rounds reuse
// the first's pages. Without the setting glibc returns the freed heap top
// beyond its adaptive trim threshold (at most 64 MB), so the second round
// faults at least two thirds of its pages again, and blocks above its adaptive
// mapping threshold (128 KB until a larger block was freed) get fresh mappings.
TEST(AllocatorSettings, FreedMemoryIsReusedWithoutPageFaults) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer replaces the allocator (mallopt is not glibc's)";
#endif
  ASSERT_TRUE(keep_freed_memory_for_reuse());
  const std::size_t total = std::size_t(192) << 20, pages = total / 4096, small = 64 << 10, large = 1 << 20;
  const std::size_t first = faults_of_allocating(total / small, small);
  const std::size_t second = faults_of_allocating(total / small, small);
  const std::size_t third = faults_of_allocating(total / large, large);
  EXPECT_GT(first, pages / 4) << "page faults are not counted";
  EXPECT_LT(second, pages / 50) << first << " faults, then " << second;
  EXPECT_LT(third, pages / 50) << "1 MB blocks: " << third << " faults";
}

}  // namespace
}  // namespace surftex
