#include "io/oxford.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/check.h"
#include "core/temp_dir.h"
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
    sdk_ = tmp_.path();
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
  TempDir tmp_{"jvl_oxford"};
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

// A raw sweep of three columns (azimuths 0, 90 and 180 degrees) with three returns: laser 8
// (elevation 0) at 10 m in column 0, laser 0 (elevation -0.1862) at 5 m in column 1, and laser
// 31 at 1 m in column 2 (not longer than the minimum range: dropped). Byte pairs are
// little-endian; the column times are kT0 + 1000 c + 2^40 (the high bytes matter).
cv::Mat RawSweep() {
  cv::Mat raw(kOxfordRawSweepRows, 3, CV_8UC1, cv::Scalar(0));
  const auto put16 = [&](int row, int col, uint16_t v) {
    raw.at<uint8_t>(row, col) = static_cast<uint8_t>(v & 0xff);
    raw.at<uint8_t>(row + 1, col) = static_cast<uint8_t>(v >> 8);
  };
  for (int c = 0; c < 3; ++c) {
    put16(96, c, static_cast<uint16_t>(9000 * c));  // 1/100 degree
    const uint64_t t = static_cast<uint64_t>(kT0) + 1000 * c + (uint64_t{1} << 40);
    for (int b = 0; b < 8; ++b) raw.at<uint8_t>(98 + b, c) = static_cast<uint8_t>(t >> (8 * b));
  }
  put16(32 + 2 * 8, 0, 5000);  // 10 m in 2 mm units
  raw.at<uint8_t>(8, 0) = 255;
  put16(32 + 2 * 0, 1, 2500);  // 5 m
  raw.at<uint8_t>(0, 1) = 51;
  put16(32 + 2 * 31, 2, 500);  // 1 m: not valid
  raw.at<uint8_t>(31, 2) = 7;
  return raw;
}

TEST_F(OxfordTest, RawPngSweepsAreDecodedAsTheSdkDoes) {
  const fs::path png = dir_ / "velodyne_left" / "raw.png";
  cv::imwrite(png.string(), RawSweep());
  std::vector<int64_t> times;
  const PointCloud cloud = ReadOxfordVelodynePng(png.string(), &times);
  ASSERT_EQ(cloud.size(), 2u);
  // Laser by laser: laser 0 (column 1) first. x = sin(az) r cos(el), y = -cos(az) r cos(el),
  // z = r sin(el) - 0.090805.
  const double el = -0.1862;
  EXPECT_LT(
      (cloud.points[0] - Eigen::Vector3d(5 * std::cos(el), 0, 5 * std::sin(el) - 0.090805)).norm(),
      1e-12);
  EXPECT_LT((cloud.points[1] - Eigen::Vector3d(0, -10, -0.090805)).norm(), 1e-12);
  EXPECT_NEAR(cloud.intensity[0], 0.2, 1e-6);
  EXPECT_NEAR(cloud.intensity[1], 1.0, 1e-6);
  ASSERT_EQ(times.size(), 2u);
  EXPECT_EQ(times[0], kT0 + 1000 + (int64_t{1} << 40));
  EXPECT_EQ(times[1], kT0 + (int64_t{1} << 40));

  // In a traversal: the .png is read when there is no .bin, the .bin wins when both exist.
  const std::string t2 = std::to_string(kT0 + 110000);  // the sweep of frame 2
  cv::imwrite((dir_ / "velodyne_left" / (t2 + ".png")).string(), RawSweep());
  const auto ds = OpenDataset(dir_.string());
  EXPECT_EQ(ds->LoadScan(2).size(), 3u);  // the .bin's three points
  fs::remove(dir_ / "velodyne_left" / (t2 + ".bin"));
  EXPECT_EQ(fs::path(ds->ScanPath(2)).filename(), t2 + ".png");
  const PointCloud scan = ds->LoadScan(2);
  ASSERT_EQ(scan.size(), 2u);
  // The sensor (yaw -pi, z down) sees column 0's return 10 m along its -y: the vehicle's right,
  // -y in the tools' axes; the firing height below the base is above it once z points up.
  EXPECT_LT((scan.points[1] - Eigen::Vector3d(0, -10, 0.090805)).norm(), 1e-9);

  // Malformed sweeps are named.
  cv::imwrite(png.string(), cv::Mat(40, 3, CV_8UC1, cv::Scalar(0)));
  try {
    ReadOxfordVelodynePng(png.string());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("raw.png: 40 rows, expected 106"), std::string::npos)
        << e.what();
  }
  std::ofstream(png) << "not a png";
  EXPECT_THROW(ReadOxfordVelodynePng(png.string()), Error);
  fs::remove(dir_ / "velodyne_left" / (t2 + ".png"));
  EXPECT_THROW(ds->LoadScan(2), Error);
}

// The right Velodyne: 0.9 m to the right of the left one, as on the car, oriented as it, with
// sweeps at 30 ms + 50 ms k (20 ms after the left ones). Its sensor-frame point (-10, 0, 0) is
// 10 m ahead, (0, 0, 1) 1 m below it.
void AddRightVelodyne(const fs::path& sdk, const fs::path& dir) {
  fs::create_directories(dir / "velodyne_right");
  std::ofstream(sdk / "extrinsics" / "velodyne_right.txt")
      << "-0.6 0.56 -0.27 0 0 -3.141592653589793\n";
  std::ofstream stamps(dir / "velodyne_right.timestamps");
  for (int k = 0; k < 8; ++k) {
    const int64_t t = kT0 + 30000 + 50000 * k;
    stamps << t << " 1\n";
    const float v[8] = {-10, 0, /*y*/ 0, 0, /*z*/ 0, 1, /*i*/ 255, 255};
    WriteBytes(dir / "velodyne_right" / (std::to_string(t) + ".bin"), v, sizeof(v));
  }
}

TEST_F(OxfordTest, RightVelodyneAndBothMerged) {
  AddRightVelodyne(sdk_, dir_);
  DatasetOptions right;
  right.lidar = "right";
  const auto r = OpenDataset(dir_.string(), right);
  // Frame 2 (125 ms) pairs with the right sweep at 130 ms.
  EXPECT_EQ(fs::path(r->ScanPath(2)).filename(), std::to_string(kT0 + 130000) + ".bin");
  EXPECT_EQ(fs::path(r->ScanPath(2)).parent_path().filename(), "velodyne_right");
  const PointCloud rs = r->LoadScan(2);
  ASSERT_EQ(rs.size(), 2u);
  EXPECT_LT((rs.points[0] - Eigen::Vector3d(10, 0, 0)).norm(), 1e-9);
  // 10 m ahead of the right LiDAR: 0.56 m right of and 0.27 m above the camera.
  EXPECT_LT(
      (r->calibration().cam0_from_velo * rs.points[0] - Eigen::Vector3d(0.56, -0.27, 9.4)).norm(),
      1e-9);
  EXPECT_NE(r->id(), OpenDataset(dir_.string())->id());

  DatasetOptions both;
  both.lidar = "both";
  const auto b = OpenDataset(dir_.string(), both);
  const auto left = OpenDataset(dir_.string());
  EXPECT_LT((b->calibration().cam0_from_velo.translation() -
             left->calibration().cam0_from_velo.translation())
                .norm(),
            1e-15);
  EXPECT_EQ(b->ScanPath(2), left->ScanPath(2));
  const PointCloud bs = b->LoadScan(2);
  ASSERT_EQ(bs.size(), 5u);  // the left sweep's three points, then the right one's two
  const PointCloud ls = left->LoadScan(2);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(bs.points[i], ls.points[i]);
  // The right sweep in the left one's frame: 10 m ahead, 0.9 m to the right (y left: -0.9).
  EXPECT_LT((bs.points[3] - Eigen::Vector3d(10, -0.9, 0)).norm(), 1e-9);
  EXPECT_LT((bs.points[4] - Eigen::Vector3d(0, -0.9, -1)).norm(), 1e-9);
  EXPECT_LT(
      (b->calibration().cam0_from_velo * bs.points[3] - Eigen::Vector3d(0.56, -0.27, 9.4)).norm(),
      1e-9);
}

TEST_F(OxfordTest, LidarOptionErrorsAreOneLineAndNamed) {
  auto message = [](const auto& f) {
    try {
      f();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  DatasetOptions right;
  right.lidar = "right";
  EXPECT_NE(message([&] { OpenDataset(dir_.string(), right); }).find("velodyne_right.timestamps"),
            std::string::npos);
  DatasetOptions top;
  top.lidar = "top";
  EXPECT_NE(message([&] { OpenDataset(dir_.string(), top); }).find("--lidar: expected"),
            std::string::npos);
  DatasetOptions radar;
  radar.ground_truth = "radar";
  EXPECT_NE(message([&] { OpenDataset(dir_.string(), radar); }).find("gt/radar_odometry.csv"),
            std::string::npos);
  // A layout with one LiDAR refuses the option, naming it and the layout.
  const fs::path kitti = sdk_ / "kitti" / "00";
  fs::create_directories(kitti / "velodyne");
  std::ofstream(kitti / "calib.txt") << "";
  const std::string e = message([&] { OpenDataset(kitti.string(), right); });
  EXPECT_NE(e.find("--lidar right"), std::string::npos) << e;
  EXPECT_NE(e.find("kitti dataset"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  EXPECT_NE(message([&] { OpenDataset(kitti.string(), radar); }).find("--gt-source radar"),
            std::string::npos);
}

TEST_F(OxfordTest, ScanTimeOffsetsAreSweepMinusImageTimes) {
  const auto ds = OpenDataset(dir_.string());
  ASSERT_EQ(ds->scan_time_offsets().size(), 6u);
  // Frame 0 (0 ms) has the sweep at 10 ms, frame 1 (62.5 ms) the one at 60 ms.
  EXPECT_NEAR(ds->scan_time_offsets()[0], 0.010, 1e-12);
  EXPECT_NEAR(ds->scan_time_offsets()[1], -0.0025, 1e-12);
  EXPECT_NEAR(ds->ScanTimeOffsetInFrames(0), 0.010 / 0.0625, 1e-9);
  EXPECT_NEAR(ds->ScanTimeOffsetInFrames(1), -0.0025 / 0.0625, 1e-9);
}

// The same drive written as gps/ins.csv and as gt/radar_odometry.csv (the radar poses
// P_ins T(ins)^-1 T(radar), as relative poses of the later in the earlier), sampled at the image
// times: both give the same world_from_cam0. The car turns left (yaw -0.1 rad per frame, NED)
// while driving north-east and climbing.
TEST_F(OxfordTest, RadarOdometryGroundTruthMatchesTheInsOne) {
  std::ofstream(sdk_ / "extrinsics" / "radar.txt") << "-0.71813 0.12 -0.54479 0 0.05 0\n";
  const Rigid3d ins_ext = OxfordSe3(-1.71, 0.12, 1.19, 0, 0, 0);
  const Rigid3d radar_ext = OxfordSe3(-0.71813, 0.12, -0.54479, 0, 0.05, 0);
  std::vector<int64_t> times;
  std::vector<Rigid3d> ned_from_ins;
  for (int j = 0; j < 8; ++j) {
    times.push_back(kT0 - 62500 + 62500 * j);
    ned_from_ins.push_back(OxfordSe3(5735000.0 + 0.6 * j, 620000.0 + 0.2 * j, -100.0 - 0.01 * j,
                                     0.01 * j, -0.02, 0.3 - 0.1 * j));
  }
  {
    std::ofstream ins(dir_ / "gps" / "ins.csv");
    ins << "timestamp,ins_status,latitude,longitude,altitude,northing,easting,down,utm_zone,"
           "velocity_north,velocity_east,velocity_down,roll,pitch,yaw\n";
    ins.precision(17);
    for (size_t j = 0; j < times.size(); ++j) {
      const auto v = OxfordXyzRpy(ned_from_ins[j]);
      ins << times[j] << ",INS_SOLUTION_GOOD,51.76,-1.26,110.0," << v[0] << "," << v[1] << ","
          << v[2] << ",30U,0,0,0," << v[3] << "," << v[4] << "," << v[5] << "\n";
    }
  }
  fs::create_directories(dir_ / "gt");
  const auto write_radar = [&](int broken_row) {
    std::ofstream radar(dir_ / "gt" / "radar_odometry.csv");
    radar << "source_timestamp,destination_timestamp,x,y,z,roll,pitch,yaw,"
             "source_radar_timestamp,destination_radar_timestamp\n";
    radar.precision(17);
    for (size_t j = 0; j + 1 < times.size(); ++j) {
      const Rigid3d a = ned_from_ins[j] * ins_ext.Inverse() * radar_ext;
      const Rigid3d b = ned_from_ins[j + 1] * ins_ext.Inverse() * radar_ext;
      const auto v = OxfordXyzRpy(a.Inverse() * b);
      const int64_t destination = times[j] + (static_cast<int>(j) == broken_row ? 1 : 0);
      radar << times[j + 1] << "," << destination << "," << v[0] << "," << v[1] << "," << v[2]
            << "," << v[3] << "," << v[4] << "," << v[5] << "," << times[j + 1] - 1000 << ","
            << times[j] - 1000 << "\n";
    }
  };
  write_radar(-1);
  DatasetOptions ins_options, radar_options;
  ins_options.ground_truth = "ins";
  radar_options.ground_truth = "radar";
  const auto from_ins = OpenDataset(dir_.string(), ins_options);
  const auto from_radar = OpenDataset(dir_.string(), radar_options);
  ASSERT_TRUE(from_ins->ground_truth() && from_radar->ground_truth());
  const Trajectory& a = *from_ins->ground_truth();
  const Trajectory& b = *from_radar->ground_truth();
  ASSERT_EQ(a.size(), 6u);
  ASSERT_EQ(b.size(), 6u);
  double path = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.frames[i], b.frames[i]);
    // 1e-7 m: the northings of 5.7e6 m carry 1e-9 m of rounding each.
    EXPECT_LT((a.world_from_cam[i].translation() - b.world_from_cam[i].translation()).norm(), 1e-7)
        << i;
    EXPECT_LT(
        RotationAngle(a.world_from_cam[i].rotation().inverse() * b.world_from_cam[i].rotation()),
        1e-9)
        << i;
    if (i > 0) {
      path += (a.world_from_cam[i].translation() - a.world_from_cam[i - 1].translation()).norm();
    }
  }
  EXPECT_GT(path, 2.0);  // the drive moves: the comparison is not between two identities
  EXPECT_GT(RotationAngle(a.world_from_cam.back().rotation()), 0.4);
  // The default: the INS when present, else the radar odometry.
  EXPECT_NE(from_ins->id(), from_radar->id());
  EXPECT_EQ(OpenDataset(dir_.string())->id(), from_ins->id());
  fs::remove(dir_ / "gps" / "ins.csv");
  EXPECT_EQ(OpenDataset(dir_.string())->id(), from_radar->id());
  EXPECT_THROW(OpenDataset(dir_.string(), ins_options), Error);
  // A broken chain is named by file and line.
  write_radar(3);
  try {
    OpenDataset(dir_.string());
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("radar_odometry.csv, line 5: destination_timestamp"), std::string::npos) << m;
  }
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
