#include "eval/metrics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/check.h"
#include "eval/test_util.h"

namespace jvl::eval {
namespace {

PairedPoses Pair(const PoseSeries& gt, const PoseSeries& est) {
  PairedPoses p;
  p.frames = gt.frames;
  p.gt = gt.poses;
  p.est.assign(gt.size(), Eigen::Matrix4d::Identity());
  p.has_est.assign(gt.size(), 0);
  for (size_t e = 0; e < est.size(); ++e) {
    if (const auto g = gt.IndexOf(est.frames[e])) p.est[*g] = est.poses[e], p.has_est[*g] = 1;
  }
  return p;
}

TEST(Stats, KnownValues) {
  const ErrorStats s = ComputeStats({4, 1, 3, 2});
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));
  EXPECT_EQ(s.min, 1);
  EXPECT_EQ(s.max, 4);
  EXPECT_EQ(s.count, 4);
  EXPECT_DOUBLE_EQ(ComputeStats({5, 1, 3}).median, 3);
  EXPECT_EQ(ComputeStats({}).count, 0);
}

TEST(Ape, PureTranslationOffset) {
  const PoseSeries gt = testing::Curve(40, 0.02);
  PoseSeries est = gt;
  for (auto& p : est.poses) p.block<3, 1>(0, 3) += Eigen::Vector3d(1, 2, 2);  // |offset| = 3
  const ApeResult ape = ComputeApe(Pair(gt, est));
  EXPECT_EQ(ape.translation_stats.count, 40);
  EXPECT_NEAR(ape.translation_stats.rmse, 3.0, 1e-12);
  EXPECT_NEAR(ape.translation_stats.min, 3.0, 1e-12);
  EXPECT_NEAR(ape.translation_stats.std, 0.0, 1e-12);
  EXPECT_NEAR(ape.rotation_stats.max, 0.0, 1e-6);
}

// KITTI camera moving along +z (up = -y): lateral (up x along) is -x, i.e. left.
TEST(ApeComponents, SplitsAlongThePathAndAboutTheCameraAxes) {
  const PoseSeries gt = testing::StraightLine(30);
  PoseSeries est = gt;
  const Eigen::Matrix3d pitch =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (auto& p : est.poses) {
    p.block<3, 1>(0, 3) += Eigen::Vector3d(0.3, -0.2, 0.1);  // 0.3 right, 0.2 up, 0.1 ahead.
    p.topLeftCorner<3, 3>() = p.topLeftCorner<3, 3>() * pitch;
  }
  est.poses[7].topLeftCorner<3, 3>() = testing::Yaw(-0.02);  // One frame turned right.
  const ApeComponents c = ComputeApeComponents(Pair(gt, est));
  EXPECT_NEAR((c.up - Eigen::Vector3d(0, -1, 0)).norm(), 0.0, 1e-15);
  ASSERT_EQ(c.along.count, 30);
  EXPECT_EQ(c.skipped, 0);
  EXPECT_NEAR(c.along.min, 0.1, 1e-12);
  EXPECT_NEAR(c.along.max, 0.1, 1e-12);
  EXPECT_NEAR(c.lateral.rmse, 0.3, 1e-12);
  EXPECT_NEAR(c.lateral.max, -0.3, 1e-12);  // To the right: negative.
  EXPECT_NEAR(c.vertical.min, 0.2, 1e-12);
  EXPECT_NEAR(c.vertical.max, 0.2, 1e-12);
  EXPECT_NEAR(c.pitch_deg[0], 0.01 * 180 / M_PI, 1e-10);
  EXPECT_NEAR(c.yaw_deg[0], 0.0, 1e-12);
  EXPECT_NEAR(c.roll_deg[0], 0.0, 1e-12);
  EXPECT_NEAR(c.pitch_deg[7], 0.0, 1e-12);
  EXPECT_NEAR(c.yaw_deg[7], -0.02 * 180 / M_PI, 1e-10);
  // Up given explicitly: +x as up makes the old vertical offset (-y) lateral.
  const ApeComponents x = ComputeApeComponents(Pair(gt, est), Eigen::Vector3d(2, 0, 0));
  EXPECT_NEAR(x.vertical.min, 0.3, 1e-12);
  EXPECT_NEAR(std::abs(x.lateral.max), 0.2, 1e-12);
}

TEST(ApeComponents, StandingStillUsesTheCameraAxisAndSkipsTravelAlongUp) {
  // Not moving: the direction of travel is the camera's z axis.
  const PoseSeries still = testing::MakeSeries(0, 5, [](int64_t) {
    return testing::Pose(testing::Yaw(M_PI / 2), Eigen::Vector3d(1, 0, 1));
  });
  PoseSeries est = still;
  for (auto& p : est.poses) p(0, 3) += 0.5;  // Along the turned camera's z (= world +x).
  const ApeComponents c = ComputeApeComponents(Pair(still, est));
  EXPECT_NEAR(c.along.rmse, 0.5, 1e-12);
  EXPECT_NEAR(c.lateral.rmse, 0.0, 1e-12);
  // Moving straight up (along -y): no direction of travel on the ground.
  const PoseSeries lift = testing::MakeSeries(0, 6, [](int64_t f) {
    return testing::Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, -2.0 * f, 0));
  });
  const ApeComponents l = ComputeApeComponents(Pair(lift, lift));
  EXPECT_EQ(l.skipped, 6);
  EXPECT_EQ(l.along.count, 0);
}

TEST(Rpe, ConstantYawDriftByFramesAndMetres) {
  const double w = 0.01;  // rad of extra yaw per frame
  const PoseSeries gt = testing::StraightLine(100);
  const PoseSeries est = testing::Curve(100, w);
  const PairedPoses p = Pair(gt, est);
  const std::vector<double> dist = TrajectoryDistances(p.gt);
  EXPECT_DOUBLE_EQ(dist.back(), 99.0);
  const RpeResult by_frame = ComputeRpe(p, dist, {});
  EXPECT_EQ(by_frame.translation_stats.count, 99);
  EXPECT_NEAR(by_frame.rotation_stats.mean, w * 180 / M_PI, 1e-9);
  EXPECT_NEAR(by_frame.rotation_stats.std, 0, 1e-9);
  EXPECT_NEAR(by_frame.translation_stats.max, 0, 1e-12);

  RpeOptions metres;
  metres.delta = 5;  // The end is the first frame more than 5 m further: 6 frames ahead.
  metres.unit = RpeUnit::kMetres;
  const RpeResult by_m = ComputeRpe(p, dist, metres);
  EXPECT_EQ(by_m.translation_stats.count, 94);
  EXPECT_EQ(by_m.last_frame.front() - by_m.first_frame.front(), 6);
  EXPECT_NEAR(by_m.rotation_stats.mean, 6 * w * 180 / M_PI, 1e-9);
  // Translation error of 6 drifting unit steps against a 6 m straight line.
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();
  for (int k = 0; k < 6; ++k) drift += testing::Yaw(k * w) * Eigen::Vector3d(0, 0, 1);
  const double t = (drift - Eigen::Vector3d(0, 0, 6)).norm();
  EXPECT_NEAR(by_m.translation_stats.mean, t, 1e-12);
  EXPECT_NEAR(by_m.percent_stats.mean, t / 6 * 100, 1e-10);
  RpeOptions bad;
  bad.delta = 1.5;
  EXPECT_THROW(bad.Check(), Error);
}

TEST(Rpe, MissingFrameDropsItsPairs) {
  const PoseSeries gt = testing::StraightLine(20);
  const PoseSeries est = testing::Erase(gt, 7);
  const RpeResult r = ComputeRpe(Pair(gt, est), TrajectoryDistances(gt.poses), {});
  EXPECT_EQ(r.translation_stats.count, 17);  // 19 pairs minus (6,7) and (7,8).
}

}  // namespace
}  // namespace jvl::eval
