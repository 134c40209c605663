#include "loop/scan_descriptor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "geometry/rigid3.h"

namespace jvl::loop {
namespace {

// A place: the road plane 1.73 m below the sensor, boxes (buildings, parked cars) and poles at
// random positions within 70 m, sampled as points in the world frame.
std::vector<Eigen::Vector3d> Place(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::Vector3d> world;
  for (int k = 0; k < 4000; ++k) world.emplace_back(140 * u(rng) - 70, 140 * u(rng) - 70, -1.73);
  for (int b = 0; b < 25; ++b) {
    const Eigen::Vector2d c(120 * u(rng) - 60, 120 * u(rng) - 60);
    if (c.norm() < 8) continue;
    const double w = 2 + 12 * u(rng), d = 2 + 8 * u(rng), h = 1 + 14 * u(rng);
    for (int k = 0; k < 600; ++k) {  // The four walls.
      const double t = u(rng), z = -1.73 + h * u(rng);
      const int side = k % 4;
      const double x = side < 2 ? c.x() + (t - 0.5) * w : c.x() + (side == 2 ? -w : w) / 2;
      const double y = side < 2 ? c.y() + (side == 0 ? -d : d) / 2 : c.y() + (t - 0.5) * d;
      world.emplace_back(x, y, z);
    }
  }
  for (int p = 0; p < 30; ++p) {
    const Eigen::Vector2d c(100 * u(rng) - 50, 100 * u(rng) - 50);
    const double h = 3 + 6 * u(rng);
    for (int k = 0; k < 40; ++k) world.emplace_back(c.x(), c.y(), -1.73 + h * k / 40.0);
  }
  return world;
}

std::vector<Eigen::Vector3d> Scan(const std::vector<Eigen::Vector3d>& world,
                                  const Rigid3d& world_from_sensor) {
  const Rigid3d sensor_from_world = world_from_sensor.Inverse();
  std::vector<Eigen::Vector3d> scan;
  for (const auto& p : world) scan.push_back(sensor_from_world * p);
  return scan;
}

Rigid3d Yawed(double yaw, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  return Rigid3d(ExpSO3(Eigen::Vector3d(0, 0, yaw)), t);
}

// The sector as defined: atan2's azimuth in [0, 2 pi), scaled and floored.
int ReferenceSector(double x, double y, int sectors) {
  const double pi = 3.14159265358979323846;
  double azimuth = std::atan2(y, x);
  if (azimuth < 0) azimuth += 2 * pi;
  return std::min(sectors - 1, static_cast<int>(azimuth / (2 * pi) * sectors));
}

TEST(ScanDescriptor, AzimuthSectorIsAtan2sSector) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_real_distribution<double> log_scale(-3, 2.5);
  for (const int sectors : {4, 7, 60, 360, 3600}) {
    // Random directions at ranges from 1 mm to 300 m.
    for (int i = 0; i < 300000; ++i) {
      const double scale = std::pow(10.0, log_scale(rng));
      const double x = scale * u(rng), y = scale * u(rng);
      if (x == 0 && y == 0) continue;
      ASSERT_EQ(AzimuthSector(x, y, sectors), ReferenceSector(x, y, sectors))
          << x << " " << y << " " << sectors;
    }
    // On and beside every sector boundary: from 1e-12 to 1e-2 rad either side, where the
    // polynomial alone would be wrong.
    for (int k = 0; k <= sectors; ++k) {
      const double boundary = 2 * 3.14159265358979323846 * k / sectors;
      for (double offset = 1e-12; offset < 1e-2; offset *= 1.7) {
        for (const double angle : {boundary, boundary - offset, boundary + offset}) {
          const double x = 25 * std::cos(angle), y = 25 * std::sin(angle);
          ASSERT_EQ(AzimuthSector(x, y, sectors), ReferenceSector(x, y, sectors))
              << angle << " " << sectors;
        }
      }
    }
    // The axes, signed zeros included.
    for (const auto& [x, y] : std::vector<std::pair<double, double>>{
             {1, 0}, {1, -0.0}, {-1, 0}, {-1, -0.0}, {0, 1}, {-0.0, 1}, {0, -1}, {-0.0, -1}}) {
      EXPECT_EQ(AzimuthSector(x, y, sectors), ReferenceSector(x, y, sectors)) << x << " " << y;
    }
  }
}

TEST(ScanDescriptor, RingKeyAndDistanceIgnoreTheSensorsYaw) {
  const ScanDescriptorOptions o;
  const auto place = Place(1);
  const ScanDescriptor a = ComputeScanDescriptor(Scan(place, Rigid3d()), o);
  EXPECT_EQ(a.cells.rows(), 20);
  EXPECT_EQ(a.cells.cols(), 60);
  EXPECT_GT(a.cells.maxCoeff(), 5.0f);
  EXPECT_LT(CompareDescriptors(a, a).distance, 1e-9);
  const double sector = 2 * M_PI / 60;
  for (int k : {7, 23, 45}) {  // Whole sectors: the same cells, shifted.
    // The sensor turned by -k sectors: the scene appears turned by +k sectors.
    const ScanDescriptor b = ComputeScanDescriptor(Scan(place, Yawed(-k * sector)), o);
    EXPECT_LT(RingKeyDistance(a, b), 0.05) << k;
    const DescriptorMatch m = CompareDescriptors(a, b);
    EXPECT_EQ(m.shift, k);
    EXPECT_LT(m.distance, 0.02) << k;
    EXPECT_NEAR(m.yaw, std::remainder(k * sector, 2 * M_PI), 1e-12);
  }
  // Any yaw: found within a sector, and nearer than any other place (the cells of a yaw between
  // two sector multiples differ where an edge or a pole crosses a sector boundary).
  double nearest_other = 1;
  for (unsigned seed = 2; seed < 7; ++seed) {
    const ScanDescriptor other = ComputeScanDescriptor(Scan(Place(seed), Rigid3d()), o);
    nearest_other = std::min(nearest_other, CompareDescriptors(a, other).distance);
  }
  for (double yaw : {0.3, -1.1, 2.9}) {
    const ScanDescriptor b = ComputeScanDescriptor(Scan(place, Yawed(-yaw)), o);
    const DescriptorMatch m = CompareDescriptors(a, b);
    EXPECT_LT(std::abs(std::remainder(m.yaw - yaw, 2 * M_PI)), sector) << yaw;
    EXPECT_LT(m.distance, nearest_other - 0.1) << yaw;
  }
}

TEST(ScanDescriptor, TheSamePlaceIsNearerThanAnotherOne) {
  const ScanDescriptorOptions o;
  const auto place = Place(1);
  const ScanDescriptor a = ComputeScanDescriptor(Scan(place, Rigid3d()), o);
  // The same place seen 1.5 m to the side and turned by 170 degrees (a revisit from the other
  // direction).
  const ScanDescriptor again =
      ComputeScanDescriptor(Scan(place, Yawed(2.97, Eigen::Vector3d(0.5, 1.5, 0))), o);
  const DescriptorMatch same = CompareDescriptors(a, again);
  for (unsigned seed = 2; seed < 7; ++seed) {
    const ScanDescriptor other = ComputeScanDescriptor(Scan(Place(seed), Rigid3d()), o);
    EXPECT_GT(CompareDescriptors(a, other).distance, same.distance + 0.1) << seed;
  }
  EXPECT_LT(std::abs(std::remainder(same.yaw + 2.97, 2 * M_PI)), 0.15);
}

TEST(ScanDescriptor, EmptyScansAndBadInput) {
  const ScanDescriptorOptions o;
  const ScanDescriptor empty = ComputeScanDescriptor({}, o);
  EXPECT_EQ(empty.cells.sum(), 0.0f);
  EXPECT_EQ(CompareDescriptors(empty, empty).distance, 1.0);
  // Points beyond the range, at the sensor's axis or not finite are left out.
  const ScanDescriptor far = ComputeScanDescriptor(
      {Eigen::Vector3d(90, 0, 0), Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(std::nan(""), 1, 1)},
      o);
  EXPECT_EQ(far.cells.sum(), 0.0f);
  ScanDescriptorOptions bad;
  bad.sectors = 2;
  EXPECT_THROW(ComputeScanDescriptor({}, bad), std::exception);
  ScanDescriptorOptions other;
  other.rings = 10;
  EXPECT_THROW(CompareDescriptors(empty, ComputeScanDescriptor({}, other)), std::exception);
}

}  // namespace
}  // namespace jvl::loop
