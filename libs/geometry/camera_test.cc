#include "geometry/camera.h"

#include <gtest/gtest.h>

#include "core/check.h"

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

}  // namespace
}  // namespace jvl
