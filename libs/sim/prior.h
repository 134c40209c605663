// Prior trajectories from ground truth: a drifting odometry as the paper's inputs (a poor LiDAR
// odometry, "LiDAR odometry N=1", or an ORB-SLAM2-like visual odometry). The relative motions of
// the ground truth are corrupted and re-integrated, so errors accumulate like real drift:
// a yaw-rate bias doing a random walk, slow pitch/roll drift, a scale drift, white rotation noise
// per metre, and a non-accumulating per-frame jitter.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "geometry/trajectory.h"

namespace jvl::sim {

struct PriorOptions {
  uint64_t seed = 1;
  // Accumulating rotation errors (degrees; "per sqrt(m)" = random-walk density over distance).
  double yaw_bias_deg_per_100m = 0.0;  // Constant part of the yaw drift.
  double yaw_bias_walk = 0.0;          // deg/100m per sqrt(100 m): walk of the yaw-rate bias.
  double yaw_noise_deg = 0.0;          // deg per sqrt(100 m): white yaw noise.
  double pitch_roll_walk = 0.0;        // deg/100m per sqrt(100 m), pitch and roll biases.
  double pitch_roll_noise_deg = 0.0;   // deg per sqrt(100 m).
  // Scale: length factor 1 + bias + walk.
  double scale_bias = 0.0;  // Relative (0.01 = 1 %).
  double scale_walk = 0.0;  // Relative per sqrt(100 m).
  // Per-frame jitter that does not accumulate.
  double jitter_translation_m = 0.0;
  double jitter_rotation_deg = 0.0;
  void Check() const;
};

// Presets: "lidar-n1" (poor LiDAR odometry, several metres APE per km), "orbslam2" (stereo
// ORB-SLAM2-like VO, about 1 m per km), "good" (sub-metre drift), "none" (a copy).
PriorOptions PriorPreset(const std::string& name, uint64_t seed);
std::vector<std::string> PriorPresetNames();

Trajectory MakePrior(const Trajectory& ground_truth, const PriorOptions& options);

struct PriorStats {
  double length_m = 0;
  double ape_rmse_m = 0;  // Translation error, no alignment (both start at the same pose).
  double ape_max_m = 0;
  double final_yaw_error_deg = 0;
  double final_rotation_error_deg = 0;
};
PriorStats ComparePrior(const Trajectory& ground_truth, const Trajectory& prior);

}  // namespace jvl::sim
