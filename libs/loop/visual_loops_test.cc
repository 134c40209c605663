#include "loop/visual_loops.h"

#include <gtest/gtest.h>

#include <random>

#include "lidar/test_scenes.h"

namespace jvl::loop {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

Calibration TestCalibration() {
  Calibration c;
  c.P[0] << 700, 0, 620, 0, 0, 700, 188, 0, 0, 0, 1, 0;
  c.P[1] << 700, 0, 620, -378, 0, 700, 188, 0, 0, 0, 1, 0;  // 0.54 m right of camera 0
  c.image_width = 1241;
  c.image_height = 376;
  Eigen::Matrix3d r;  // KITTI's axes: cam0 x = -velo y, y = -velo z, z = velo x.
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  c.cam0_from_velo = Rigid3d(Eigen::Quaterniond(r), Eigen::Vector3d::Zero());
  return c;
}

// The scan of `cam_points` (cam0 frame) as the LiDAR gives it (velodyne frame).
PointCloud ScanOf(const std::vector<Eigen::Vector3d>& cam_points, const Calibration& c) {
  PointCloud scan;
  const Rigid3d velo_from_cam0 = c.cam0_from_velo.Inverse();
  for (const auto& p : cam_points)
    if (p.norm() < 60) scan.points.push_back(velo_from_cam0 * p);
  return scan;
}

struct Pair {
  VisualKeyframe query, match;
  PointCloud query_scan, match_scan;
  Rigid3d match_from_query;
};

// The pair's verification: the query is frame 1, the match frame 0.
LoopCandidate Verify(const Pair& p, const Calibration& c, int camera = 0) {
  VisualLoopOptions o;
  o.camera = camera;
  LoopScanCache scans([&](int64_t frame) { return frame == 1 ? p.query_scan : p.match_scan; }, c,
                      o.lidar);
  return VerifyVisualCandidate(p.query, p.match, 1, 0, scans, o);
}

// A street seen by the match keyframe at the origin and by the query from `match_from_query`;
// the features are scene points seen by both, each with its own random descriptor (all in one
// vocabulary node).
Pair StreetPair(const Rigid3d& match_from_query, const Calibration& c, int camera_index = 0) {
  const std::vector<Eigen::Vector3d> scene = lidar::testing::StreetScene(0.1);
  Pair p;
  p.match_from_query = match_from_query;
  const Rigid3d query_from_match = match_from_query.Inverse();
  std::vector<Eigen::Vector3d> query_points;
  for (const auto& x : scene) query_points.push_back(query_from_match * x);
  p.match_scan = ScanOf(scene, c);
  p.query_scan = ScanOf(query_points, c);
  // The keypoints as the chosen camera sees them, at its offset from camera 0.
  const PinholeCamera camera = c.Camera(camera_index);
  const Eigen::Vector3d offset = c.CameraOffset(camera_index);
  std::mt19937 random(5);
  for (size_t i = 0; i < scene.size(); i += 97) {
    const Eigen::Vector3d xm = scene[i] + offset;
    const Eigen::Vector3d xq = query_from_match * scene[i] + offset;
    if (xm.z() < 2 || xq.z() < 2 || xm.norm() > 40) continue;
    const Eigen::Vector2d um = camera.Project(xm), uq = camera.Project(xq);
    if (!camera.InImage(um, 10) || !camera.InImage(uq, 10)) continue;
    vision::Descriptor d;
    for (uint8_t& b : d) b = static_cast<uint8_t>(random() & 0xff);
    p.match.keypoints.push_back({um.cast<float>(), 0, 0, 1});
    p.query.keypoints.push_back({uq.cast<float>(), 0, 0, 1});
    p.match.descriptors.push_back(d);
    p.query.descriptors.push_back(d);
  }
  p.match.nodes.assign(p.match.descriptors.size(), 0);
  p.query.nodes.assign(p.query.descriptors.size(), 0);
  return p;
}

TEST(VisualLoops, RejectsBadOptions) {
  VisualLoopOptions o;
  o.min_inliers = 3;
  EXPECT_THROW(o.Check(), std::exception);
  o = VisualLoopOptions{};
  o.ratio = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = VisualLoopOptions{};
  o.consistency = 0;
  EXPECT_THROW(o.Check(), std::exception);
}

TEST(VisualLoops, VerificationRecoversARevisit) {
  const Calibration c = TestCalibration();
  const Rigid3d truth(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(1.0, 0.05, 2.0));
  const Pair p = StreetPair(truth, c);
  ASSERT_GT(p.query.keypoints.size(), 100u);
  const LoopCandidate got = Verify(p, c);
  EXPECT_EQ(got.status, LoopStatus::kAccepted) << ToString(got.status);
  EXPECT_GE(got.inliers, 60);
  const Rigid3d error = truth.Inverse() * got.match_from_query;
  EXPECT_LT(error.translation().norm(), 0.05);
  EXPECT_LT(RotationAngle(error.rotation()) * kRadToDeg, 0.3);
}

// The same revisit seen by camera 1, 0.54 m beside camera 0: the pose and the points come back
// in camera 0's frame (the points project through the offset onto their keypoints).
TEST(VisualLoops, VerificationThroughAnotherCameraReturnsCamera0Geometry) {
  const Calibration c = TestCalibration();
  const Rigid3d truth(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(1.0, 0.05, 2.0));
  const Pair p = StreetPair(truth, c, 1);
  ASSERT_GT(p.query.keypoints.size(), 100u);
  const LoopCandidate got = Verify(p, c, 1);
  EXPECT_EQ(got.status, LoopStatus::kAccepted) << ToString(got.status);
  EXPECT_GE(got.inliers, 60);
  const Rigid3d error = truth.Inverse() * got.match_from_query;
  EXPECT_LT(error.translation().norm(), 0.05);
  EXPECT_LT(RotationAngle(error.rotation()) * kRadToDeg, 0.3);
  ASSERT_FALSE(got.points.empty());
  const Eigen::Vector3d offset = c.CameraOffset(1);
  for (const LoopPoint& point : got.points) {
    EXPECT_LT((c.Camera(1).Project(point.p_match + offset) - point.match_uv).norm(), 1.0);
    EXPECT_LT(
        (c.Camera(1).Project(truth.Inverse() * point.p_match + offset) - point.query_uv).norm(),
        3.0);
  }
}

TEST(VisualLoops, VerificationRejectsCraftedFalseCandidates) {
  const Calibration c = TestCalibration();
  const Rigid3d truth(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.5, 0, 1.5));
  // 1. The descriptors agree but the keypoints of the query are scattered: no pose explains them.
  Pair scattered = StreetPair(truth, c);
  std::mt19937 random(9);
  for (auto& k : scattered.query.keypoints)
    k.uv = Eigen::Vector2f(static_cast<float>(random() % 1200), static_cast<float>(random() % 360));
  const LoopCandidate a = Verify(scattered, c);
  EXPECT_EQ(a.status, LoopStatus::kFewInliers) << ToString(a.status);

  // 2. The images agree (a look-alike facade) but the query's scan is of another place: a long
  // featureless corridor, where the registration cannot confirm the image's pose.
  Pair elsewhere = StreetPair(truth, c);
  elsewhere.query_scan = ScanOf(lidar::testing::CorridorScene(0.1), c);
  const LoopCandidate b = Verify(elsewhere, c);
  EXPECT_GE(b.inliers, 60);  // The images alone would have accepted it.
  EXPECT_NE(b.status, LoopStatus::kAccepted) << ToString(b.status);
}

}  // namespace
}  // namespace jvl::loop
