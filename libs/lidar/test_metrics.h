// Test-only trajectory metrics: SE(3) Umeyama alignment of positions, APE (RMSE of aligned
// positions) and end-point drift as a fraction of the distance travelled.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>
#include <vector>

namespace jvl::lidar::testing {

struct TrajectoryErrors {
  double ape_rmse = 0;   // m, after SE(3) alignment of all positions.
  double end_drift = 0;  // m, |end error| with both trajectories anchored at the first frame.
  double distance = 0;   // m, ground-truth path length.
  double drift_fraction() const { return distance > 0 ? end_drift / distance : 0; }
};

// Umeyama (1991) without scale: R, t minimising sum |gt_i - (R est_i + t)|^2.
inline void AlignSE3(const std::vector<Eigen::Vector3d>& est,
                     const std::vector<Eigen::Vector3d>& gt, Eigen::Matrix3d* r,
                     Eigen::Vector3d* t) {
  Eigen::Vector3d me = Eigen::Vector3d::Zero(), mg = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < est.size(); ++i) {
    me += est[i];
    mg += gt[i];
  }
  me /= static_cast<double>(est.size());
  mg /= static_cast<double>(est.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < est.size(); ++i) cov += (gt[i] - mg) * (est[i] - me).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) s(2, 2) = -1;
  *r = svd.matrixU() * s * svd.matrixV().transpose();
  *t = mg - *r * me;
}

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
  Eigen::Matrix3d r;
  Eigen::Vector3d t;
  AlignSE3(pe, pg, &r, &t);
  double sum = 0;
  for (size_t i = 0; i < pe.size(); ++i) sum += (r * pe[i] + t - pg[i]).squaredNorm();
  e.ape_rmse = std::sqrt(sum / static_cast<double>(pe.size()));
  // End-point drift: relative pose of the last frame w.r.t. the first one.
  const Eigen::Matrix4d rel_e = est.front().inverse() * est.back();
  const Eigen::Matrix4d rel_g = gt.front().inverse() * gt.back();
  e.end_drift = (rel_e.block<3, 1>(0, 3) - rel_g.block<3, 1>(0, 3)).norm();
  return e;
}

}  // namespace jvl::lidar::testing
