#include "loop/lidar_loops.h"

#include <gtest/gtest.h>

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
  o.consistency_yaw_deg = 0;
  EXPECT_THROW(o.Check(), std::exception);
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
