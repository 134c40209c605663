// Writes a simulated world to disk in a dataset layout (KITTI odometry or KITTI-360) plus the
// sim/ ground truth,
// frame-parallel. Only io/ functions touch files; this glues sim/ and io/ for the tool and tests.
#pragma once

#include <functional>
#include <string>

#include "io/artifact.h"
#include "io/sim_io.h"
#include "sim/sequence.h"

namespace jvl::sim {

struct WriteStats {
  int64_t frames = 0;
  int64_t points = 0;
  double frame_seconds = 0;  // Wall time of the frame loop.
};

// `provenance` is asked for after the frames are written (wall time); `tick` is called once per
// finished frame (progress display), from worker threads.
WriteStats WriteSequence(const World& world, const io::SequenceLayout& layout, int threads,
                         const std::function<io::Provenance()>& provenance,
                         const std::function<void()>& tick = {});

}  // namespace jvl::sim
