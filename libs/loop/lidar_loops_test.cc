#include "loop/lidar_loops.h"

#include <gtest/gtest.h>

#include <cmath>

namespace jvl::loop {
namespace {

TEST(LidarLoops, RejectsBadOptions) {
  LidarLoopOptions o;
  o.max_descriptor_distance = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = LidarLoopOptions{};
  o.consistency = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = LidarLoopOptions{};
  o.verify_candidates = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = LidarLoopOptions{};
  o.consistency_deg = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = LidarLoopOptions{};
  o.coarse_samples_per_list = o.association.samples_per_list + 1;
  EXPECT_THROW(o.Check(), std::exception);
  o = LidarLoopOptions{};
  o.coarse_voxel = -1;
  EXPECT_THROW(o.Check(), std::exception);
}

Rigid3d Pose(double yaw, double x, double z) {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())),
                 Eigen::Vector3d(x, 0, z));
}

TEST(LidarLoops, ConsecutiveLoopsAgreeInGeometry) {
  // Truth: a street driven along z, revisited 100 m later in the trajectory's frame (drift:
  // the second pass is placed 2 m and 1 deg off, which the relative motions do not see).
  const Rigid3d drift = Pose(0.017, 2.0, 0.5);
  const Rigid3d m1 = Pose(0, 0, 10), m2 = Pose(0, 0, 15);
  const Rigid3d q1_true = Pose(0.02, 1.0, 11), q2_true = Pose(0.03, 1.1, 16);
  const Rigid3d q1 = drift * q1_true, q2 = drift * q2_true;
  const Rigid3d loop1 = m1.Inverse() * q1_true, loop2 = m2.Inverse() * q2_true;
  const Rigid3d right = LoopDisagreement(q1, m1, loop1, q2, m2, loop2);
  EXPECT_LT(right.translation().norm(), 1e-9);
  EXPECT_LT(RotationAngle(right.rotation()), 1e-9);
  // The second registration slid 3 m along the street, or turned the wrong way round.
  const Rigid3d slid = loop2 * Pose(0, 0, 3);
  EXPECT_NEAR(LoopDisagreement(q1, m1, loop1, q2, m2, slid).translation().norm(), 3, 1e-9);
  const Rigid3d turned = loop2 * Pose(M_PI, 0, 0);
  EXPECT_NEAR(RotationAngle(LoopDisagreement(q1, m1, loop1, q2, m2, turned).rotation()), M_PI,
              1e-9);
}

TEST(LidarLoops, ScanCacheReturnsOnePreparationPerFrame) {
  // Three small scans (a box room each); a capacity of 2 evicts the least recently used.
  int loads = 0;
  auto load = [&](int64_t frame) {
    ++loads;
    PointCloud scan;
    for (int i = -40; i <= 40; ++i)
      for (int j = -10; j <= 10; ++j) {
        const double a = i * 0.25, b = j * 0.2;
        scan.points.emplace_back(a, 8.0 + frame, b);  // Walls (velodyne frame: z up).
        scan.points.emplace_back(a, -8.0, b);
        scan.points.emplace_back(12.0, a * 0.6, b);
        scan.points.emplace_back(a, b * 3, -1.7);  // Ground.
      }
    return scan;
  };
  Calibration c;
  c.cam0_from_velo = Rigid3d();
  LidarLoopOptions o;
  o.preprocess.min_range = 1.0;
  o.preprocess.remove_small_objects = false;
  LoopScanCache cache(load, c, o, 2);
  const auto a = cache.Get(0);
  EXPECT_EQ(cache.Get(0), a);  // Kept.
  EXPECT_EQ(loads, 1);
  cache.Get(1);
  cache.Get(2);  // Evicts 0.
  EXPECT_EQ(loads, 3);
  const auto again = cache.Get(0);
  EXPECT_EQ(loads, 4);
  EXPECT_NE(again, a);
  ASSERT_GT(a->samples.size(), 1000u);
  EXPECT_EQ(again->samples.points, a->samples.points);  // The same preparation.
  EXPECT_EQ(cache.Get(2), cache.Get(2));
  EXPECT_EQ(loads, 4);
}

TEST(LidarLoops, RelativeHeadingIsTheTurnAboutTheVertical) {
  // cam0: y down; a turn to the left is a rotation by -a about y.
  for (const double a : {0.0, 0.3, -1.2, 3.0}) {
    const Rigid3d rel(Eigen::Quaterniond(Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(1, 0, 2));
    EXPECT_NEAR(RelativeHeading(rel), a, 1e-12);
  }
}

}  // namespace
}  // namespace jvl::loop
