#include "io/kitti_raw.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/kitti.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

constexpr double kEarthRadius = 6378137.0;
constexpr double kLat0 = 49.0;

// Latitude whose Mercator y (with the scale of kLat0) is y0 + dy metres.
double LatitudeAt(double dy) {
  const double scale = std::cos(kLat0 * M_PI / 180.0);
  const double y0 = scale * kEarthRadius * std::log(std::tan((90.0 + kLat0) * M_PI / 360.0));
  return 360.0 / M_PI * std::atan(std::exp((y0 + dy) / (scale * kEarthRadius))) - 90.0;
}
double LongitudeAt(double dx) {
  const double scale = std::cos(kLat0 * M_PI / 180.0);
  return 8.4 + dx / (scale * kEarthRadius * M_PI / 180.0);
}

// A raw drive: 10 m east in 5 steps (heading east, yaw 0), a left turn of 90 degrees on the
// spot, then 6 m north in 3 steps, climbing 1 m on the last one. Velodyne axes are KITTI's
// (x forward, y left, z up), the IMU is aligned with the velodyne, R_rect is the identity.
class KittiRawTest : public ::testing::Test {
 protected:
  void SetUp() override {
    date_ = tmp_.path() / "2011_09_26";
    drive_ = date_ / "2011_09_26_drive_0001_sync";
    for (const char* sub : {"velodyne_points/data", "oxts/data", "image_00/data"})
      fs::create_directories(drive_ / sub);
    std::ofstream(date_ / "calib_cam_to_cam.txt")
        << "calib_time: 09-Jan-2012 13:57:47\n"
        << "S_rect_00: 1.242000e+03 3.750000e+02\n"
        << "R_rect_00: 1 0 0 0 1 0 0 0 1\n"
        << "P_rect_00: 721.5 0 609.5 0 0 721.5 172.8 0 0 0 1 0\n"
        << "P_rect_01: 721.5 0 609.5 -387.5 0 721.5 172.8 0 0 0 1 0\n"
        << "P_rect_02: 721.5 0 609.5 44.8 0 721.5 172.8 0.2 0 0 1 0.003\n"
        << "P_rect_03: 721.5 0 609.5 -339.5 0 721.5 172.8 2.2 0 0 1 0.003\n";
    std::ofstream(date_ / "calib_velo_to_cam.txt")
        << "calib_time: 15-Mar-2012 11:37:16\nR: 0 -1 0 0 0 -1 1 0 0\nT: 0 -0.08 -0.27\n";
    std::ofstream(date_ / "calib_imu_to_velo.txt")
        << "calib_time: 25-May-2012 16:47:16\nR: 1 0 0 0 1 0 0 0 1\nT: 0 0 0\n";
    struct P {
      double east, north, up, yaw;
    };
    std::vector<P> packets;
    for (int i = 0; i <= 5; ++i) packets.push_back({2.0 * i, 0, 0, 0});
    packets.push_back({10, 0, 0, M_PI / 2});
    for (int i = 1; i <= 3; ++i) packets.push_back({10, 2.0 * i, i == 3 ? 1.0 : 0.0, M_PI / 2});
    std::ofstream stamps(drive_ / "velodyne_points" / "timestamps.txt");
    for (size_t i = 0; i < packets.size(); ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010zu", i);
      std::ofstream oxts(drive_ / "oxts" / "data" / (std::string(name) + ".txt"));
      oxts.precision(17);
      oxts << LatitudeAt(packets[i].north) << " " << LongitudeAt(packets[i].east) << " "
           << 112.0 + packets[i].up << " 0 0 " << packets[i].yaw;
      for (int k = 6; k < 30; ++k) oxts << " 0";
      oxts << "\n";
      PointCloud cloud;
      cloud.points = {{10, 0, 0}};
      WriteVelodyneBin(
          (drive_ / "velodyne_points" / "data" / (std::string(name) + ".bin")).string(), cloud);
      char stamp[64];
      std::snprintf(stamp, sizeof(stamp), "2011-09-26 13:02:%02zu.%09d", 25 + i / 10,
                    static_cast<int>((i % 10) * 100000000 + 12345));
      stamps << stamp << "\n";
    }
  }
  TempDir tmp_{"jvl_raw"};
  fs::path date_, drive_;
};

TEST_F(KittiRawTest, DetectsFormatAndReadsCalibration) {
  const auto ds = OpenDataset(drive_.string());
  EXPECT_EQ(ds->format(), DatasetFormat::kKittiRaw);
  EXPECT_EQ(ds->frames().size(), 10u);
  EXPECT_EQ(ds->id().rfind("kitti-raw:2011_09_26_drive_0001_sync:", 0), 0u);
  const Calibration& c = ds->calibration();
  EXPECT_DOUBLE_EQ(c.P[0](0, 0), 721.5);
  EXPECT_DOUBLE_EQ(c.P[2](0, 3), 44.8);
  EXPECT_EQ(c.image_width, 1242);
  EXPECT_EQ(c.image_height, 375);
  // A point 10 m ahead of the velodyne is 10 m along the camera's z axis.
  const Eigen::Vector3d p = c.cam0_from_velo * Eigen::Vector3d(10, 0, 0);
  EXPECT_LT((p - Eigen::Vector3d(0, -0.08, 9.73)).norm(), 1e-12);
  EXPECT_EQ(ds->LoadScan(3).size(), 1u);
  EXPECT_NEAR(ds->timestamps()[1], 0.1, 1e-6);
  EXPECT_NEAR(ds->timestamps()[9], 0.9, 1e-6);
  // The same HDL-64E as the odometry sequences: --vertical-correction auto takes 0.205 deg.
  EXPECT_DOUBLE_EQ(ds->lidar_elevation_error_deg(), 0.205);
}

TEST_F(KittiRawTest, OxtsGroundTruthFollowsTheKnownPath) {
  const auto ds = OpenDataset(drive_.string());
  ASSERT_TRUE(ds->ground_truth().has_value());
  const Trajectory& gt = *ds->ground_truth();
  ASSERT_EQ(gt.size(), 10u);
  // Frame 0 is the origin.
  EXPECT_LT(gt.world_from_cam[0].translation().norm(), 1e-9);
  // Straight east = straight ahead along the camera's z axis, 2 m per frame.
  for (int i = 0; i <= 5; ++i) {
    EXPECT_NEAR(gt.world_from_cam[i].translation().z(), 2.0 * i, 1e-6) << i;
    EXPECT_NEAR(gt.world_from_cam[i].translation().x(), 0.0, 1e-6) << i;
    EXPECT_LT(RotationAngle(gt.world_from_cam[i].rotation()), 1e-9);
  }
  // After the left turn the camera looks along world -x (to the left of the start).
  const Eigen::Vector3d forward = gt.world_from_cam[6].rotation() * Eigen::Vector3d::UnitZ();
  EXPECT_LT((forward - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-9);
  // North = to the left = camera -x; 1 m climb = camera -y. The camera centre sits 0.27 m
  // ahead of the IMU along the velodyne x axis, which the turn swings around.
  const Eigen::Vector3d c9 = gt.world_from_cam[9].translation();
  // Camera centre in the IMU frame: -R^T T = (0.27, 0, -0.08); after the turn it points north.
  EXPECT_NEAR(c9.x(), -6.27, 1e-5);
  EXPECT_NEAR(c9.y(), -1.0, 1e-5);
  EXPECT_NEAR(c9.z(), 9.73, 1e-5);
  const Eigen::Vector3d c6 = gt.world_from_cam[6].translation();
  EXPECT_NEAR((c9 - c6).norm(), std::sqrt(36.0 + 1.0), 1e-5);
}

TEST(KittiRawParseTest, TimestampsAndPackets) {
  const double a = ParseKittiRawTimestamp("2011-09-26 13:02:25.964389445", "t");
  const double b = ParseKittiRawTimestamp("2011-09-26 13:02:26.064389445", "t");
  EXPECT_NEAR(b - a, 0.1, 1e-6);
  // 2011-09-26 is day 15243 after 1970-01-01.
  EXPECT_NEAR(ParseKittiRawTimestamp("2011-09-26 00:00:00.0", "t"), 15243.0 * 86400.0, 1e-3);
  EXPECT_THROW(ParseKittiRawTimestamp("yesterday", "t"), Error);
  EXPECT_THROW(ParseOxtsPacket("49.0 8.4 112", "p"), Error);
  const OxtsPacket p = ParseOxtsPacket("49.5 8.25 110.5 0.01 -0.02 1.5 0 0", "p");
  EXPECT_DOUBLE_EQ(p.yaw, 1.5);
}

TEST_F(KittiRawTest, MissingCalibrationIsNamed) {
  fs::remove(date_ / "calib_velo_to_cam.txt");
  try {
    OpenDataset(drive_.string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(e.message().find("calib_velo_to_cam.txt"), std::string::npos) << e.message();
  }
}

}  // namespace
}  // namespace jvl::io
