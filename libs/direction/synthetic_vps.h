// Test support (not part of jvl::direction): driving paths made of straight segments and turns,
// priors with yaw drift, and vanishing-point observations projected from the true road
// direction with noise, building-axis VPs and outliers.
#pragma once

#include <cstdint>
#include <vector>

#include "direction/direction_cluster.h"

namespace jvl::direction::testing {

// A straight segment (turn_deg == 0) or a circular arc turning left (> 0) or right (< 0).
struct PathSegment {
  double length_m = 100;
  double turn_deg = 0;
};

struct SyntheticPath {
  Trajectory truth;                           // KITTI convention: y down, ground x-z, 1 pose/step.
  std::vector<int> segment;                   // Segment of every pose.
  std::vector<Eigen::Vector3d> road;          // True unit road (tangent) direction per pose.
  std::vector<Eigen::Vector3d> segment_road;  // Road direction of every straight segment (else 0).
};

SyntheticPath MakePath(const std::vector<PathSegment>& segments, double step_m = 1.0,
                       double start_heading_deg = 0.0);

struct SyntheticVpOptions {
  double noise_deg = 0.3;           // Angular noise of every VP direction.
  double forward_rate = 0.9;        // Probability of a forward (road) VP on a straight segment.
  double curve_forward_rate = 0.5;  // ... on an arc (where the "road VP" follows the tangent).
  double curve_noise_deg = 3.0;     // Extra scatter of forward VPs on arcs.
  double building_rate = 0.6;       // Horizontal facade axis perpendicular to the road.
  double vertical_rate = 0.4;       // Vertical building edges.
  double outlier_rate = 0.15;       // A random direction in front of the camera.
  uint32_t seed = 7;
};

PinholeCamera KittiCamera();  // KITTI 04 P0 intrinsics, 1226 x 370.

// VPs (<= 3 per frame) seen by the true cameras.
std::vector<VpObservation> SimulateVps(const SyntheticPath& path, const PinholeCamera& camera,
                                       const SyntheticVpOptions& options);
// Same for any trajectory, the true road direction being the GT forward motion direction.
std::vector<VpObservation> SimulateVpsFromMotion(const Trajectory& truth,
                                                 const PinholeCamera& camera,
                                                 const SyntheticVpOptions& options);

// Prior with a yaw random walk about world -y (sigma per pose in deg); translations are
// re-integrated with the drifted heading. Returns the yaw error (rad) per pose in *yaw.
Trajectory DriftPrior(const Trajectory& truth, double sigma_deg_per_pose, uint32_t seed,
                      std::vector<double>* yaw);

}  // namespace jvl::direction::testing
