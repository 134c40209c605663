#include "geometry/trajectory.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace jvl {

std::optional<size_t> Trajectory::IndexOf(int64_t frame) const {
  const auto it = std::lower_bound(frames.begin(), frames.end(), frame);
  if (it == frames.end() || *it != frame) return std::nullopt;
  return static_cast<size_t>(it - frames.begin());
}

void Trajectory::Check(const char* what) const {
  JVL_CHECK(frames.size() == world_from_cam.size(),
            what << ": " << frames.size() << " frame ids but " << world_from_cam.size()
                 << " poses");
  JVL_CHECK(timestamps.empty() || timestamps.size() == frames.size(),
            what << ": " << timestamps.size() << " timestamps for " << frames.size() << " poses");
  for (size_t i = 0; i < frames.size(); ++i) {
    JVL_CHECK(i == 0 || frames[i] > frames[i - 1],
              what << ": frame ids must increase, got " << frames[i - 1] << " then " << frames[i]);
    const auto a = world_from_cam[i].ToArray();
    for (double v : a) {
      JVL_CHECK(std::isfinite(v), what << ": pose of frame " << frames[i] << " is not finite");
    }
  }
}

void Trajectory::Append(int64_t frame, const Rigid3d& pose, std::optional<double> timestamp) {
  frames.push_back(frame);
  world_from_cam.push_back(pose);
  if (timestamp) timestamps.push_back(*timestamp);
}

std::vector<double> PathLengths(const Trajectory& t) {
  std::vector<double> s(t.size(), 0.0);
  for (size_t i = 1; i < t.size(); ++i)
    s[i] = s[i - 1] +
           (t.world_from_cam[i].translation() - t.world_from_cam[i - 1].translation()).norm();
  return s;
}

}  // namespace jvl
