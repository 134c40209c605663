// Constructed trajectories for the evaluation tests.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <functional>

#include "eval/pose_series.h"

namespace jvl::eval::testing {

inline Eigen::Matrix4d Pose(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = r;
  m.block<3, 1>(0, 3) = t;
  return m;
}

// Rotation about the camera's y axis (KITTI cam0: y points down, so this is a yaw).
inline Eigen::Matrix3d Yaw(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

// Frames first..first+n-1 with pose(frame) and timestamps 0.1 * frame.
inline PoseSeries MakeSeries(int64_t first, int n,
                             const std::function<Eigen::Matrix4d(int64_t)>& pose) {
  PoseSeries s;
  for (int64_t f = first; f < first + n; ++f) {
    s.frames.push_back(f);
    s.poses.push_back(pose(f));
    s.timestamps.push_back(0.1 * static_cast<double>(f));
  }
  return s;
}

// Straight drive along +z at 1 m per frame.
inline PoseSeries StraightLine(int n) {
  return MakeSeries(0, n, [](int64_t f) {
    return Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, static_cast<double>(f)));
  });
}

// A planar curve (constant yaw rate) at 1 m per frame: a bit more general than a line.
inline PoseSeries Curve(int n, double yaw_rate) {
  PoseSeries s;
  Eigen::Matrix4d pose = Eigen::Matrix4d::Identity();
  const Eigen::Matrix4d step = Pose(Yaw(yaw_rate), Eigen::Vector3d(0, 0, 1));
  for (int f = 0; f < n; ++f) {
    s.frames.push_back(f);
    s.poses.push_back(pose);
    s.timestamps.push_back(0.1 * f);
    pose = pose * step;
  }
  return s;
}

inline PoseSeries Erase(PoseSeries s, int64_t frame) {
  const auto row = *s.IndexOf(frame);
  s.frames.erase(s.frames.begin() + row);
  s.poses.erase(s.poses.begin() + row);
  s.timestamps.erase(s.timestamps.begin() + row);
  return s;
}

}  // namespace jvl::eval::testing
