#include "fidelity/sensor_stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <random>

#include "io/dataset.h"
#include "io/schema_check.h"

namespace jvl::fidelity {
namespace {

// One ring of `n` points swept counter-clockwise from behind to behind, each point at the
// range where the ray at elevation `elevation` meets `surface` (returns range or -1).
template <typename Surface>
void AddRing(int n, double elevation, Surface surface, PointCloud* scan) {
  for (int k = 0; k < n; ++k) {
    const double azimuth = -M_PI + (k + 0.5) * 2 * M_PI / n;
    const Eigen::Vector3d ray(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    const double t = surface(ray);
    if (t > 0) {
      scan->points.push_back(t * ray);
      scan->intensity.push_back(0.25f);
    }
  }
}

// Flat road 1.73 m below the sensor and a wall 8 m to the left (y = 8).
double RoadAndWall(const Eigen::Vector3d& ray) {
  double t = 1e9;
  if (ray.z() < 0) t = std::min(t, -1.73 / ray.z());
  if (ray.y() > 0) {
    const double tw = 8.0 / ray.y();
    if ((tw * ray).z() > -1.73) t = std::min(t, tw);
  }
  return t < 100 ? t : -1;
}

TEST(ScanStats, RingsRangesGroundAndAWall) {
  PointCloud scan;
  const int kRings = 40;
  for (int r = 0; r < kRings; ++r)
    AddRing(1000, (2.0 - 26.0 * r / (kRings - 1)) * M_PI / 180, RoadAndWall, &scan);
  const ScanStats s = ComputeScanStats(scan, ScanStatsOptions{});
  EXPECT_EQ(s.points, scan.size());
  EXPECT_EQ(s.rings, kRings);
  double sum = 0;
  for (double f : s.range_fraction) sum += f;
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_FLOAT_EQ(s.intensity_median, 0.25f);
  // Every return off the wall is on the road; the wall's lowest returns are within 0.2 m of
  // the road's height in their cells, so they count as ground too.
  size_t on_wall = 0, wall_base = 0;
  for (const auto& p : scan.points) {
    if (std::abs(p.y() - 8.0) < 1e-6) {
      ++on_wall;
      if (p.z() < -1.53) ++wall_base;
    }
  }
  ASSERT_GT(on_wall, 1000u);
  EXPECT_NEAR(s.ground_fraction, 1.0 - static_cast<double>(on_wall - wall_base) / scan.size(),
              0.01);
  EXPECT_GT(s.shape_voxels, 500u);
  EXPECT_GT(s.vertical_planar, 0.8);
  EXPECT_LT(s.scattered, 0.05);
}

TEST(ScanStats, FoliageIsScatteredAndAPoleLinear) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  PointCloud crown, pole;
  while (crown.size() < 3000) {  // A ball of returns 2 m across, 10 m ahead, 1 m up.
    const Eigen::Vector3d d(u(rng), u(rng), u(rng));
    if (d.norm() <= 1) crown.points.push_back(Eigen::Vector3d(10, 0, 1) + d);
  }
  for (int k = 0; k < 400; ++k) pole.points.emplace_back(10 + 0.01 * u(rng), 3, -1.5 + 0.01 * k);
  const ScanStats c = ComputeScanStats(crown, ScanStatsOptions{});
  EXPECT_GT(c.scattered, 0.9);
  EXPECT_TRUE(std::isnan(c.intensity_median));
  const ScanStats p = ComputeScanStats(pole, ScanStatsOptions{});
  // The voxels near the pole's ends have fewer than 6 neighbours (sparse); all others are linear.
  EXPECT_GT(p.linear, 0.8);
  EXPECT_NEAR(p.linear + p.sparse, 1.0, 1e-12);
}

// A wall across the road 60 m ahead (x = 60) and nothing behind: far returns ahead are the
// wall's returns above its base, none behind; the road is ground, not counted.
TEST(ScanStats, FarReturnsAheadAndBehind) {
  const auto wall_ahead = [](const Eigen::Vector3d& ray) {
    double t = 1e9;
    if (ray.z() < 0) t = std::min(t, -1.73 / ray.z());
    if (ray.x() > 0) {
      const double tw = 60.0 / ray.x();
      if ((tw * ray).z() > -1.73 && std::abs((tw * ray).y()) < 30) t = std::min(t, tw);
    }
    return t < 100 ? t : -1;
  };
  PointCloud scan;
  for (int r = 0; r < 40; ++r) AddRing(2000, (2.0 - 26.0 * r / 39) * M_PI / 180, wall_ahead, &scan);
  // The wall's returns up to 1.2 m above the road may count as ground (far away, a cell's
  // lowest return can be on the wall, within the ground band of the road's height).
  size_t on_wall = 0, well_above = 0;
  for (const auto& p : scan.points) {
    on_wall += std::abs(p.x() - 60) < 1e-6;
    well_above += std::abs(p.x() - 60) < 1e-6 && p.z() > -0.5;
  }
  const ScanStats s = ComputeScanStats(scan, ScanStatsOptions{});
  ASSERT_GT(well_above, 500u);
  EXPECT_GE(s.far_ahead, well_above);
  EXPECT_LE(s.far_ahead, on_wall);
  EXPECT_EQ(s.far_behind, 0u);
  ScanStatsOptions beyond;  // The wall is nearer than 70 m: not far.
  beyond.far_range = 70;
  EXPECT_EQ(ComputeScanStats(scan, beyond).far_ahead, 0u);
  beyond.far_range = 0;
  EXPECT_THROW(ComputeScanStats(scan, beyond), std::exception);
}

TEST(ScanStats, EmptyScanAndBadOptions) {
  const ScanStats s = ComputeScanStats(PointCloud{}, ScanStatsOptions{});
  EXPECT_EQ(s.points, 0u);
  EXPECT_TRUE(std::isnan(s.ground_fraction));
  ScanStatsOptions bad;
  bad.radius = 0;
  EXPECT_THROW(ComputeScanStats(PointCloud{}, bad), std::exception);
}

TEST(ImageStats, PlainImageAndCheckerboard) {
  const cv::Mat plain(370, 1226, CV_8UC1, cv::Scalar(128));
  const ImageStats p = ComputeImageStats(plain, ImageStatsOptions{});
  EXPECT_DOUBLE_EQ(p.mean, 128);
  EXPECT_NEAR(p.contrast, 0, 1e-4);
  EXPECT_DOUBLE_EQ(p.gradient_mean, 0);
  EXPECT_EQ(p.fast_corners, 0u);
  EXPECT_EQ(p.orb_keypoints, 0u);
  EXPECT_DOUBLE_EQ(p.corner_cells, 0);

  cv::Mat board(370, 1226, CV_8UC1);
  for (int y = 0; y < board.rows; ++y)
    for (int x = 0; x < board.cols; ++x) board.at<uchar>(y, x) = ((x / 20 + y / 20) % 2) ? 200 : 50;
  cv::GaussianBlur(board, board, cv::Size(5, 5), 1.0);
  const ImageStats b = ComputeImageStats(board, ImageStatsOptions{});
  EXPECT_NEAR(b.mean, 125, 2);
  EXPECT_GT(b.contrast, 60);  // 75 before the blur softened the edges.
  EXPECT_LT(b.contrast, 75);
  EXPECT_GT(b.gradient_mean, 5);
  EXPECT_GT(b.fast_corners, 500u);  // One or more per board corner (about 1100 inner corners).
  EXPECT_DOUBLE_EQ(b.corner_cells, 1.0);
  EXPECT_GT(b.orb_cells, 0.9);
  EXPECT_DOUBLE_EQ(b.dark_fraction, 0);
  EXPECT_DOUBLE_EQ(b.bright_fraction, 0);
  EXPECT_THROW(ComputeImageStats(cv::Mat(), ImageStatsOptions{}), std::exception);
}

TEST(SensorStatsSummary, MatchesTheSchemaAndSkipsNonFiniteValues) {
  std::vector<ScanStats> scans(3);
  scans[0].ground_fraction = 0.5;
  scans[1].ground_fraction = std::nan("");
  scans[2].ground_fraction = 0.7;
  scans[0].points = 10;
  scans[1].points = 30;
  scans[2].points = 20;
  std::vector<ImageStats> images(1);
  images[0].mean = 90;
  nlohmann::json doc = {{"schema", "sensor_stats"},
                        {"schema_version", 1},
                        {"provenance", nlohmann::json::object()},
                        {"frames", {0, 5, 10}},
                        {"scan", SummariseScans(scans)},
                        {"image", SummariseImages(images)}};
  const std::string schema = std::string(JVL_SOURCE_DIR) + "/schemas/sensor_stats.schema.json";
  EXPECT_TRUE(io::CheckJsonAgainstSchema(doc, schema).empty());
  EXPECT_DOUBLE_EQ(doc["scan"]["ground"]["median"].get<double>(), 0.6);
  EXPECT_TRUE(doc["scan"]["ground"]["frames"][1].is_null());
  EXPECT_DOUBLE_EQ(doc["scan"]["points"]["median"].get<double>(), 20);
  EXPECT_DOUBLE_EQ(doc["scan"]["points"]["p90"].get<double>(), 30);
  EXPECT_DOUBLE_EQ(doc["image"]["mean"]["median"].get<double>(), 90);
  doc["image"] = nullptr;  // --no-images
  EXPECT_TRUE(io::CheckJsonAgainstSchema(doc, schema).empty());
  doc["scan"].erase("ground");
  EXPECT_FALSE(io::CheckJsonAgainstSchema(doc, schema).empty());
}

TEST(SensorStatsKitti, RealFrameOfSequence04) {
  const std::string root =
      std::string(JVL_SOURCE_DIR) + "/../shared/data/kitti_odometry_04_f0-50/sequences/04";
  if (!std::filesystem::exists(root))
    GTEST_SKIP() << "../shared/data/kitti_odometry_04_f0-50 not found (real KITTI excerpt)";
  const auto ds = io::OpenDataset(root, io::DatasetFormat::kAuto, {});
  const ScanStats s = ComputeScanStats(ds->LoadScan(0), ScanStatsOptions{});
  // An HDL-64E: 64 rings, the first split at the frame start (65 segments), ~1900 points each.
  EXPECT_GE(s.rings, 64);
  EXPECT_LE(s.rings, 66);
  EXPECT_GT(s.ring_points_median, 1700);
  EXPECT_LT(s.ring_points_median, 2200);
  EXPECT_GT(s.ground_fraction, 0.3);
  EXPECT_LT(s.ground_fraction, 0.9);
  const ImageStats i = ComputeImageStats(ds->LoadImage(0), ImageStatsOptions{});
  EXPECT_GT(i.fast_corners, 500u);
  EXPECT_GT(i.orb_keypoints, 1500u);
}

}  // namespace
}  // namespace jvl::fidelity
