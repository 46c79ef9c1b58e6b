// SPDX-License-Identifier: AGPL-3.0-or-later
// Process-wide settings of the C allocator (glibc malloc) for long runs.
#pragma once

#include <cstddef>

namespace surftex {

/// Memory the allocator holds after a free is kept for the next allocation
/// instead of being given back to the system at once: glibc gives large
/// blocks their own mappings and returns a heap's free top above its trim
/// threshold, so a stage that frees and reallocates its buffers (subdivision
/// levels, per-job vectors, atlas images) pays a page fault and a zeroed page
/// per 4 KB again. Returns false when the allocator refused a setting (or is
/// not glibc's). Call once, before threads start.
bool keep_freed_memory_for_reuse();

/// The process's minor page faults so far (getrusage; 0 where not available).
std::size_t minor_page_faults();

}  // namespace surftex
