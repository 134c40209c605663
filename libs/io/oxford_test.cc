#include "io/oxford.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/check.h"
#include "io/files.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

constexpr int kW = 80, kH = 64;
constexpr int64_t kT0 = 1547131046000000;  // µs

void WriteBytes(const fs::path& path, const void* data, size_t size) {
  std::ofstream(path, std::ios::binary).write(static_cast<const char*>(data), size);
}

// A traversal of six centre-camera frames (16 Hz) and eight left-Velodyne sweeps (20 Hz), with
// the SDK's extrinsics/ and models/ one folder above it. The car drives north at 10 m/s with
// the vehicle frame (x forward, y right, z down) level. The Velodyne sits as on the real car:
// behind and above the camera, its x axis pointing backwards (yaw -pi) and z down. The images
// hold a grey ramp (value = column) as a GBRG mosaic; the undistortion table samples each pixel
// one column to the right.
class OxfordTest : public ::testing::Test {
 protected:
  void SetUp() override {
    sdk_ = fs::temp_directory_path() / ("jvl_oxford_" + std::to_string(::getpid()));
    dir_ = sdk_ / "2019-01-10-14-36-48-radar-oxford-10k";
    for (const fs::path& d : {dir_ / "stereo" / "centre", dir_ / "velodyne_left", dir_ / "gps",
                              sdk_ / "extrinsics", sdk_ / "models"})
      fs::create_directories(d);
    std::ofstream(sdk_ / "models" / "stereo_narrow_left.txt")
        << "100.0 100.0 40.0 32.0\n0 0 1 0\n1 0 0 0\n0 1 0 0\n0 0 0 1\n";
    std::vector<double> lut(2 * kW * kH);
    for (int r = 0; r < kH; ++r)
      for (int c = 0; c < kW; ++c) {
        lut[r * kW + c] = c + 1.0;
        lut[kW * kH + r * kW + c] = r;
      }
    WriteBytes(sdk_ / "models" / "stereo_narrow_left_distortion_lut.bin", lut.data(),
               lut.size() * sizeof(double));
    std::ofstream(sdk_ / "extrinsics" / "velodyne_left.txt")
        << "-0.6 -0.34 -0.27 0 0 -3.141592653589793\n";
    std::ofstream(sdk_ / "extrinsics" / "ins.txt") << "-1.71 0.12 1.19 0 0 0";
    cv::Mat ramp(kH, kW, CV_8UC1);
    for (int r = 0; r < kH; ++r)
      for (int c = 0; c < kW; ++c) ramp.at<uint8_t>(r, c) = static_cast<uint8_t>(c);
    std::ofstream cams(dir_ / "stereo.timestamps");
    for (int i = 0; i < 6; ++i) {
      const int64_t t = kT0 + 62500 * i;
      cams << t << " 1\n";
      cv::imwrite((dir_ / "stereo" / "centre" / (std::to_string(t) + ".png")).string(), ramp);
    }
    std::ofstream velo(dir_ / "velodyne_left.timestamps");
    for (int k = 0; k < 8; ++k) {
      const int64_t t = kT0 + 10000 + 50000 * k;
      velo << t << " 1\n";
      // Points in the sensor frame, planar: x..., y..., z..., intensity...
      const float v[12] = {-10, 0, 0, /*y*/ 0, 3, 0, /*z*/ 0, 0, 2, /*i*/ 255, 0, 51};
      WriteBytes(dir_ / "velodyne_left" / (std::to_string(t) + ".bin"), v, sizeof(v));
    }
    std::ofstream ins(dir_ / "gps" / "ins.csv");
    ins << "timestamp,ins_status,latitude,longitude,altitude,northing,easting,down,utm_zone,"
           "velocity_north,velocity_east,velocity_down,roll,pitch,yaw\n";
    ins.precision(17);
    for (int j = 0; j < 7; ++j) {
      ins << kT0 - 100000 + 100000 * j << ",INS_SOLUTION_GOOD,51.76,-1.26,110.0,"
          << 5735000.0 + 1.0 * j << ",620000.0,-100.0,30U,10,0,0,0,0,0\n";
    }
  }
  void TearDown() override { fs::remove_all(sdk_); }
  fs::path sdk_, dir_;
};

TEST_F(OxfordTest, ReadsFramesCalibrationAndPairsSweeps) {
  EXPECT_EQ(DetectDatasetFormat(dir_.string()), DatasetFormat::kOxford);
  const auto ds = OpenDataset(dir_.string());
  EXPECT_EQ(ds->format(), DatasetFormat::kOxford);
  EXPECT_FALSE(ds->scans_motion_compensated());
  ASSERT_EQ(ds->frames().size(), 6u);
  EXPECT_NEAR(ds->timestamps()[4], 0.25, 1e-12);
  const Calibration& c = ds->calibration();
  EXPECT_DOUBLE_EQ(c.P[0](0, 0), 100.0);
  EXPECT_DOUBLE_EQ(c.P[0](1, 2), 32.0);
  EXPECT_EQ(c.image_width, kW);
  EXPECT_EQ(c.image_height, kH);
  // Frame 1 (62.5 ms) pairs with the sweep at 60 ms, frame 5 (312.5 ms) with 310 ms.
  EXPECT_EQ(fs::path(ds->ScanPath(1)).filename(), std::to_string(kT0 + 60000) + ".bin");
  EXPECT_EQ(fs::path(ds->ScanPath(5)).filename(), std::to_string(kT0 + 310000) + ".bin");
  // The scan in the tools' axes (x forward, y left, z up) at the LiDAR: the sensor's -x is
  // ahead, its +y is to the left, its +z below.
  const PointCloud scan = ds->LoadScan(2);
  ASSERT_EQ(scan.size(), 3u);
  EXPECT_LT((scan.points[0] - Eigen::Vector3d(10, 0, 0)).norm(), 1e-6);
  EXPECT_LT((scan.points[1] - Eigen::Vector3d(0, 3, 0)).norm(), 1e-6);
  EXPECT_LT((scan.points[2] - Eigen::Vector3d(0, 0, -2)).norm(), 1e-6);
  EXPECT_NEAR(scan.intensity[0], 1.0, 1e-6);
  EXPECT_NEAR(scan.intensity[2], 0.2, 1e-6);
  // 10 m ahead of the LiDAR, which is 0.6 m behind, 0.34 m left and 0.27 m above the camera.
  const Eigen::Vector3d p = c.cam0_from_velo * scan.points[0];
  EXPECT_LT((p - Eigen::Vector3d(-0.34, -0.27, 9.4)).norm(), 1e-9);
}

TEST_F(OxfordTest, ImagesAreDemosaicedAndUndistortedWithTheTable) {
  const auto ds = OpenDataset(dir_.string());
  const cv::Mat img = ds->LoadImage(3, 0);
  ASSERT_EQ(img.type(), CV_8UC1);
  ASSERT_EQ(img.cols, kW);
  // The ramp, sampled one column to the right.
  for (int c = 4; c < kW - 4; c += 7) EXPECT_NEAR(img.at<uint8_t>(kH / 2, c), c + 1, 1) << c;
  EXPECT_THROW(ds->LoadImage(3, 1), Error);
}

TEST_F(OxfordTest, GroundTruthIsTheInterpolatedInsPoseOfTheCamera) {
  const auto ds = OpenDataset(dir_.string());
  ASSERT_TRUE(ds->ground_truth().has_value());
  const Trajectory& gt = *ds->ground_truth();
  ASSERT_EQ(gt.size(), 6u);
  // North at 10 m/s = along the camera's optical axis, 0.625 m per frame, level.
  for (size_t i = 0; i < gt.size(); ++i) {
    EXPECT_LT((gt.world_from_cam[i].translation() - Eigen::Vector3d(0, 0, 0.625 * i)).norm(), 1e-6)
        << i;
    EXPECT_LT(RotationAngle(gt.world_from_cam[i].rotation()), 1e-9) << i;
  }
}

TEST_F(OxfordTest, MissingOrMalformedFilesAreNamed) {
  auto expect_error = [](const auto& f, const std::string& needle) {
    try {
      f();
      ADD_FAILURE() << "no error, expected one naming " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  std::ofstream(sdk_ / "models" / "stereo_narrow_left_distortion_lut.bin") << "short";
  expect_error([&] { OpenDataset(dir_.string()); }, "stereo_narrow_left_distortion_lut.bin");
  fs::remove(sdk_ / "extrinsics" / "velodyne_left.txt");
  expect_error([&] { OpenDataset(dir_.string()); }, "extrinsics/velodyne_left.txt");
  std::ofstream(dir_ / "stereo.timestamps") << "12 1\n11 1\n";
  expect_error([&] { OpenDataset(dir_.string()); }, "not after the previous");
  // A sweep farther than 40 ms from every image: the frame has no scan.
  EXPECT_EQ(NearestTime({100, 200, 300}, 260), 2);
  EXPECT_EQ(NearestTime({100, 200, 300}, 250), 1);
  EXPECT_EQ(NearestTime({}, 5), -1);
}

TEST(OxfordSe3, RollPitchYawOrder) {
  // R = Rz(yaw) Ry(pitch) Rx(roll): a quarter yaw turns x into y whatever the roll.
  const Rigid3d t = OxfordSe3(1, 2, 3, M_PI / 2, 0, M_PI / 2);
  EXPECT_LT((t.RotationMatrix() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(),
            1e-12);
  EXPECT_LT((t.RotationMatrix() * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(),
            1e-12);
  EXPECT_LT((t.translation() - Eigen::Vector3d(1, 2, 3)).norm(), 1e-12);
}

}  // namespace
}  // namespace jvl::io
