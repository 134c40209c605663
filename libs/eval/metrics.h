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
