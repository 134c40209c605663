#include "eval/kitti_metric.h"

#include <gtest/gtest.h>

#include <cmath>

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

// On a 1 m/frame line the segment of length L from frame f ends at f + L + 1 (the first frame
// whose distance *exceeds* L). Frames 0..999 hold 999 m, so starts f <= 998 - L qualify.
int SegmentCount(double length) { return static_cast<int>((998 - length) / 10) + 1; }

TEST(Kitti, ScaleErrorGivesKnownTranslationError) {
  const PoseSeries gt = testing::StraightLine(1000);
  PoseSeries est = gt;
  for (auto& p : est.poses) p.block<3, 1>(0, 3) *= 1.1;
  const KittiResult k = ComputeKitti(Pair(gt, est), TrajectoryDistances(gt.poses), {});
  double sum = 0;
  int count = 0;
  for (double length = 100; length <= 800; length += 100) {
    sum += SegmentCount(length) * 0.1 * (length + 1) / length;
    count += SegmentCount(length);
  }
  ASSERT_EQ(static_cast<int>(k.segments.size()), count);
  EXPECT_NEAR(k.t_rel_percent, sum / count * 100, 1e-10);
  EXPECT_NEAR(k.r_rel_deg_per_100m, 0, 1e-9);
  ASSERT_EQ(k.per_length.size(), 8u);
  EXPECT_EQ(k.per_length[0].count, SegmentCount(100));
  EXPECT_NEAR(k.per_length[0].t_rel_percent, 10 * 101.0 / 100.0, 1e-10);
  EXPECT_EQ(k.segments.front().last_frame, 101);
}

TEST(Kitti, ConstantYawDriftGivesKnownRotationError) {
  const double w = 1e-4;
  const PoseSeries gt = testing::StraightLine(1000);
  const PoseSeries est = testing::Curve(1000, w);
  const KittiResult k = ComputeKitti(Pair(gt, est), TrajectoryDistances(gt.poses), {});
  double sum = 0;
  int count = 0;
  for (double length = 100; length <= 800; length += 100) {
    sum += SegmentCount(length) * w * (length + 1) / length;  // rad per m
    count += SegmentCount(length);
  }
  EXPECT_NEAR(k.r_rel_deg_per_100m, sum / count * 180 / M_PI * 100, 1e-7);
  EXPECT_NEAR(k.per_length[7].r_rel_deg_per_100m, w * 801 / 800 * 180 / M_PI * 100, 1e-7);
}

TEST(Kitti, MissingAndLateFramesSkipTheirSegments) {
  const PoseSeries gt = testing::StraightLine(1000);
  PoseSeries est = testing::Erase(gt, 10);
  est = testing::Erase(est, 0);  // Starts at frame 1, like an estimate that begins late.
  const KittiResult k = ComputeKitti(Pair(gt, est), TrajectoryDistances(gt.poses), {});
  int count = 0;
  for (double length = 100; length <= 800; length += 100) count += SegmentCount(length);
  EXPECT_EQ(static_cast<int>(k.segments.size()), count - 16);  // Starts 0 and 10 are gone.
  EXPECT_EQ(k.segments.front().first_frame, 20);
  EXPECT_NEAR(k.t_rel_percent, 0, 1e-12);
}

TEST(Kitti, TooShortHasNoSegments) {
  const PoseSeries gt = testing::StraightLine(50);
  const KittiResult k = ComputeKitti(Pair(gt, gt), TrajectoryDistances(gt.poses), {});
  EXPECT_TRUE(k.segments.empty());
  // Undefined, not 0 (a perfect-looking score): NaN, written as null and shown as n/a.
  EXPECT_TRUE(std::isnan(k.t_rel_percent));
  EXPECT_TRUE(std::isnan(k.r_rel_deg_per_100m));
  EXPECT_EQ(k.per_length[0].count, 0);
  EXPECT_TRUE(std::isnan(k.per_length[0].t_rel_percent));
}

}  // namespace
}  // namespace jvl::eval
