// Runs the odometry on real KITTI 04 scans (../shared/data) and checks its accuracy against
// the ground truth. Skipped when the data is absent.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <string>

#include "io/dataset.h"
#include "lidar/odometry.h"
#include "lidar/test_metrics.h"

namespace jvl::lidar {
namespace {

const std::string kSequence =
    std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50/sequences/04";

struct RunSummary {
  testing::TrajectoryErrors errors;
  double median_ms = 0;
  int flagged = 0;
};

RunSummary RunKitti(const std::string& frames, const OdometryOptions& options) {
  const auto dataset =
      io::OpenDataset(kSequence, io::DatasetFormat::kAuto, ParseFrameRange(frames));
  EXPECT_TRUE(dataset->ground_truth().has_value());
  Odometry odometry(dataset->calibration().cam0_from_velo, options, 2);
  std::vector<Eigen::Matrix4d> est, gt;
  std::vector<double> ms;
  RunSummary s;
  const std::clock_t cpu0 = std::clock();
  double iterations = 0;
  for (size_t k = 0; k < dataset->frames().size(); ++k) {
    const OdometryFrame f =
        odometry.ProcessScan(dataset->LoadScan(dataset->frames()[k]), dataset->frames()[k]);
    est.push_back(f.world_from_cam.Matrix4());
    gt.push_back(dataset->ground_truth()->world_from_cam[k].Matrix4());
    ms.push_back(f.diagnostics.time_ms);
    s.flagged += f.diagnostics.degenerate;
    iterations += f.diagnostics.iterations;
    if (std::getenv("JVL_LIDAR_VERBOSE")) {
      const FrameDiagnostics& d = f.diagnostics;
      std::printf(
          "frame %lld: %lld pts, pre %.1f surf %.1f reg %.1f total %.1f ms, %d samples, %d it, "
          "%d corr, res %.4f, eig %.4f\n",
          static_cast<long long>(f.frame), static_cast<long long>(d.points_after_filter),
          d.preprocess_ms, d.surface_ms, d.register_ms, d.time_ms, d.samples, d.iterations,
          d.correspondences, d.residual, d.min_eigenvalue);
    }
  }
  const double cpu_ms = 1e3 * static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  std::printf("CPU time %.1f ms per frame (incl. loading)\n",
              cpu_ms / static_cast<double>(ms.size()));
  std::sort(ms.begin(), ms.end());
  s.median_ms = ms[ms.size() / 2];
  s.errors = testing::ComputeErrors(est, gt);
  std::printf("iterations %.2f mean\n", iterations / static_cast<double>(ms.size()));
  std::printf(
      "KITTI 04 frames %s: APE %.4f m, end drift %.4f m over %.2f m (%.3f %%), "
      "median %.1f ms/scan, %d flagged\n",
      frames.c_str(), s.errors.ape_rmse, s.errors.end_drift, s.errors.distance,
      100 * s.errors.drift_fraction(), s.median_ms, s.flagged);
  return s;
}

OdometryOptions EnvOptions() {
  OdometryOptions o;
  if (const char* v = std::getenv("JVL_H")) o.association.kernel_h = std::atof(v);
  if (const char* v = std::getenv("JVL_R")) o.association.search_radius = std::atof(v);
  if (const char* v = std::getenv("JVL_VOXEL")) o.preprocess.voxel_size = std::atof(v);
  if (const char* v = std::getenv("JVL_NR")) o.surface.normal_radius = std::atof(v);
  if (const char* v = std::getenv("JVL_N")) o.scan_map_size = std::atoi(v);
  if (const char* v = std::getenv("JVL_S")) o.association.samples_per_list = std::atoi(v);
  if (const char* v = std::getenv("JVL_DESKEW")) o.deskew = std::atoi(v);
  if (const char* v = std::getenv("JVL_VC")) o.preprocess.vertical_correction_deg = std::atof(v);
  if (const char* v = std::getenv("JVL_SMALL")) o.preprocess.remove_small_objects = std::atoi(v);
  if (const char* v = std::getenv("JVL_MAXD")) o.association.max_distance = std::atof(v);
  if (const char* v = std::getenv("JVL_CT")) o.registration.convergence_translation = std::atof(v);
  if (const char* v = std::getenv("JVL_CR")) o.registration.convergence_rotation = std::atof(v);
  if (const char* v = std::getenv("JVL_K")) o.surface.normal_neighbors = std::atoi(v);
  return o;
}

TEST(OdometryKittiTest, Tune) {
  if (!std::getenv("JVL_TUNE")) GTEST_SKIP();
  RunKitti("0:51", EnvOptions());
}

TEST(OdometryKittiTest, TenFramesAccurate) {
  if (!std::filesystem::exists(kSequence)) GTEST_SKIP() << "KITTI 04 sample absent: " << kSequence;
  const RunSummary s = RunKitti("0:10", OdometryOptions());
  EXPECT_LT(s.errors.ape_rmse, 0.03);
  EXPECT_LT(s.errors.drift_fraction(), 0.02);  // Over 12 m only; 0.87 % measured.
  EXPECT_EQ(s.flagged, 0);
}

TEST(OdometryKittiTest, FiftyOneFramesWithinBudget) {
  if (!std::filesystem::exists(kSequence)) GTEST_SKIP() << "KITTI 04 sample absent: " << kSequence;
  const RunSummary s = RunKitti("0:51", OdometryOptions());
  EXPECT_LE(s.errors.ape_rmse, 0.15);
  EXPECT_LE(s.errors.drift_fraction(), 0.01);
}

}  // namespace
}  // namespace jvl::lidar
