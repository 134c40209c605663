// Thread count resolution and a deterministic parallel loop.
#pragma once

#include <cstdint>
#include <functional>

namespace jvl {

// 0 means "all hardware threads"; negative values are rejected.
int ResolveThreadCount(int requested);

// Calls fn(i) for i in [0, n) on `threads` threads. Work is handed out in index order; the
// result must not depend on the schedule (write results into slot i). The first exception
// thrown by fn is rethrown after all threads have stopped.
void ParallelFor(int64_t n, int threads, const std::function<void(int64_t)>& fn);

}  // namespace jvl
