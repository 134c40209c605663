#include "lidar/preprocess.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace jvl::lidar {
namespace {

// Everything off except the step under test (ground labelling never removes points).
PreprocessOptions AllOff() {
  PreprocessOptions o;
  o.voxel_size = 0;
  o.outlier_radius = 0;
  o.remove_small_objects = false;
  return o;
}

// A flat ground patch at cam0 y = +1.7 (1.7 m below the sensor), spacing `step`.
void AddGround(double half, double step, std::vector<Eigen::Vector3d>* pts) {
  for (double x = -half; x <= half; x += step) {
    for (double z = -half; z <= half; z += step) pts->emplace_back(x, 1.7, z);
  }
}

// A sensor moving at constant velocity sees a fixed world point p from the pose at its time
// fraction s: cur_from_sensor(s) = Exp(s xi). De-skewing brings every observation back to p.
TEST(PreprocessTest, DeskewUndoesConstantVelocityMotion) {
  const Rigid3d prev_from_cur(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.1, 1.0, 0.0).normalized())),
      Eigen::Vector3d(0.1, 0.0, 1.2));
  const Vector6d xi = LogSE3(prev_from_cur);
  const Eigen::Vector3d p(3.0, -1.0, 12.0);
  PreprocessedScan scan;
  for (const float s : {-0.5f, -0.2f, 0.0f, 0.3f, 0.5f}) {
    scan.points.push_back(ExpSE3(static_cast<double>(s) * xi).Inverse() * p);
    scan.time_fraction.push_back(s);
  }
  DeskewScan(prev_from_cur, &scan);
  for (const Eigen::Vector3d& q : scan.points) EXPECT_LT((q - p).norm(), 1e-6);
}

// A scan taken `offset` frame periods after its frame (an Oxford sweep after its image) is moved
// to the frame time: the observations made from cur_from_sensor(s + offset) all return to p.
TEST(PreprocessTest, DeskewMovesALateScanToTheFrameTime) {
  const Rigid3d prev_from_cur(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d(0.1, 1.0, 0.0).normalized())),
      Eigen::Vector3d(0.1, 0.0, 1.2));
  const Vector6d xi = LogSE3(prev_from_cur);
  const Eigen::Vector3d p(3.0, -1.0, 12.0);
  const double offset = 0.32;  // 20 ms at 16 Hz
  PreprocessedScan scan;
  scan.time_offset = offset;
  for (const float s : {-0.5f, 0.0f, 0.4f}) {
    scan.points.push_back(ExpSE3((static_cast<double>(s) + offset) * xi).Inverse() * p);
    scan.time_fraction.push_back(s);
  }
  PreprocessedScan uncompensated = scan;
  uncompensated.time_offset = 0;
  DeskewScan(prev_from_cur, &scan);
  DeskewScan(prev_from_cur, &uncompensated);
  for (const Eigen::Vector3d& q : scan.points) EXPECT_LT((q - p).norm(), 1e-6);
  // Without the offset the points stay where the sensor was 20 ms later: 0.38 m off.
  EXPECT_GT((uncompensated.points[1] - p).norm(), 0.3);
}

TEST(PreprocessTest, RangeCutDropsNearPointsAndNaN) {
  PointCloud scan;
  scan.points = {{3, 0, 0}, {0, 4.9, 0}, {6, 0, 0}, {0, 0, 5.1}, {20, 1, 1}};
  scan.points.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0, 0);
  const PreprocessedScan out = PreprocessScan(scan, Rigid3d(), AllOff());
  EXPECT_EQ(out.counts.non_finite, 1);
  EXPECT_EQ(out.counts.after_range, 3);
  ASSERT_EQ(out.points.size(), 3u);
  for (const auto& p : out.points) EXPECT_GE(p.norm(), 5.0);
}

TEST(PreprocessTest, MovesPointsIntoCam0) {
  PointCloud scan;
  scan.points = {{10, 0, 0}};
  const Rigid3d cam0_from_velo(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY())),
                               Eigen::Vector3d(0.1, -0.2, 0.3));
  const PreprocessedScan out = PreprocessScan(scan, cam0_from_velo, AllOff());
  ASSERT_EQ(out.points.size(), 1u);
  EXPECT_LT((out.points[0] - cam0_from_velo * Eigen::Vector3d(10, 0, 0)).norm(), 1e-12);
}

TEST(PreprocessTest, VerticalCorrectionRaisesElevation) {
  std::vector<Eigen::Vector3d> pts = {{10, 0, 0}, {0, -20, 1}};
  const double angle = 0.205 * M_PI / 180;
  const double elev1 = std::atan2(1.0, 20.0);
  CorrectVerticalAngle(angle, &pts);
  EXPECT_NEAR(std::atan2(pts[0].z(), pts[0].head<2>().norm()), angle, 1e-12);
  EXPECT_NEAR(std::atan2(pts[1].z(), pts[1].head<2>().norm()), elev1 + angle, 1e-12);
  EXPECT_NEAR(pts[1].norm(), std::sqrt(401.0), 1e-9);  // Range unchanged.
}

// The closed form equals the rotation about the horizontal axis p x up, in every direction; a
// point on the vertical axis (no such axis) is left as it is.
TEST(PreprocessTest, VerticalCorrectionIsTheRotationAboutTheHorizontalAxis) {
  std::vector<Eigen::Vector3d> pts;
  for (int a = 0; a < 12; ++a)
    for (const double z : {-2.5, -0.3, 0.0, 0.8, 4.0}) {
      const double az = a * M_PI / 6 + 0.1;
      pts.emplace_back((5 + a) * std::cos(az), (5 + a) * std::sin(az), z);
    }
  pts.emplace_back(0, 0, 3);
  for (const double angle : {0.205 * M_PI / 180, -0.5 * M_PI / 180}) {
    std::vector<Eigen::Vector3d> corrected = pts;
    CorrectVerticalAngle(angle, &corrected);
    for (size_t i = 0; i + 1 < pts.size(); ++i) {
      const Eigen::Vector3d axis = pts[i].cross(Eigen::Vector3d::UnitZ()).normalized();
      EXPECT_LT((corrected[i] - Eigen::AngleAxisd(angle, axis) * pts[i]).norm(), 1e-12) << i;
    }
    EXPECT_EQ(corrected.back(), pts.back());
  }
}

TEST(PreprocessTest, AzimuthTimeFraction) {
  EXPECT_NEAR(AzimuthTimeFraction({10, 0, 0}), 0.0, 1e-7);    // Forward: the frame time.
  EXPECT_NEAR(AzimuthTimeFraction({0, 10, 0}), -0.25, 1e-7);  // Left: a quarter turn before.
  EXPECT_NEAR(AzimuthTimeFraction({0, -10, 0}), 0.25, 1e-7);
}

TEST(PreprocessTest, RadiusOutliersRemovedBothMethodsAgree) {
  std::vector<Eigen::Vector3d> pts;
  AddGround(5, 0.25, &pts);
  const size_t dense = pts.size();
  pts.emplace_back(0, -5, 0);  // Isolated points.
  pts.emplace_back(3, -8, 2);
  pts.emplace_back(3.3, -8, 2);  // A pair: one neighbour each, still below min 2.
  for (const std::string method : {"grid", "pcl"}) {
    const std::vector<uint8_t> keep = RadiusOutlierMask(pts, 0.6, 2, method, 2);
    for (size_t i = 0; i < dense; ++i) ASSERT_EQ(keep[i], 1) << method << " " << i;
    for (size_t i = dense; i < pts.size(); ++i) EXPECT_EQ(keep[i], 0) << method << " " << i;
  }
}

TEST(PreprocessTest, GroundPlaneFoundAndLabelled) {
  std::vector<Eigen::Vector3d> pts;
  AddGround(15, 0.3, &pts);
  const size_t ground = pts.size();
  for (double z = -10; z <= 10; z += 0.2) {  // A wall at x = 6.
    for (double y = -2; y <= 1.2; y += 0.2) pts.emplace_back(6, y, z);
  }
  PreprocessOptions o;
  Eigen::Vector4d plane;
  bool found = false;
  const std::vector<uint8_t> label = SegmentGround(pts, o, &plane, &found);
  ASSERT_TRUE(found);
  // n.p + d = 0 with n = +-y and d = -+1.7.
  EXPECT_NEAR(std::abs(plane[1]), 1.0, 1e-6);
  EXPECT_NEAR(plane[3] / plane[1], -1.7, 1e-6);
  const auto n_ground = std::count(label.begin(), label.begin() + ground, 1);
  const auto n_wall = std::count(label.begin() + ground, label.end(), 1);
  EXPECT_EQ(static_cast<size_t>(n_ground), ground);
  EXPECT_LT(n_wall, 60);  // Only the wall's bottom row (y = 1.6, 1.8 within 0.25 m).
}

TEST(PreprocessTest, SmallObjectsRemovedLargeStructuresKept) {
  std::vector<Eigen::Vector3d> pts;
  std::vector<uint8_t> is_ground;
  AddGround(20, 0.3, &pts);
  is_ground.assign(pts.size(), 1);
  const size_t n_ground = pts.size();
  // A building facade 30 m long (kept) and a car-sized box 4 x 1.5 x 1.8 m (removed).
  for (double z = -15; z <= 15; z += 0.2) {
    for (double y = -6; y <= 1.5; y += 0.2) pts.emplace_back(-8, y, z);
  }
  const size_t n_wall_end = pts.size();
  for (double x = 3; x <= 4.5; x += 0.2) {
    for (double z = 8; z <= 12; z += 0.2) {
      for (double y = -0.1; y <= 1.5; y += 0.4) pts.emplace_back(x, y, z);
    }
  }
  is_ground.resize(pts.size(), 0);
  PreprocessOptions o;
  int64_t removed = 0;
  const std::vector<uint8_t> keep = SmallObjectMask(pts, is_ground, o, &removed);
  EXPECT_EQ(removed, 1);
  for (size_t i = 0; i < n_wall_end; ++i) ASSERT_EQ(keep[i], 1) << i;
  for (size_t i = n_wall_end; i < pts.size(); ++i) ASSERT_EQ(keep[i], 0) << i;
  EXPECT_GT(n_ground, 0u);
}

TEST(PreprocessTest, EmptyAndTinyScansDoNotThrow) {
  const PreprocessedScan empty = PreprocessScan(PointCloud(), Rigid3d(), PreprocessOptions());
  EXPECT_TRUE(empty.points.empty());
  EXPECT_FALSE(empty.ground_found);
  PointCloud tiny;
  tiny.points = {{10, 0, 0}, {10, 0.1, 0}};
  const PreprocessedScan t = PreprocessScan(tiny, Rigid3d(), PreprocessOptions());
  EXPECT_LE(t.points.size(), 2u);
}

TEST(PreprocessTest, OptionsChecked) {
  PreprocessOptions o;
  o.min_range = -1;
  EXPECT_THROW(o.Check(), std::exception);
  o = PreprocessOptions();
  o.outlier_method = "kdtree";
  EXPECT_THROW(o.Check(), std::exception);
}

}  // namespace
}  // namespace jvl::lidar
