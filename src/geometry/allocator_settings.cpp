// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/allocator_settings.h"

#include <sys/resource.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace surftex {

bool keep_freed_memory_for_reuse() {
#if defined(__GLIBC__)
  // Blocks up to 1 GiB come from the heaps, not from their own mappings (a
  // thread's heap holds at most 64 MB: larger blocks of worker threads are
  // still mapped); freed memory at a heap's top stays up to 1 GiB; a heap grows
  // in steps of 16 MB. glibc's own thresholds start at 128 KB and adapt only
  // after a large block was freed; setting any of them stops the adaptation,
  // so all three are set. Measured: decision 204, session 21.
  const bool mapped = mallopt(M_MMAP_THRESHOLD, 1 << 30) == 1;
  const bool trim = mallopt(M_TRIM_THRESHOLD, 1 << 30) == 1;
  const bool pad = mallopt(M_TOP_PAD, 16 << 20) == 1;
  return mapped && trim && pad;
#else
  return false;
#endif
}

std::size_t minor_page_faults() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return static_cast<std::size_t>(u.ru_minflt);
}

}  // namespace surftex
