// Heap housekeeping for tools that build and free very large structures in phases.
#pragma once

namespace jvl {

// Returns the free pages of the heap to the operating system (glibc malloc_trim; a no-op with
// other C libraries). After a phase frees millions of small allocations, glibc keeps their pages
// resident, and a later phase whose allocations do not fit the holes exactly grows the resident
// set beyond the earlier peak; trimming between phases keeps the peak at that of one phase.
void ReleaseFreeHeapMemory();

}  // namespace jvl
