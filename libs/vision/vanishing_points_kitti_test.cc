// Accuracy of the forward VP on real KITTI odometry sequence 04, frames 0-50 (a straight road):
// the forward VP direction against the ground-truth direction of travel over the next 20 m.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>

#include "core/timer.h"
#include "io/dataset.h"
#include "io/trajectory_io.h"
#include "vision/vanishing_points.h"

namespace jvl {
namespace {

const std::string kRoot = std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50";

// Unit direction, in the camera frame of `i`, from the position of frame i to the position of
// the first frame whose path length from i reaches `distance` metres.
std::optional<Eigen::Vector3d> TravelDirection(const Trajectory& gt, size_t i, double distance) {
  double path = 0;
  for (size_t k = i + 1; k < gt.size(); ++k) {
    path += (gt.world_from_cam[k].translation() - gt.world_from_cam[k - 1].translation()).norm();
    if (path >= distance) {
      const Eigen::Vector3d world =
          gt.world_from_cam[k].translation() - gt.world_from_cam[i].translation();
      return (gt.world_from_cam[i].rotation().conjugate() * world).normalized();
    }
  }
  return std::nullopt;
}

double Percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(
      std::min<double>(v.size() - 1, std::floor(q * (v.size() - 1) + 0.5)))];
}

TEST(VanishingPointsKitti, ForwardVpMatchesDirectionOfTravel) {
  if (!std::filesystem::exists(kRoot + "/sequences/04/calib.txt")) {
    GTEST_SKIP() << "KITTI 04 subset not found at " << kRoot << " (needs ../shared/data)";
  }
  cv::setNumThreads(1);
  const auto dataset =
      io::OpenDataset(kRoot + "/sequences/04", io::DatasetFormat::kAuto, ParseFrameRange("0:51"));
  const Trajectory gt = io::ReadTrajectory(kRoot + "/poses/04.txt");
  PinholeCamera camera = dataset->calibration().Camera(0);
  VpDetectOptions options;
  std::vector<double> errors_deg, times_ms;
  int missing = 0;
  for (int64_t frame : dataset->frames()) {
    const cv::Mat image = dataset->LoadImage(frame, 0);
    camera.width = image.cols;
    camera.height = image.rows;
    Timer timer;
    const VpResult result = DetectVanishingPoints(image, camera, options);
    times_ms.push_back(timer.ElapsedMs());
    const auto travel = TravelDirection(gt, static_cast<size_t>(*gt.IndexOf(frame)), 20.0);
    ASSERT_TRUE(travel.has_value()) << "frame " << frame;
    if (result.forward_index < 0) {
      ++missing;
      continue;
    }
    const Eigen::Vector3d d = result.vps[result.forward_index].direction;
    errors_deg.push_back(std::acos(std::clamp(d.dot(*travel), -1.0, 1.0)) * 180.0 / M_PI);
  }
  ASSERT_FALSE(errors_deg.empty());
  const double median = Percentile(errors_deg, 0.5);
  const double p90 = Percentile(errors_deg, 0.9);
  std::printf(
      "KITTI 04 f0-50: forward VP in %zu/%zu frames; error median %.3f deg, p90 %.3f deg, "
      "max %.3f deg; detection median %.2f ms\n",
      errors_deg.size(), dataset->frames().size(), median, p90, Percentile(errors_deg, 1.0),
      Percentile(times_ms, 0.5));
  EXPECT_LE(median, 2.0);
  EXPECT_LE(missing, 5);
}

}  // namespace
}  // namespace jvl
