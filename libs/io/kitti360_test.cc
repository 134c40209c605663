#include "io/kitti360.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/check.h"
#include "core/temp_dir.h"
#include "io/kitti.h"

namespace jvl::io {
namespace {

namespace fs = std::filesystem;

const char* kDrive = "2013_05_28_drive_0003_sync";

void WriteMatrix(std::ostream& out, const Rigid3d& t, bool four_by_four) {
  const Eigen::Matrix<double, 3, 4> m = t.Matrix3x4();
  out.precision(17);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out << " " << m(r, c);
  if (four_by_four) out << " 0 0 0 1";
}

Rigid3d Yaw(double yaw, const Eigen::Vector3d& t) {
  return Rigid3d(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix(), t);
}

// A KITTI-360 tree with one drive of five frames (0-4). The rig follows the devkit's frames:
// the unrectified camera looks along the Velodyne's and the IMU's x axis; R_rect_00 turns by
// 0.01 rad about the camera's x axis. The IMU moves 2 m per frame through a world whose origin
// is far away (as KITTI-360's map frame), turning by 0.1 rad per frame; frames 0 and 3 have no
// pose (the car stood still).
class Kitti360Test : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = tmp_.path();
    velo_ = root_ / "data_3d_raw" / kDrive;
    images_ = root_ / "data_2d_raw" / kDrive;
    poses_ = root_ / "data_poses" / kDrive;
    fs::create_directories(root_ / "calibration");
    fs::create_directories(velo_ / "velodyne_points" / "data");
    fs::create_directories(images_ / "image_00" / "data_rect");
    fs::create_directories(poses_);
    rect_ = Rigid3d(Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                    Eigen::Vector3d::Zero());
    Eigen::Matrix3d axes;  // camera (x right, y down, z ahead) in the x-ahead, z-up frames
    axes << 0, 0, 1, -1, 0, 0, 0, -1, 0;
    velo_from_cam_ = Rigid3d(axes, Eigen::Vector3d(0.27, 0.0, -0.08));
    pose_from_cam_ = Rigid3d(axes, Eigen::Vector3d(1.5, 0.3, 0.9));
    {
      std::ofstream f(root_ / "calibration" / "perspective.txt");
      f << "calib_time: 09-Jan-2012 13:57:47\n"
        << "S_00: 1.392000e+03 5.120000e+02\n"
        << "P_rect_00: 552.55 0 682.05 0 0 552.55 238.77 0 0 0 1 0\n"
        << "R_rect_00:";
      const Eigen::Matrix3d r = rect_.RotationMatrix();
      f.precision(17);
      for (int i = 0; i < 9; ++i) f << " " << r(i / 3, i % 3);
      f << "\nS_rect_00: 9.600000e+01 6.400000e+01\n"
        << "P_rect_01: 552.55 0 682.05 -328.32 0 552.55 238.77 0 0 0 1 0\n";
    }
    {
      std::ofstream f(root_ / "calibration" / "calib_cam_to_velo.txt");
      WriteMatrix(f, velo_from_cam_, false);
      f << "\n";
    }
    {
      std::ofstream f(root_ / "calibration" / "calib_cam_to_pose.txt");
      for (const char* cam : {"image_00", "image_01", "image_02", "image_03"}) {
        f << cam << ":";
        WriteMatrix(f, pose_from_cam_, false);
        f << "\n";
      }
    }
    std::ofstream stamps(velo_ / "velodyne_points" / "timestamps.txt");
    std::ofstream imu(poses_ / "poses.txt");
    std::ofstream cam(poses_ / "cam0_to_world.txt");
    const cv::Mat image(64, 96, CV_8UC1, cv::Scalar(128));
    for (int i = 0; i < 5; ++i) {
      char name[32];
      std::snprintf(name, sizeof(name), "%010d", i);
      PointCloud cloud;
      cloud.points = {{10, 0, 0}, {0, 5, 1}};
      WriteVelodyneBin((velo_ / "velodyne_points" / "data" / (std::string(name) + ".bin")).string(),
                       cloud);
      cv::imwrite((images_ / "image_00" / "data_rect" / (std::string(name) + ".png")).string(),
                  image);
      stamps << "2013-05-28 08:46:0" << i << ".500000000\n";
      world_from_imu_[i] = Yaw(0.1 * i, Eigen::Vector3d(1000.0 + 2.0 * i, 500.0, 115.0));
      if (i == 0 || i == 3) continue;
      imu << i;
      WriteMatrix(imu, world_from_imu_[i], false);
      imu << "\n";
      cam << i;
      WriteMatrix(cam, world_from_imu_[i] * pose_from_cam_ * rect_.Inverse(), true);
      cam << "\n";
    }
  }

  // The expected ground truth: rectified camera 0, relative to frame 1 (the first posed one).
  Rigid3d Expected(int frame) const {
    const Rigid3d world_from_rect = world_from_imu_.at(frame) * pose_from_cam_ * rect_.Inverse();
    const Rigid3d first = world_from_imu_.at(1) * pose_from_cam_ * rect_.Inverse();
    return first.Inverse() * world_from_rect;
  }

  TempDir tmp_{"jvl_k360"};
  fs::path root_, velo_, images_, poses_;
  Rigid3d rect_, velo_from_cam_, pose_from_cam_;
  std::map<int, Rigid3d> world_from_imu_;
};

double Distance(const Rigid3d& a, const Rigid3d& b) {
  return (a.Matrix3x4() - b.Matrix3x4()).cwiseAbs().maxCoeff();
}

TEST_F(Kitti360Test, DetectedFromEachOfTheDrivesFolders) {
  for (const fs::path& dir : {velo_, images_, poses_}) {
    EXPECT_EQ(DetectDatasetFormat(dir.string()), DatasetFormat::kKitti360) << dir;
    const auto where = LocateKitti360(dir.string() + "/");
    ASSERT_TRUE(where.has_value()) << dir;
    EXPECT_EQ(where->drive, kDrive);
    EXPECT_EQ(fs::path(where->root), root_);
  }
  EXPECT_EQ(ParseDatasetFormat("kitti360"), DatasetFormat::kKitti360);
  // Without the calibration it is not KITTI-360 (and the Velodyne folder reads as KITTI raw).
  fs::remove(root_ / "calibration" / "perspective.txt");
  EXPECT_FALSE(LocateKitti360(velo_.string()).has_value());
  EXPECT_EQ(DetectDatasetFormat(velo_.string()), DatasetFormat::kKittiRaw);
}

TEST_F(Kitti360Test, ReadsCalibrationFramesTimesScansAndImages) {
  const auto ds = OpenDataset(velo_.string());
  EXPECT_EQ(ds->format(), DatasetFormat::kKitti360);
  EXPECT_EQ(ds->id().rfind(std::string("kitti360:") + kDrive + ":", 0), 0u);
  EXPECT_FALSE(ds->scans_motion_compensated());
  ASSERT_EQ(ds->frames().size(), 5u);
  const Calibration& c = ds->calibration();
  EXPECT_DOUBLE_EQ(c.P[0](0, 0), 552.55);
  EXPECT_DOUBLE_EQ(c.P[1](0, 3), -328.32);
  EXPECT_EQ(c.image_width, 96);
  EXPECT_EQ(c.image_height, 64);
  // cam0 (rectified) from velo = R_rect * inverse(cam_to_velo).
  EXPECT_LT(Distance(c.cam0_from_velo, rect_ * velo_from_cam_.Inverse()), 1e-12);
  // A point 10 m ahead of the Velodyne is about 10 m ahead of the camera.
  const Eigen::Vector3d p = c.cam0_from_velo * Eigen::Vector3d(10, 0, 0);
  EXPECT_NEAR(p.z(), 9.73, 0.01);
  EXPECT_EQ(ds->LoadScan(2).size(), 2u);
  EXPECT_EQ(ds->LoadImage(4, 0).cols, 96);
  EXPECT_NEAR(ds->timestamps()[3], 3.0, 1e-6);
  EXPECT_EQ(fs::path(ds->ImagePath(2, 0)), images_ / "image_00" / "data_rect" / "0000000002.png");
  // The fisheyes are not read, with a one-line reason.
  try {
    ds->LoadImage(1, 2);
    FAIL() << "camera 2 was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("fisheye"), std::string::npos) << e.what();
  }
  // --frames clips the drive as the paper's sequences are clipped.
  const auto clipped = OpenDataset(images_.string(), DatasetFormat::kAuto, ParseFrameRange("1:4"));
  EXPECT_EQ(clipped->frames(), (std::vector<int64_t>{1, 2, 3}));
  EXPECT_NEAR(clipped->timestamps()[0], 1.0, 1e-6);
}

TEST_F(Kitti360Test, GroundTruthIsTheRectifiedCameraFromTheFirstPosedFrame) {
  const auto ds = OpenDataset(poses_.string());
  ASSERT_TRUE(ds->ground_truth().has_value());
  const Trajectory& gt = *ds->ground_truth();
  // Frames 0 and 3 have no pose and are absent.
  EXPECT_EQ(gt.frames, (std::vector<int64_t>{1, 2, 4}));
  EXPECT_LT(Distance(gt.world_from_cam[0], Rigid3d()), 1e-9);
  for (size_t i = 0; i < gt.size(); ++i) {
    EXPECT_LT(Distance(gt.world_from_cam[i], Expected(static_cast<int>(gt.frames[i]))), 1e-9)
        << gt.frames[i];
  }
  // 2 m per frame straight ahead of the IMU at frame 1 is about 2 m along the camera's z axis.
  EXPECT_NEAR(gt.world_from_cam[1].translation().z(), 2.0, 0.25);
  EXPECT_NEAR(gt.timestamps[2], 4.0, 1e-6);
  // Without cam0_to_world.txt the same poses come from poses.txt and calib_cam_to_pose.txt.
  fs::remove(poses_ / "cam0_to_world.txt");
  const auto from_imu = OpenDataset(velo_.string());
  ASSERT_TRUE(from_imu->ground_truth().has_value());
  const Trajectory& gt2 = *from_imu->ground_truth();
  ASSERT_EQ(gt2.frames, gt.frames);
  for (size_t i = 0; i < gt.size(); ++i)
    EXPECT_LT(Distance(gt2.world_from_cam[i], gt.world_from_cam[i]), 1e-9) << gt.frames[i];
}

TEST_F(Kitti360Test, BadFilesGiveOneLineErrorsNamingThem) {
  auto expect_error = [](const auto& f, const std::string& needle) {
    try {
      f();
      ADD_FAILURE() << "no error, expected one naming " << needle;
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(needle), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  };
  std::ofstream(poses_ / "cam0_to_world.txt", std::ios::app) << "5 1 0 0\n";
  expect_error([&] { OpenDataset(velo_.string()); }, "cam0_to_world.txt, line 4");
  std::ofstream(poses_ / "cam0_to_world.txt") << "2 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n"
                                                 "1 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n";
  expect_error([&] { OpenDataset(velo_.string()); }, "is not after frame 2");
  fs::remove(root_ / "calibration" / "calib_cam_to_velo.txt");
  expect_error([&] { OpenDataset(velo_.string(), DatasetFormat::kKitti360); },
               "calib_cam_to_velo.txt");
  expect_error([&] { OpenDataset(root_.string(), DatasetFormat::kKitti360); },
               "not a KITTI-360 drive folder");
}

}  // namespace
}  // namespace jvl::io
