// SPDX-License-Identifier: AGPL-3.0-or-later
// Linked into every benchmark: the allocator settings of the surftex command
// (apps/main.cpp), so that a benchmark's figures are the command's. Set during
// static initialisation, before main and before any thread starts.
#include "geometry/allocator_settings.h"

namespace {
const bool kAllocatorSet = surftex::keep_freed_memory_for_reuse();
}  // namespace
