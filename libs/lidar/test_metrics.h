// Test-only trajectory metrics: SE(3) Umeyama alignment of positions (eval::Umeyama), APE (RMSE of aligned
// positions) and end-point drift as a fraction of the distance travelled.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "eval/align.h"

namespace jvl::lidar::testing {

struct TrajectoryErrors {
  double ape_rmse = 0;   // m, after SE(3) alignment of all positions.
  double end_drift = 0;  // m, |end error| with both trajectories anchored at the first frame.
  double distance = 0;   // m, ground-truth path length.
  double drift_fraction() const { return distance > 0 ? end_drift / distance : 0; }
};

// est and gt: world_from_cam poses of the same frames (4x4).
inline TrajectoryErrors ComputeErrors(const std::vector<Eigen::Matrix4d>& est,
                                      const std::vector<Eigen::Matrix4d>& gt) {
  TrajectoryErrors e;
  std::vector<Eigen::Vector3d> pe, pg;
  for (size_t i = 0; i < est.size(); ++i) {
    pe.push_back(est[i].block<3, 1>(0, 3));
    pg.push_back(gt[i].block<3, 1>(0, 3));
    if (i > 0) e.distance += (pg[i] - pg[i - 1]).norm();
  }
  const eval::Similarity a = eval::Umeyama(pe, pg, /*with_scale=*/false);
  double sum = 0;
  for (size_t i = 0; i < pe.size(); ++i) {
    sum += (a.rotation * pe[i] + a.translation - pg[i]).squaredNorm();
  }
  e.ape_rmse = std::sqrt(sum / static_cast<double>(pe.size()));
  // End-point drift: relative pose of the last frame w.r.t. the first one.
  const Eigen::Matrix4d rel_e = est.front().inverse() * est.back();
  const Eigen::Matrix4d rel_g = gt.front().inverse() * gt.back();
  e.end_drift = (rel_e.block<3, 1>(0, 3) - rel_g.block<3, 1>(0, 3)).norm();
  return e;
}

}  // namespace jvl::lidar::testing
