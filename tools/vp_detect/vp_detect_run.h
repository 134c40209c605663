// The body of vp_detect, callable without a command line: VPs for every selected frame of a
// dataset, in parallel over frames, in frame order.
#pragma once

#include <string>
#include <vector>

#include "io/dataset.h"
#include "io/vps_io.h"
#include "vision/vanishing_points.h"

namespace jvl {

struct VpDetectRunOptions {
  VpDetectOptions detect;
  int camera = 0;  // Left greyscale camera (the paper uses the left image).
  int threads = 1;
  std::string debug_dir;  // Non-empty: write <debug_dir>/<frame 06d>.png overlays.
  bool progress = true;
};

struct VpDetectRunResult {
  io::VpsData data;
  std::vector<double> detect_ms;  // Per frame: segments + VPs (image loading excluded).
  int frames_with_vps = 0;
  int frames_with_forward = 0;
};

VpDetectRunResult RunVpDetect(const io::Dataset& dataset, const VpDetectRunOptions& options);

// The stored rows of one frame's result.
std::vector<io::VpRecord> ToRecords(int64_t frame, const VpResult& result);

}  // namespace jvl
