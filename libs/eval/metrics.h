// Absolute and relative pose errors over a ground truth paired with an aligned estimate.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace jvl::eval {

// Every ground-truth pose, with the aligned estimate at the rows that have one.
struct PairedPoses {
  std::vector<int64_t> frames;       // Ground-truth frame indices.
  std::vector<Eigen::Matrix4d> gt;   // world_from_cam, all ground-truth rows.
  std::vector<Eigen::Matrix4d> est;  // Same length; valid where has_est.
  std::vector<uint8_t> has_est;
  size_t size() const { return frames.size(); }
};

struct ErrorStats {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;  // std: population (1/N).
  int64_t count = 0;
};
// Values summed in their given order (deterministic); median of an even count is the mean of
// the two middle values. All zero for no values.
ErrorStats ComputeStats(const std::vector<double>& values);

// Path length from row 0 to each row along the positions (KITTI devkit trajectoryDistances).
std::vector<double> TrajectoryDistances(const std::vector<Eigen::Matrix4d>& poses);

struct ApeResult {
  std::vector<int64_t> frames;        // Matched frames.
  std::vector<double> translation_m;  // |t_gt - t_est| per matched frame.
  std::vector<double> rotation_deg;   // Angle of R(gt^-1 est) per matched frame.
  ErrorStats translation_stats, rotation_stats;
};
ApeResult ComputeApe(const PairedPoses& paired);

// The APE split along the ground-truth path and about the camera axes, signed, per matched
// frame. Position error est - gt in the path frame: vertical along `up`, along = direction of
// travel (ground truth, over >= 1 m ahead and behind; the camera's z axis when standing) on the
// plane normal to `up`, lateral = up x along (left of the direction of travel). Rotation error:
// the rotation vector of R_gt^T R_est, i.e. about the ground-truth camera's x, y, z axes (pitch,
// yaw, roll for a KITTI camera: x right, y down, z forward). Frames whose direction of travel is
// along `up` are left out (`skipped`). The stats are of the signed values: rmse is the RMS.
struct ApeComponentStats {
  ErrorStats along, lateral, vertical, pitch, yaw, roll;
};
struct ApeComponents : ApeComponentStats {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  std::vector<int64_t> frames;
  std::vector<double> along_m, lateral_m, vertical_m, pitch_deg, yaw_deg, roll_deg;
  int64_t skipped = 0;
};
// `up` in the frame of the paired poses; zero: minus the y axis of the first ground-truth
// camera (KITTI: world -y is up when the first pose is the identity).
ApeComponents ComputeApeComponents(const PairedPoses& paired,
                                   const Eigen::Vector3d& up = Eigen::Vector3d::Zero());
// Statistics of the per-frame components of several results together (in the given order).
ApeComponentStats PoolApeComponents(const std::vector<const ApeComponents*>& parts);

enum class RpeUnit { kFrames, kMetres };
RpeUnit ParseRpeUnit(const std::string& name);  // frames|m
std::string ToString(RpeUnit unit);

struct RpeOptions {
  double delta = 1;  // Frames (a positive integer) or metres (> 0).
  RpeUnit unit = RpeUnit::kFrames;
  void Check() const;
};

struct RpeResult {
  std::vector<int64_t> first_frame, last_frame;
  std::vector<double> translation_m;        // |t| of (gt_i^-1 gt_j)^-1 (est_i^-1 est_j).
  std::vector<double> translation_percent;  // translation_m / ground-truth path length * 100.
  std::vector<double> rotation_deg;
  ErrorStats translation_stats, percent_stats, rotation_stats;
};
// Pairs start at every matched frame i; the end j is frame i + delta (frames) or the first
// ground-truth row whose path distance from i exceeds delta (metres); j must be matched too.
RpeResult ComputeRpe(const PairedPoses& paired, const std::vector<double>& gt_distances,
                     const RpeOptions& options);

// Statistics of per-item errors pooled from several results (in the given order).
ErrorStats PoolStats(const std::vector<const std::vector<double>*>& parts);

}  // namespace jvl::eval
