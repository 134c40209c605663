// A trajectory: one world_from_cam0 pose per frame, identified by dataset frame index.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "geometry/rigid3.h"

namespace jvl {

struct Trajectory {
  std::vector<int64_t> frames;         // Dataset frame indices, strictly increasing.
  std::vector<Rigid3d> world_from_cam;  // Same length as frames.
  std::vector<double> timestamps;      // Seconds; empty or same length as frames.

  size_t size() const { return frames.size(); }
  bool empty() const { return frames.empty(); }
  bool has_timestamps() const { return !timestamps.empty(); }
  // Index of `frame` in `frames`, or nullopt.
  std::optional<size_t> IndexOf(int64_t frame) const;
  // Throws jvl::Error naming `what` if sizes disagree, frames are not increasing or a pose
  // is not finite.
  void Check(const char* what) const;
  void Append(int64_t frame, const Rigid3d& pose, std::optional<double> timestamp = {});
};

// Path length (m) from the first pose to every pose: the sum of the distances between
// consecutive positions.
std::vector<double> PathLengths(const Trajectory& trajectory);

}  // namespace jvl
