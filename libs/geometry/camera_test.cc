#include "geometry/camera.h"

#include <gtest/gtest.h>

#include "core/check.h"
#include "geometry/calibration.h"

namespace jvl {
namespace {

TEST(CameraTest, ProjectUnprojectRoundTrip) {
  // KITTI sequence 04 P0 intrinsics.
  PinholeCamera cam{707.0912, 707.0912, 601.8873, 183.1104, 1226, 370};
  const Eigen::Vector3d p(2.0, -1.0, 10.0);
  const Eigen::Vector2d uv = cam.Project(p);
  EXPECT_NEAR(uv.x(), 707.0912 * 0.2 + 601.8873, 1e-12);
  EXPECT_NEAR(uv.y(), 707.0912 * -0.1 + 183.1104, 1e-12);
  EXPECT_LT((cam.Unproject(uv) * 10.0 - p).norm(), 1e-12);
  EXPECT_TRUE(cam.InImage(uv));
  EXPECT_FALSE(cam.InImage(Eigen::Vector2d(1226, 10)));
  EXPECT_LT((cam.K() * cam.Unproject(uv) - Eigen::Vector3d(uv.x(), uv.y(), 1)).norm(), 1e-12);
}

TEST(CameraTest, CheckRejectsBadIntrinsics) {
  PinholeCamera cam{0, 700, 600, 180, 1226, 370};
  EXPECT_THROW(cam.Check(), Error);
}

// KITTI odometry sequence 04's calib.txt: P2 (left colour camera) = K [I | t_2].
TEST(CalibrationTest, CameraOffsetIsKInverseTimesTheLastColumn) {
  Calibration c;
  c.P[0] << 707.0912, 0, 601.8873, 0, 0, 707.0912, 183.1104, 0, 0, 0, 1, 0;
  c.P[2] << 707.0912, 0, 601.8873, 46.88783, 0, 707.0912, 183.1104, 0.1178601, 0, 0, 1, 0.006203223;
  EXPECT_LT(c.CameraOffset(0).norm(), 1e-15);
  const Eigen::Vector3d t = c.CameraOffset(2);
  EXPECT_NEAR(t.z(), 0.006203223, 1e-12);
  EXPECT_NEAR(t.x(), (46.88783 - 601.8873 * 0.006203223) / 707.0912, 1e-12);  // 0.0610 m
  EXPECT_NEAR(t.y(), (0.1178601 - 183.1104 * 0.006203223) / 707.0912, 1e-12);
  // The projection of a camera-0 point by P2 is camera 2's pinhole projection at the offset.
  const Eigen::Vector3d x0(1.5, -0.4, 12.0);
  const Eigen::Vector3d h = c.P[2] * x0.homogeneous();
  EXPECT_LT((c.Camera(2).Project(x0 + t) - h.hnormalized()).norm(), 1e-9);
  EXPECT_LT((CameraChoice::Of(c, 2).camera_from_cam0() * x0 - (x0 + t)).norm(), 1e-12);
  // Camera 1 has no projection here: a one-line error naming the source.
  EXPECT_THROW(c.CheckCamera(1, "calib.txt"), Error);
  EXPECT_NO_THROW(c.CheckCamera(2, "calib.txt"));
  EXPECT_THROW(c.CheckCamera(4, "calib.txt"), Error);
}

}  // namespace
}  // namespace jvl
