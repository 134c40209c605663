// Test-only keyframe APE: RMSE of positions after the SE(3) Umeyama (1991) alignment (no scale).
#pragma once

#include <Eigen/Core>
#include <Eigen/SVD>
#include <cmath>
#include <vector>

#include "geometry/rigid3.h"

namespace jvl::mapping::testing {

inline double KeyframeApe(const std::vector<Rigid3d>& est, const std::vector<Rigid3d>& gt) {
  const size_t n = est.size();
  Eigen::Vector3d me = Eigen::Vector3d::Zero(), mg = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    me += est[i].translation();
    mg += gt[i].translation();
  }
  me /= static_cast<double>(n);
  mg /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    cov += (gt[i].translation() - mg) * (est[i].translation() - me).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) s(2, 2) = -1;
  const Eigen::Matrix3d r = svd.matrixU() * s * svd.matrixV().transpose();
  const Eigen::Vector3d t = mg - r * me;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    sum += (r * est[i].translation() + t - gt[i].translation()).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(n));
}

}  // namespace jvl::mapping::testing
