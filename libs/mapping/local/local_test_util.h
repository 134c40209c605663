// Test-only keyframe APE: RMSE of positions after the SE(3) Umeyama (1991) alignment (no scale).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "eval/align.h"
#include "geometry/rigid3.h"

namespace jvl::mapping::testing {

inline double KeyframeApe(const std::vector<Rigid3d>& est, const std::vector<Rigid3d>& gt) {
  std::vector<Eigen::Vector3d> pe, pg;
  for (size_t i = 0; i < est.size(); ++i) {
    pe.push_back(est[i].translation());
    pg.push_back(gt[i].translation());
  }
  const eval::Similarity a = eval::Umeyama(pe, pg, /*with_scale=*/false);
  double sum = 0;
  for (size_t i = 0; i < pe.size(); ++i) {
    sum += (a.rotation * pe[i] + a.translation - pg[i]).squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(pe.size()));
}

}  // namespace jvl::mapping::testing
