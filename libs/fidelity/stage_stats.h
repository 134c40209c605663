// What the stages see, computed the same way on real and simulated sequences: the stage side of
// the simulator's fidelity table (docs/sim.md, `sensor_stats --odometry/--vps/--visual`). Each
// statistic compares a stage's artifact with the sequence's ground-truth poses (or, for the
// visual map, with itself), so that a simulated drive can be held against a real one stage by
// stage.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "geometry/trajectory.h"
#include "io/visual_io.h"
#include "io/vps_io.h"

namespace jvl::fidelity {

struct StageStatsOptions {
  double drift_length_m = 50;  // Path length of the odometry's drift windows (m).
  double min_step_m = 0.1;     // Frame steps shorter than this get no relative RPE (%).
  double vp_lookahead_m = 20;  // The direction of travel: towards the position this far ahead.
  // The forward VP's error only where the road ahead is straight: the ground truth turns by at
  // most this much over the lookahead (deg). On a bend the lines ahead are not along the
  // direction of travel, and a straight real excerpt has no bends to compare with.
  double vp_max_turn_deg = 2;
  void Check() const;
};

// Per-frame values of every stage statistic, NaN where a frame has none. `frames` is the
// ground truth's frame list; the values are in its order.
struct StageSeries {
  std::vector<int64_t> frames;
  // lidar_odom (any trajectory): at frame k+1 the translation norm of
  // (G_k^-1 G_k+1)^-1 (E_k^-1 E_k+1) (m) and that divided by the true step (%); at frame k the
  // same error over the first frame j whose path length from k reaches drift_length_m, divided
  // by that path length (%).
  std::vector<double> odom_rpe_m, odom_rpe_percent, odom_drift_percent;
  // At frame k+1, the direction of the estimate's step from k against the truth's, in frame
  // k's camera (x right, y down, z forward): the difference of their angles atan2(x, z) (yaw,
  // right positive) and atan2(y, hypot(x, z)) (pitch, down positive), deg. Their median over a
  // drive is a rotation between the frame the estimate's motion is expressed in and the ground
  // truth's (a camera-LiDAR calibration error, or the ground truth's own); NaN for steps
  // shorter than min_step_m.
  std::vector<double> odom_direction_yaw_deg, odom_direction_pitch_deg;
  // vp_detect: 1 where the frame has a forward VP, 0 where it has none (NaN where vp_detect did
  // not run); the angle between the forward VP's direction and the direction of travel (the
  // ground truth's position vp_lookahead_m further along the path, in the frame's camera), NaN
  // without a forward VP, without that much path ahead, or where the ground truth turns by more
  // than vp_max_turn_deg over it.
  std::vector<double> vp_forward_found, vp_forward_error_deg;
  // visual_assoc, at its keyframes: observations (map points seen), the share of the keyframe's
  // keypoints that observe a map point, and the median reprojection error of its observations
  // at the artifact's poses (px).
  std::vector<double> visual_points, visual_tracked_fraction, visual_reprojection_px;
};

// Starts a series over the frames of `ground_truth` (every value NaN).
StageSeries MakeStageSeries(const Trajectory& ground_truth);

// Fill their part of `series`. The estimate and the VPs only count at frames of the ground
// truth; a frame missing from the estimate gives NaN.
void AddOdometryStats(const Trajectory& ground_truth, const Trajectory& estimate,
                      const StageStatsOptions& options, StageSeries* series);
void AddVpStats(const Trajectory& ground_truth, const io::VpsData& vps,
                const StageStatsOptions& options, StageSeries* series);
void AddVisualStats(const io::VisualMapData& visual, StageSeries* series);

// The "stages" part of a sensor_stats artifact (schemas/sensor_stats.schema.json): per statistic
// its mean, median, 10 % and 90 % quantile over the frames where it is finite (null if none) and
// the per-frame values; statistics of a stage that was not given are left out.
nlohmann::json SummariseStages(const StageSeries& series, bool odometry, bool vps, bool visual);

}  // namespace jvl::fidelity
