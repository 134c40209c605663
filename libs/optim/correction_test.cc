#include "optim/correction.h"

#include <gtest/gtest.h>

#include "core/check.h"
#include "optim/test_util.h"

namespace jvl::optim {
namespace {

using testing::RandomPose;

void ExpectPoseNear(const Rigid3d& a, const Rigid3d& b, double tol) {
  EXPECT_LT((a.translation() - b.translation()).norm(), tol);
  EXPECT_LT(RotationAngle(a.rotation().conjugate() * b.rotation()), tol);
}

std::vector<Rigid3d> StraightKeyframes(int count) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < count; ++i) {
    poses.emplace_back(ExpSO3(Eigen::Vector3d(0, 0.02 * i, 0)),
                       Eigen::Vector3d(0.1 * i, 0, 2.0 * i));
  }
  return poses;
}

TEST(DistributeCorrection, FollowsAlgorithm1) {
  const std::vector<Rigid3d> poses = StraightKeyframes(5);
  // Correction in the paper's convention: Delta T_n = T^_nw T_nw^-1.
  const Eigen::Vector3d phi(0.01, 0.08, -0.02);
  const Eigen::Vector3d dt(0.4, -0.2, 1.0);
  const Rigid3d delta(ExpSO3(phi), dt);
  const Rigid3d corrected_n = (delta * poses.back().Inverse()).Inverse();
  const std::vector<Rigid3d> out = DistributeCorrection(poses, corrected_n);
  ASSERT_EQ(out.size(), poses.size());
  ExpectPoseNear(out.front(), poses.front(), 1e-12);
  ExpectPoseNear(out.back(), corrected_n, 1e-12);
  for (size_t i = 1; i + 1 < poses.size(); ++i) {
    const double f = static_cast<double>(i) / 4.0;
    const Rigid3d delta_i = out[i].Inverse() * poses[i];  // T^_iw T_iw^-1
    ExpectPoseNear(delta_i, Rigid3d(ExpSO3(f * phi), f * dt), 1e-9);
  }
}

TEST(DistributeCorrection, UsesPositionsAndRejectsBadInput) {
  const std::vector<Rigid3d> poses = StraightKeyframes(3);
  const Rigid3d delta(ExpSO3(Eigen::Vector3d(0, 0.1, 0)), Eigen::Vector3d(1, 0, 0));
  const Rigid3d corrected_n = (delta * poses.back().Inverse()).Inverse();
  // Middle keyframe at 90 % of the span.
  const std::vector<Rigid3d> out = DistributeCorrection(poses, corrected_n, {10, 19, 20});
  const Rigid3d delta_1 = out[1].Inverse() * poses[1];
  EXPECT_NEAR(RotationAngle(delta_1.rotation()), 0.09, 1e-9);
  EXPECT_NEAR(delta_1.translation().x(), 0.9, 1e-9);
  EXPECT_THROW(DistributeCorrection({poses[0]}, corrected_n), Error);
  EXPECT_THROW(DistributeCorrection(poses, corrected_n, {1, 2}), Error);
  EXPECT_THROW(DistributeCorrection(poses, corrected_n, {3, 3, 3}), Error);
}

TEST(DistributeCorrection, IdentityCorrectionIsANoOp) {
  const std::vector<Rigid3d> poses = StraightKeyframes(6);
  const std::vector<Rigid3d> out = DistributeCorrection(poses, poses.back());
  ASSERT_EQ(out.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) ExpectPoseNear(out[i], poses[i], 1e-12);
}

Trajectory PriorTrajectory(int count) {
  Trajectory t;
  for (int i = 0; i < count; ++i) {
    t.Append(100 + i,
             Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.01 * i, 0)), Eigen::Vector3d(0, 0, 1.0 * i)),
             0.1 * i);
  }
  return t;
}

TEST(InterpolateFullRate, CommonCorrectionMovesEveryFrameRigidly) {
  std::mt19937 rng(8);
  const Trajectory prior = PriorTrajectory(11);
  const Rigid3d g = RandomPose(rng, 0.2, 3.0);
  std::map<int64_t, Rigid3d> keyframes;
  for (int64_t f : {102, 105, 108}) keyframes[f] = g * prior.world_from_cam[f - 100];
  const Trajectory out = InterpolateFullRate(prior, keyframes);
  ASSERT_EQ(out.frames, prior.frames);
  for (size_t i = 0; i < out.size(); ++i) {
    ExpectPoseNear(out.world_from_cam[i], g * prior.world_from_cam[i], 1e-9);
  }
}

TEST(InterpolateFullRate, InterpolatesNeighbouringCorrectionsOnSE3) {
  std::mt19937 rng(9);
  Trajectory prior = PriorTrajectory(11);
  prior.timestamps[3] = 0.45;  // uneven time: fraction (0.45 - 0.2) / (0.5 - 0.2)
  const Rigid3d g2 = RandomPose(rng, 0.1, 1.0);
  const Rigid3d g5 = RandomPose(rng, 0.1, 1.0);
  const std::map<int64_t, Rigid3d> keyframes = {{102, g2 * prior.world_from_cam[2]},
                                                {105, g5 * prior.world_from_cam[5]}};
  const Trajectory out = InterpolateFullRate(prior, keyframes);
  ExpectPoseNear(out.world_from_cam[0], g2 * prior.world_from_cam[0], 1e-9);  // before the first
  ExpectPoseNear(out.world_from_cam[2], keyframes.at(102), 1e-12);
  ExpectPoseNear(out.world_from_cam[3],
                 Interpolate(g2, g5, (0.45 - 0.2) / 0.3) * prior.world_from_cam[3], 1e-9);
  ExpectPoseNear(out.world_from_cam[4], Interpolate(g2, g5, 2.0 / 3.0) * prior.world_from_cam[4],
                 1e-9);
  ExpectPoseNear(out.world_from_cam[5], keyframes.at(105), 1e-12);
  ExpectPoseNear(out.world_from_cam[10], g5 * prior.world_from_cam[10], 1e-9);  // after the last
  EXPECT_THROW(InterpolateFullRate(prior, {{99, Rigid3d()}}), Error);
  EXPECT_THROW(InterpolateFullRate(prior, {}), Error);
}

// The prior jumps 0.5 m between frames 104 and 105, inside the keyframe interval 103..106; the
// optimised keyframes follow the true motion. The frames of that interval get the constant twist
// between the optimised keyframes, so the step is gone; elsewhere the corrections are
// interpolated as before. With step_factor 0 the step survives.
TEST(InterpolateFullRate, BridgesAStepOfThePriorInsideAKeyframeInterval) {
  const Trajectory truth = PriorTrajectory(12);
  Trajectory prior = truth;
  for (size_t i = 5; i < prior.size(); ++i)
    prior.world_from_cam[i] = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.5, 0, 0)) *
                              prior.world_from_cam[i];
  std::map<int64_t, Rigid3d> keyframes;
  for (int64_t f : {100, 101, 102, 103, 106, 107, 108, 109, 111})
    keyframes[f] = truth.world_from_cam[static_cast<size_t>(f - 100)];
  int64_t bridged = -1;
  const Trajectory out = InterpolateFullRate(prior, keyframes, 5.0, &bridged);
  EXPECT_EQ(bridged, 1);
  // Frames 104 and 105 follow the constant twist from 103 to 106, not the truth's motion (its
  // translation is along a fixed world axis while it turns): 1 cm off, against the 0.5 m step.
  for (size_t i = 0; i < out.size(); ++i)
    ExpectPoseNear(out.world_from_cam[i], truth.world_from_cam[i], i == 4 || i == 5 ? 0.02 : 1e-6);
  const Trajectory kept = InterpolateFullRate(prior, keyframes, 0.0, &bridged);
  EXPECT_EQ(bridged, 0);
  const Rigid3d step = (kept.world_from_cam[4].Inverse() * kept.world_from_cam[5]).Inverse() *
                       (truth.world_from_cam[4].Inverse() * truth.world_from_cam[5]);
  EXPECT_GT(step.translation().norm(), 0.3);
}

}  // namespace
}  // namespace jvl::optim
