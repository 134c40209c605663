#include "loop/correction.h"

#include <gtest/gtest.h>

#include <cmath>

namespace jvl::loop {
namespace {

double PoseDistance(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation() - b.translation()).norm() +
         RotationAngle(a.rotation().inverse() * b.rotation());
}

// A drive along x with a slow left turn: world_from_cam of 11 keyframes.
std::vector<Rigid3d> Drive() {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < 11; ++i) {
    const double yaw = 0.05 * i;
    poses.emplace_back(ExpSO3(Eigen::Vector3d(0, yaw, 0)),
                       Eigen::Vector3d(2.0 * i, 0.1 * i * i, 0));
  }
  return poses;
}

TEST(DistributeCorrection, EndpointsExactInteriorInterpolated) {
  const std::vector<Rigid3d> before = Drive();
  std::vector<Rigid3d> poses = before;
  const size_t l = 2, n = 8;
  const Rigid3d corrected =
      Rigid3d(ExpSO3(Eigen::Vector3d(0.02, -0.1, 0.03)), Eigen::Vector3d(0.5, -0.3, 0.2)) *
      before[n];
  DistributeCorrection(l, n, corrected, &poses);
  EXPECT_LT(PoseDistance(poses[n], corrected), 1e-12);
  for (size_t i = 0; i <= l; ++i) EXPECT_LT(PoseDistance(poses[i], before[i]), 1e-15) << i;
  for (size_t i = n + 1; i < poses.size(); ++i) EXPECT_LT(PoseDistance(poses[i], before[i]), 1e-15);
  // In cam_from_world terms, keyframe i's correction is the fraction (i - l) / (n - l) of n's on
  // the Lie algebra of the rotation and linearly in the translation.
  const Rigid3d full = corrected.Inverse() * before[n];
  for (size_t i = l + 1; i < n; ++i) {
    const Rigid3d applied = poses[i].Inverse() * before[i];
    const double w = static_cast<double>(i - l) / static_cast<double>(n - l);
    EXPECT_LT((LogSO3(applied.rotation()) - w * LogSO3(full.rotation())).norm(), 1e-12) << i;
    EXPECT_LT((applied.translation() - w * full.translation()).norm(), 1e-12) << i;
  }
  // Interior corrections grow monotonically from l to n.
  double previous = 0;
  for (size_t i = l + 1; i <= n; ++i) {
    const double d = PoseDistance(poses[i], before[i]);
    EXPECT_GT(d, previous) << i;
    previous = d;
  }
}

TEST(DistributeCorrection, IdentityCorrectionIsANoOp) {
  const std::vector<Rigid3d> before = Drive();
  std::vector<Rigid3d> poses = before;
  DistributeCorrection(0, 10, before[10], &poses);
  for (size_t i = 0; i < poses.size(); ++i) EXPECT_LT(PoseDistance(poses[i], before[i]), 1e-12);
}

TEST(DistributeCorrection, RejectsBadIndices) {
  std::vector<Rigid3d> poses = Drive();
  EXPECT_THROW(DistributeCorrection(5, 5, poses[5], &poses), std::exception);
  EXPECT_THROW(DistributeCorrection(6, 5, poses[5], &poses), std::exception);
  EXPECT_THROW(DistributeCorrection(0, 11, poses[5], &poses), std::exception);
  EXPECT_THROW(DistributeCorrection(0, 3, poses[3], nullptr), std::exception);
}

}  // namespace
}  // namespace jvl::loop
