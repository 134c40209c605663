// Poses as the evaluation sees them: general 4x4 matrices exactly as read from the file.
//
// The KITTI devkit (and tools that reproduce it, such as kitti-odom-eval) multiply and invert the
// 3x4 matrices of the text files as they are, without projecting the rotation block onto SO(3).
// Text files carry rotation blocks that are orthonormal only to ~1e-7, and the rotation error of
// a short segment (arccos of the trace) is sensitive to that at the 1e-5 level, so the evaluation
// keeps the raw matrices and inverts them as general matrices to agree with the devkit digits.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/trajectory.h"

namespace jvl::eval {

struct PoseSeries {
  std::vector<int64_t> frames;         // Dataset frame indices, strictly increasing.
  std::vector<Eigen::Matrix4d> poses;  // world_from_cam, last row (0 0 0 1).
  std::vector<double> timestamps;      // Seconds; empty or same length as frames.

  size_t size() const { return frames.size(); }
  bool empty() const { return frames.empty(); }
  bool has_timestamps() const { return !timestamps.empty(); }
  // Row of `frame`, or nullopt (binary search).
  std::optional<size_t> IndexOf(int64_t frame) const;
  // Throws naming `what` if sizes disagree, frames do not increase or a pose is not finite.
  void Check(const std::string& what) const;
};

// Exact conversion of a quaternion trajectory (HDF5 artifacts, TUM text).
PoseSeries ToPoseSeries(const Trajectory& trajectory);

// Poses of the LiDAR (world_velo_from_velo) expressed for cam0: T_cam = Tr * T_velo * Tr^-1 with
// Tr = cam0_from_velo (KITTI calib "Tr", which maps velodyne points into cam0).
PoseSeries LidarToCamera(const PoseSeries& lidar_poses, const Eigen::Matrix4d& cam0_from_velo);

// Rotation angle (rad) of the rotation block of m as the KITTI devkit computes it:
// acos(clamp((trace - 1) / 2, -1, 1)).
double DevkitRotationAngle(const Eigen::Matrix4d& m);
// Norm of the translation column.
double TranslationNorm(const Eigen::Matrix4d& m);

}  // namespace jvl::eval
