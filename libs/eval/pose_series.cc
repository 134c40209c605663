#include "eval/pose_series.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace jvl::eval {

std::optional<size_t> PoseSeries::IndexOf(int64_t frame) const {
  const auto it = std::lower_bound(frames.begin(), frames.end(), frame);
  if (it == frames.end() || *it != frame) return std::nullopt;
  return static_cast<size_t>(it - frames.begin());
}

void PoseSeries::Check(const std::string& what) const {
  JVL_CHECK(poses.size() == frames.size(),
            what << ": " << frames.size() << " frames but " << poses.size() << " poses");
  JVL_CHECK(timestamps.empty() || timestamps.size() == frames.size(),
            what << ": " << timestamps.size() << " timestamps for " << frames.size() << " frames");
  for (size_t i = 0; i < frames.size(); ++i) {
    JVL_CHECK(i == 0 || frames[i] > frames[i - 1], what << ": frame " << frames[i]
                                                        << " does not increase (after "
                                                        << frames[i - 1] << ")");
    JVL_CHECK(poses[i].allFinite(), what << ": pose of frame " << frames[i] << " is not finite");
  }
}

PoseSeries ToPoseSeries(const Trajectory& trajectory) {
  PoseSeries s;
  s.frames = trajectory.frames;
  s.timestamps = trajectory.timestamps;
  s.poses.reserve(trajectory.size());
  for (const Rigid3d& pose : trajectory.world_from_cam) s.poses.push_back(pose.Matrix4());
  return s;
}

PoseSeries LidarToCamera(const PoseSeries& lidar_poses, const Eigen::Matrix4d& cam0_from_velo) {
  PoseSeries s = lidar_poses;
  const Eigen::Matrix4d velo_from_cam0 = cam0_from_velo.inverse();
  for (Eigen::Matrix4d& pose : s.poses) pose = cam0_from_velo * pose * velo_from_cam0;
  return s;
}

double DevkitRotationAngle(const Eigen::Matrix4d& m) {
  // KITTI devkit rotationError(): d = 0.5 * (a + b + c - 1), acos(max(min(d, 1), -1)).
  const double d = 0.5 * (m(0, 0) + m(1, 1) + m(2, 2) - 1.0);
  return std::acos(std::max(std::min(d, 1.0), -1.0));
}

double TranslationNorm(const Eigen::Matrix4d& m) {
  const double dx = m(0, 3), dy = m(1, 3), dz = m(2, 3);
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

}  // namespace jvl::eval
