#include "io/dataset.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/files.h"
#include "io/kitti.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

const std::string kSeq04 =
    std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50/sequences/04";

#define SKIP_WITHOUT_SHARED()                                                        \
  if (!IsDirectory(kSeq04)) {                                                        \
    GTEST_SKIP() << "real KITTI data not found at " << kSeq04                        \
                 << " (../shared/data is only present in the development checkout)"; \
  }

TEST(KittiOdometryTest, ReadsSequence04Frames0To50) {
  SKIP_WITHOUT_SHARED();
  const auto ds = OpenDataset(kSeq04);
  EXPECT_EQ(ds->format(), DatasetFormat::kKittiOdometry);
  ASSERT_EQ(ds->frames().size(), 51u);
  EXPECT_EQ(ds->frames().front(), 0);
  EXPECT_EQ(ds->frames().back(), 50);
  EXPECT_EQ(ds->id().rfind("kitti:04:", 0), 0u) << ds->id();
  // times.txt covers all 271 frames of 04; the selected ones are read.
  EXPECT_NEAR(ds->timestamps()[1], 0.1041284, 1e-12);

  const Calibration& c = ds->calibration();
  EXPECT_DOUBLE_EQ(c.P[0](0, 0), 707.0912);
  EXPECT_DOUBLE_EQ(c.P[0](0, 2), 601.8873);
  EXPECT_DOUBLE_EQ(c.P[0](1, 2), 183.1104);
  EXPECT_DOUBLE_EQ(c.P[1](0, 3), -379.8145);
  EXPECT_EQ(c.image_width, 1226);
  EXPECT_EQ(c.image_height, 370);
  const Eigen::Matrix<double, 3, 4> tr = c.cam0_from_velo.Matrix3x4();
  // Tr is projected onto SO(3); the text matrix is orthonormal only to ~2e-9.
  EXPECT_NEAR(tr(0, 1), -9.999659513510e-01, 1e-8);
  EXPECT_NEAR(tr(2, 3), -3.339968064433e-01, 1e-12);

  ASSERT_TRUE(ds->ground_truth().has_value());
  const Trajectory& gt = *ds->ground_truth();
  ASSERT_EQ(gt.size(), 51u);
  EXPECT_NEAR(gt.world_from_cam[50].translation().z(), 69.11593, 1e-9);
  EXPECT_NEAR(gt.world_from_cam[1].translation().y(), -1.821616e-02, 1e-12);

  // Point counts are file size / 16; the camera sees the expected image.
  for (int64_t f : {0, 1, 50}) {
    size_t dropped = 99;
    const PointCloud scan = ds->LoadScan(f, &dropped);
    EXPECT_EQ(static_cast<int64_t>(scan.size() + dropped), FileSize(ds->ScanPath(f)) / 16);
    EXPECT_EQ(dropped, 0u);
    EXPECT_GT(scan.size(), 100000u);
  }
  const cv::Mat image = ds->LoadImage(7);
  EXPECT_EQ(image.cols, 1226);
  EXPECT_EQ(image.rows, 370);
  EXPECT_EQ(image.type(), CV_8UC1);
}

TEST(KittiOdometryTest, FrameRangeSelection) {
  SKIP_WITHOUT_SHARED();
  const auto ds = OpenDataset(kSeq04, DatasetFormat::kAuto, ParseFrameRange("10:20"));
  ASSERT_EQ(ds->frames().size(), 10u);
  EXPECT_EQ(ds->frames().front(), 10);
  EXPECT_EQ(ds->ground_truth()->frames.front(), 10);
  EXPECT_THROW(OpenDataset(kSeq04, DatasetFormat::kAuto, ParseFrameRange("100:200")), Error);
}

// A tiny sequence folder written with the project's own writers, broken in various ways.
class BadDatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = tmp_.path();
    seq_ = root_ / "sequences" / "07";
    fs::create_directories(seq_ / "velodyne");
    Calibration calib;
    for (int i = 0; i < 4; ++i) {
      calib.P[i].setZero();
      calib.P[i](0, 0) = calib.P[i](1, 1) = 700;
      calib.P[i](0, 2) = 600;
      calib.P[i](1, 2) = 180;
      calib.P[i](2, 2) = 1;
    }
    WriteKittiCalibration((seq_ / "calib.txt").string(), calib);
    WriteKittiTimes((seq_ / "times.txt").string(), {0.0, 0.1, 0.2});
    PointCloud cloud;
    cloud.points = {{1, 2, 3}, {4, 5, 6}};
    cloud.intensity = {0.5f, 0.25f};
    for (int f = 0; f < 3; ++f) WriteVelodyneBin(Scan(f), cloud);
  }
  std::string Scan(int f) const {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d.bin", f);
    return (seq_ / "velodyne" / name).string();
  }
  std::string ErrorOf(const std::function<void()>& fn) {
    try {
      fn();
    } catch (const Error& e) {
      return e.message();
    }
    return "<no error>";
  }
  TempDir tmp_{"jvl_bad_ds"};
  fs::path root_, seq_;
};

TEST_F(BadDatasetTest, ReadsTheGoodFolder) {
  const auto ds = OpenDataset(seq_.string());
  EXPECT_EQ(ds->frames().size(), 3u);
  const PointCloud c = ds->LoadScan(2);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[1], Eigen::Vector3d(4, 5, 6));
  EXPECT_FLOAT_EQ(c.intensity[0], 0.5f);
  EXPECT_FALSE(ds->ground_truth().has_value());
}

// A colour-only download (image_2 and image_3, no image_0): the image size comes from camera
// 2's images, colour is converted to grey (OpenCV's 0.299 R + 0.587 G + 0.114 B), and cameras
// without images or projection are refused in one line.
TEST_F(BadDatasetTest, ColourCameraImagesAreReadAsGrey) {
  fs::create_directories(seq_ / "image_2");
  cv::Mat colour(80, 96, CV_8UC3, cv::Scalar(0, 0, 0));
  colour(cv::Rect(0, 0, 48, 80)).setTo(cv::Scalar(255, 0, 0));   // blue (BGR)
  colour(cv::Rect(48, 0, 48, 80)).setTo(cv::Scalar(0, 0, 200));  // red
  for (int f = 0; f < 3; ++f) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d.png", f);
    cv::imwrite((seq_ / "image_2" / name).string(), colour);
  }
  const auto ds = OpenDataset(seq_.string());
  EXPECT_EQ(ds->calibration().image_width, 96);
  EXPECT_EQ(ds->calibration().image_height, 80);
  EXPECT_NO_THROW(ds->CheckCamera(2));
  const cv::Mat grey = ds->LoadImage(1, 2);
  ASSERT_EQ(grey.type(), CV_8UC1);
  EXPECT_NEAR(grey.at<uint8_t>(10, 10), 0.114 * 255, 1.0);
  EXPECT_NEAR(grey.at<uint8_t>(10, 60), 0.299 * 200, 1.0);
  EXPECT_NE(ErrorOf([&] { ds->LoadImage(1, 0); }).find("missing image of camera 0 for frame 1"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ds->CheckCamera(5); }).find("--camera 5 is not a camera"),
            std::string::npos);
  // A camera without images is refused before any work, naming the first selected frame.
  EXPECT_NE(ErrorOf([&] {
              ds->CheckCamera(0);
            }).find("image_0/000000.png: missing image of camera 0 for frame 0"),
            std::string::npos);
}

// KITTI odometry scans are motion-compensated; a sim_sequence folder says in sim/scene.json.
TEST_F(BadDatasetTest, MotionCompensationFromTheSimulatorsSceneAndDeskewModes) {
  EXPECT_TRUE(OpenDataset(seq_.string())->scans_motion_compensated());
  fs::create_directories(seq_ / "sim");
  std::ofstream((seq_ / "sim" / "scene.json").string())
      << R"({"lidar": {"motion_distortion": true}})";
  const auto raw = OpenDataset(seq_.string());
  EXPECT_FALSE(raw->scans_motion_compensated());
  EXPECT_TRUE(ResolveDeskew("auto", *raw));
  EXPECT_FALSE(ResolveDeskew("off", *raw));
  std::ofstream((seq_ / "sim" / "scene.json").string())
      << R"({"lidar": {"motion_distortion": false}})";
  const auto compensated = OpenDataset(seq_.string());
  EXPECT_TRUE(compensated->scans_motion_compensated());
  EXPECT_FALSE(ResolveDeskew("auto", *compensated));
  EXPECT_TRUE(ResolveDeskew("on", *compensated));
  EXPECT_NE(ErrorOf([&] { ResolveDeskew("yes", *compensated); }).find("auto, on or off"),
            std::string::npos);
  // An unreadable scene file is logged and taken as compensated, not an error.
  std::ofstream((seq_ / "sim" / "scene.json").string()) << "{not json";
  EXPECT_TRUE(OpenDataset(seq_.string())->scans_motion_compensated());
}

// --vertical-correction auto: KITTI's published 0.205 deg on a KITTI odometry folder, none on a
// sim_sequence folder of the same layout (its error is the simulator's own); a number is taken
// as given, anything else is a one-line error.
TEST_F(BadDatasetTest, VerticalCorrectionAutoIsKittisPublishedErrorAndNoneOnSimulatedDrives) {
  const auto kitti = OpenDataset(seq_.string());
  EXPECT_DOUBLE_EQ(kitti->lidar_elevation_error_deg(), 0.205);
  EXPECT_DOUBLE_EQ(ResolveVerticalCorrection("auto", *kitti), 0.205);
  EXPECT_DOUBLE_EQ(ResolveVerticalCorrection("0", *kitti), 0.0);
  EXPECT_DOUBLE_EQ(ResolveVerticalCorrection("-0.12", *kitti), -0.12);
  EXPECT_NE(ErrorOf([&] {
              ResolveVerticalCorrection("on", *kitti);
            }).find("--vertical-correction: expected auto or an angle in degrees, got 'on'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { ResolveVerticalCorrection("nan", *kitti); }).find("got 'nan'"),
            std::string::npos);
  fs::create_directories(seq_ / "sim");
  std::ofstream((seq_ / "sim" / "scene.json").string())
      << R"({"lidar": {"motion_distortion": false, "elevation_bias_deg": 0.12}})";
  const auto simulated = OpenDataset(seq_.string());
  EXPECT_DOUBLE_EQ(simulated->lidar_elevation_error_deg(), 0.0);
  EXPECT_DOUBLE_EQ(ResolveVerticalCorrection("auto", *simulated), 0.0);
  EXPECT_DOUBLE_EQ(ResolveVerticalCorrection("0.12", *simulated), 0.12);
}

TEST_F(BadDatasetTest, OddSizedBinNamesTheFile) {
  std::ofstream(Scan(1), std::ios::binary | std::ios::app) << "xyz";
  const auto ds = OpenDataset(seq_.string());
  const std::string msg = ErrorOf([&] { ds->LoadScan(1); });
  EXPECT_NE(msg.find("000001.bin"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not a multiple of 16"), std::string::npos) << msg;
}

TEST_F(BadDatasetTest, NonFinitePointsAreDroppedAndCounted) {
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {NAN, 0, 0}, {0, INFINITY, 0}, {7, 8, 9}};
  WriteVelodyneBin(Scan(0), cloud);
  size_t dropped = 0;
  const PointCloud read = OpenDataset(seq_.string())->LoadScan(0, &dropped);
  EXPECT_EQ(read.size(), 2u);
  EXPECT_EQ(dropped, 2u);
}

TEST_F(BadDatasetTest, MissingImageNamesFrame) {
  const auto ds = OpenDataset(seq_.string());
  const std::string msg = ErrorOf([&] { ds->LoadImage(1); });
  EXPECT_NE(msg.find("frame 1"), std::string::npos) << msg;
}

TEST_F(BadDatasetTest, UndecodableImageNamesFile) {
  fs::create_directories(seq_ / "image_0");
  std::ofstream(seq_ / "image_0" / "000000.png") << "not a png";
  const std::string msg = ErrorOf([&] { OpenDataset(seq_.string()); });
  EXPECT_NE(msg.find("does not decode"), std::string::npos) << msg;
}

TEST_F(BadDatasetTest, TooFewTimestamps) {
  WriteKittiTimes((seq_ / "times.txt").string(), {0.0, 0.1});
  const std::string msg = ErrorOf([&] { OpenDataset(seq_.string()); });
  EXPECT_NE(msg.find("times.txt: 2 timestamps"), std::string::npos) << msg;
}

TEST_F(BadDatasetTest, TooFewGroundTruthPoses) {
  fs::create_directories(root_ / "poses");
  std::ofstream(root_ / "poses" / "07.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n";
  const std::string msg = ErrorOf([&] { OpenDataset(seq_.string()); });
  EXPECT_NE(msg.find("07.txt: 2 poses"), std::string::npos) << msg;
}

TEST_F(BadDatasetTest, MissingCalibrationAndUnknownLayout) {
  fs::remove(seq_ / "calib.txt");
  EXPECT_NE(ErrorOf([&] { OpenDataset(seq_.string()); }).find("unknown dataset layout"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] { OpenDataset((root_ / "nope").string()); }).find("not found"),
            std::string::npos);
  EXPECT_THROW(ParseDatasetFormat("zip"), Error);
}

TEST_F(BadDatasetTest, CalibrationWithoutTr) {
  std::ofstream(seq_ / "calib.txt") << "P0: 700 0 600 0 0 700 180 0 0 0 1 0\n";
  const std::string msg = ErrorOf([&] { OpenDataset(seq_.string()); });
  EXPECT_NE(msg.find("missing P1"), std::string::npos) << msg;
}

// --calib: another calib.txt's P0-P3 and Tr replace the folder's; the id (the recording) and
// the image size stay, the file becomes an input, and a missing or malformed file is one line.
TEST_F(BadDatasetTest, CalibrationFileReplacesTheDatasetsCalibration) {
  const auto own = OpenDataset(seq_.string());
  Calibration other = own->calibration();
  other.P[0](0, 0) = other.P[0](1, 1) = 710;
  other.cam0_from_velo =
      Rigid3d(ExpSO3(Eigen::Vector3d(0.002, 0, 0)), Eigen::Vector3d(0, -0.08, 0));
  const std::string path = (root_ / "calib_corrected.txt").string();
  WriteKittiCalibration(path, other);
  DatasetOptions options;
  options.calibration = path;
  const auto replaced = OpenDataset(seq_.string(), options);
  EXPECT_EQ(replaced->id(), own->id());
  EXPECT_EQ(replaced->calibration_file(), path);
  EXPECT_TRUE(own->calibration_file().empty());
  EXPECT_DOUBLE_EQ(replaced->calibration().Camera(0).fx, 710);
  EXPECT_DOUBLE_EQ(own->calibration().Camera(0).fx, 700);
  EXPECT_NEAR(RotationAngle(replaced->calibration().cam0_from_velo.rotation()), 0.002, 1e-9);
  EXPECT_NEAR(replaced->calibration().cam0_from_velo.translation().y(), -0.08, 1e-9);
  EXPECT_EQ(replaced->calibration().image_width, own->calibration().image_width);
  const std::vector<std::string> inputs = replaced->InputFiles();
  EXPECT_NE(std::find(inputs.begin(), inputs.end(), path), inputs.end());

  options.calibration = root_.string();  // A folder.
  std::string msg = ErrorOf([&] { OpenDataset(seq_.string(), options); });
  EXPECT_NE(msg.find("file not found"), std::string::npos) << msg;
  options.calibration = (root_ / "nope.txt").string();
  msg = ErrorOf([&] { OpenDataset(seq_.string(), options); });
  EXPECT_NE(msg.find("nope.txt: file not found"), std::string::npos) << msg;
  std::ofstream(root_ / "bad.txt") << "P0: 700 0 600 0 0 700 180 0 0 0 1 0\n";
  options.calibration = (root_ / "bad.txt").string();
  msg = ErrorOf([&] { OpenDataset(seq_.string(), options); });
  EXPECT_NE(msg.find("missing P1"), std::string::npos) << msg;
}

}  // namespace
}  // namespace jvl::io
