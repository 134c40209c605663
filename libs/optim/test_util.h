// Helpers shared by the optim tests (not part of the library).
#pragma once

#include <ceres/gradient_checker.h>

#include <algorithm>
#include <map>
#include <random>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "optim/pose_block.h"

namespace jvl::optim::testing {

inline PinholeCamera KittiLikeCamera() {
  PinholeCamera camera;
  camera.fx = 718.856;
  camera.fy = 718.856;
  camera.cx = 607.1928;
  camera.cy = 185.2157;
  camera.width = 1241;
  camera.height = 376;
  return camera;
}

inline Rigid3d RandomPose(std::mt19937& rng, double angle, double translation) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d omega(u(rng) * angle, u(rng) * angle, u(rng) * angle);
  const Eigen::Vector3d t(u(rng) * translation, u(rng) * translation, u(rng) * translation);
  return Rigid3d(ExpSO3(omega), t);
}

// Runs ceres::GradientChecker with the pose manifold on the blocks flagged in `is_pose`;
// returns the maximum relative error (or a large value when the check could not run).
inline double CheckGradient(const ceres::CostFunction& cost, const std::vector<bool>& is_pose,
                            std::vector<double*> parameters, std::string* log = nullptr) {
  const auto manifold = MakePoseManifold();
  std::vector<const ceres::Manifold*> manifolds;
  for (bool pose : is_pose) manifolds.push_back(pose ? manifold.get() : nullptr);
  ceres::NumericDiffOptions numeric;
  ceres::GradientChecker checker(&cost, &manifolds, numeric);
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(parameters.data(), 1e-6, &results);
  if (log != nullptr) *log = results.error_log;
  return results.return_value ? results.maximum_relative_error : 1e9;
}

// Independent check on the manifold: central differences of r(Plus(x, delta)) against the user
// Jacobian times the manifold's PlusJacobian, for the pose blocks flagged in `is_pose`
// (Euclidean otherwise). Returns the largest |difference| / max(1, |entry|).
inline double LocalJacobianError(const ceres::CostFunction& cost, const std::vector<bool>& is_pose,
                                 std::vector<double*> parameters, double h = 1e-6) {
  const auto manifold = MakePoseManifold();
  const int m = cost.num_residuals();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  std::vector<std::vector<double>> jac;
  std::vector<double*> jac_ptrs;
  for (int32_t size : sizes) jac.emplace_back(static_cast<size_t>(size * m));
  for (auto& j : jac) jac_ptrs.push_back(j.data());
  std::vector<double> r(m), rp(m), rm(m);
  if (!cost.Evaluate(parameters.data(), r.data(), jac_ptrs.data())) return 1e9;
  double worst = 0.0;
  for (size_t b = 0; b < sizes.size(); ++b) {
    const int ambient = sizes[b];
    const int tangent = is_pose[b] ? kPoseTangentSize : ambient;
    std::vector<double> plus_jac(static_cast<size_t>(ambient * tangent), 0.0);
    if (is_pose[b]) {
      manifold->PlusJacobian(parameters[b], plus_jac.data());
    } else {
      for (int i = 0; i < ambient; ++i) plus_jac[i * tangent + i] = 1.0;
    }
    const std::vector<double> original(parameters[b], parameters[b] + ambient);
    for (int k = 0; k < tangent; ++k) {
      std::vector<double> delta(tangent, 0.0), moved(ambient);
      for (double sign : {1.0, -1.0}) {
        delta[k] = sign * h;
        if (is_pose[b]) {
          manifold->Plus(original.data(), delta.data(), moved.data());
        } else {
          for (int i = 0; i < ambient; ++i) moved[i] = original[i] + delta[i];
        }
        std::copy(moved.begin(), moved.end(), parameters[b]);
        cost.Evaluate(parameters.data(), sign > 0 ? rp.data() : rm.data(), nullptr);
      }
      std::copy(original.begin(), original.end(), parameters[b]);
      for (int row = 0; row < m; ++row) {
        double user = 0.0;
        for (int a = 0; a < ambient; ++a)
          user += jac[b][row * ambient + a] * plus_jac[a * tangent + k];
        const double numeric = (rp[row] - rm[row]) / (2 * h);
        worst = std::max(worst, std::abs(user - numeric) / std::max(1.0, std::abs(user)));
      }
    }
  }
  return worst;
}

// Largest translation (m) or rotation (rad) difference between two sets of poses (ids of a).
inline double MaxPoseDifference(const std::map<int64_t, Rigid3d>& a,
                                const std::map<int64_t, Rigid3d>& b) {
  double worst = 0.0;
  for (const auto& [id, pose] : a) {
    const Rigid3d& other = b.at(id);
    worst = std::max(worst, (pose.translation() - other.translation()).norm());
    worst = std::max(worst, RotationAngle(pose.rotation().conjugate() * other.rotation()));
  }
  return worst;
}

}  // namespace jvl::optim::testing
