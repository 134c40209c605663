#include "eval/metrics.h"

#include <gtest/gtest.h>

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
