#include "eval/pose_series.h"

#include <gtest/gtest.h>

#include "core/check.h"
#include "eval/test_util.h"

namespace jvl::eval {
namespace {

using testing::Pose;

TEST(PoseSeries, IndexOfAndCheck) {
  PoseSeries s = testing::StraightLine(5);
  s = testing::Erase(s, 2);
  EXPECT_EQ(*s.IndexOf(3), 2u);
  EXPECT_FALSE(s.IndexOf(2).has_value());
  EXPECT_NO_THROW(s.Check("est"));
  s.frames[1] = 0;
  EXPECT_THROW(s.Check("est"), Error);
}

TEST(PoseSeries, DevkitRotationAngle) {
  EXPECT_DOUBLE_EQ(DevkitRotationAngle(Eigen::Matrix4d::Identity()), 0.0);
  EXPECT_NEAR(DevkitRotationAngle(Pose(testing::Yaw(0.3), Eigen::Vector3d::Zero())), 0.3, 1e-12);
  EXPECT_NEAR(DevkitRotationAngle(Pose(testing::Yaw(M_PI), Eigen::Vector3d::Zero())), M_PI, 1e-7);
  EXPECT_DOUBLE_EQ(TranslationNorm(Pose(Eigen::Matrix3d::Identity(), {3, 4, 12})), 13.0);
}

TEST(PoseSeries, LidarToCameraMapsForwardXToForwardZ) {
  // KITTI-like Tr: velodyne x (forward) -> cam z, y (left) -> -cam x, z (up) -> -cam y.
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const Eigen::Matrix4d cam0_from_velo = Pose(r, {0.1, -0.2, -0.3});
  PoseSeries velo = testing::MakeSeries(0, 3, [](int64_t f) {
    return Pose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(2.0 * f, 0, 0));
  });
  const PoseSeries cam = LidarToCamera(velo, cam0_from_velo);
  for (int f = 0; f < 3; ++f) {
    EXPECT_TRUE((cam.poses[f].topLeftCorner<3, 3>().isIdentity(1e-15)));
    EXPECT_TRUE(((cam.poses[f].block<3, 1>(0, 3) - Eigen::Vector3d(0, 0, 2.0 * f)).norm() < 1e-15));
  }
  // A yaw of the car (about velodyne z) is a rotation about -y in cam0.
  velo.poses[1] = Pose(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                       Eigen::Vector3d::Zero());
  const Eigen::Matrix4d c = LidarToCamera(velo, cam0_from_velo).poses[1];
  EXPECT_TRUE((c.topLeftCorner<3, 3>().isApprox(testing::Yaw(-0.2), 1e-14)));
}

}  // namespace
}  // namespace jvl::eval
