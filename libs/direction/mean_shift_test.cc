#include "direction/mean_shift.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/check.h"
#include "geometry/rigid3.h"

namespace jvl::direction {
namespace {

constexpr double kDeg = M_PI / 180.0;

Eigen::Vector3d Heading(double deg, double pitch_deg = 0) {
  const double h = deg * kDeg, p = pitch_deg * kDeg;
  return {std::sin(h) * std::cos(p), -std::sin(p), std::cos(h) * std::cos(p)};
}

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) / kDeg;
}

// n directions scattered around c with isotropic angular noise sigma (deg).
void AddBlob(const Eigen::Vector3d& c, double sigma_deg, int n, std::mt19937& rng,
             std::vector<Eigen::Vector3d>* out) {
  std::normal_distribution<double> g(0.0, sigma_deg * kDeg);
  for (int i = 0; i < n; ++i) out->push_back(ExpSO3(Eigen::Vector3d(g(rng), g(rng), g(rng))) * c);
}

TEST(MeanShiftSphere, RecoversTheComponentsOfAKnownMixture) {
  std::mt19937 rng(3);
  const std::vector<Eigen::Vector3d> centres = {Heading(0), Heading(30), Heading(90, 5)};
  std::vector<Eigen::Vector3d> dirs;
  for (const auto& c : centres) AddBlob(c, 0.5, 200, rng, &dirs);
  MeanShiftOptions o;
  o.bandwidth = 1.5 * kDeg;
  const MeanShiftResult r = MeanShiftSphere(dirs, o);
  ASSERT_EQ(r.modes.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(r.sizes[k], 200);
    EXPECT_LT(AngleDeg(r.modes[k], centres[k]), 0.15) << "component " << k;
    for (int i = 0; i < 200; ++i) EXPECT_EQ(r.labels[200 * k + i], k);
  }
}

TEST(MeanShiftSphere, OutliersFormSmallClustersAndDoNotMoveTheModes) {
  std::mt19937 rng(5);
  std::vector<Eigen::Vector3d> dirs;
  AddBlob(Heading(45), 0.4, 300, rng, &dirs);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 60; ++i) dirs.push_back(Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized());
  MeanShiftOptions o;
  o.bandwidth = 1.5 * kDeg;
  const MeanShiftResult r = MeanShiftSphere(dirs, o);
  EXPECT_EQ(r.labels[0], 0);
  EXPECT_GE(r.sizes[0], 300);
  EXPECT_LE(r.sizes[0], 302);  // At most a couple of random directions fall in the basin.
  EXPECT_LT(AngleDeg(r.modes[0], Heading(45)), 0.1);
  for (size_t k = 1; k < r.sizes.size(); ++k) EXPECT_LE(r.sizes[k], 3);
}

TEST(MeanShiftSphere, BinSeedingGivesTheSamePartitionAsPerPointSeeds) {
  std::mt19937 rng(11);
  std::vector<Eigen::Vector3d> dirs;
  AddBlob(Heading(-20), 0.5, 150, rng, &dirs);
  AddBlob(Heading(-10), 0.5, 150, rng, &dirs);
  MeanShiftOptions o;
  o.bandwidth = 1.5 * kDeg;
  const MeanShiftResult binned = MeanShiftSphere(dirs, o);
  o.seed_bin = 0;
  const MeanShiftResult exact = MeanShiftSphere(dirs, o);
  ASSERT_EQ(binned.modes.size(), 2u);
  EXPECT_EQ(binned.labels, exact.labels);
  EXPECT_LT(AngleDeg(binned.modes[0], exact.modes[0]), 1e-3);
  // Deterministic: the same input gives the same result.
  EXPECT_EQ(MeanShiftSphere(dirs, o).labels, exact.labels);
}

TEST(MeanShiftSphere, WideBandwidthMergesCloseComponents) {
  std::mt19937 rng(13);
  std::vector<Eigen::Vector3d> dirs;
  AddBlob(Heading(0), 0.3, 100, rng, &dirs);
  AddBlob(Heading(2), 0.3, 100, rng, &dirs);
  MeanShiftOptions o;
  o.bandwidth = 0.4 * kDeg;
  EXPECT_EQ(MeanShiftSphere(dirs, o).modes.size(), 2u);
  o.bandwidth = 3 * kDeg;
  const MeanShiftResult r = MeanShiftSphere(dirs, o);
  ASSERT_EQ(r.modes.size(), 1u);
  EXPECT_LT(AngleDeg(r.modes[0], Heading(1)), 0.1);
}

TEST(MeanShiftPlane, SplitsSpatiallySeparateRuns) {
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i <= 60; ++i) pts.push_back({0.0, double(i)});  // 0..60 m
  for (int i = 0; i <= 60; ++i) pts.push_back({0.0, 200.0 + i});  // 200..260 m
  for (int i = 0; i <= 40; ++i) pts.push_back({80.0 + i, 50.0});  // a cross street
  MeanShiftOptions o;
  o.bandwidth = 15;
  const MeanShiftResult r = MeanShiftPlane(pts, o);
  ASSERT_EQ(r.modes.size(), 3u);
  EXPECT_EQ(r.sizes, (std::vector<int>{61, 61, 41}));
  // A uniform run shorter than the kernel support has one mode, at its middle.
  EXPECT_NEAR(r.modes[0].y(), 30.0, 1.0);
  EXPECT_NEAR(r.modes[1].y(), 230.0, 1.0);
  EXPECT_NEAR(r.modes[2].x(), 100.0, 1.0);
}

TEST(MeanShiftPlane, LongUniformRunHasAFlatDensityAndSplits) {
  // Why the second level joins touching sub-clusters (see direction_cluster.cc): inside a
  // uniform run longer than twice the kernel support the density is flat.
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i <= 300; ++i) pts.push_back({0.0, double(i)});
  MeanShiftOptions o;
  o.bandwidth = 15;
  EXPECT_GT(MeanShiftPlane(pts, o).modes.size(), 1u);
}

TEST(MeanShiftPlane, GaussianBlobsHaveModesAtTheirMeans) {
  std::mt19937 rng(17);
  std::normal_distribution<double> g(0.0, 2.0);
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < 400; ++i) pts.push_back(Eigen::Vector2d(g(rng), g(rng)));
  for (int i = 0; i < 400; ++i) pts.push_back(Eigen::Vector2d(40 + g(rng), -30 + g(rng)));
  MeanShiftOptions o;
  o.bandwidth = 4;
  const MeanShiftResult r = MeanShiftPlane(pts, o);
  ASSERT_EQ(r.modes.size(), 2u);
  EXPECT_LT(r.modes[0].head<2>().norm(), 0.5);
  EXPECT_LT((r.modes[1].head<2>() - Eigen::Vector2d(40, -30)).norm(), 0.5);
}

TEST(MeanShift, RejectsBadOptionsAndInputs) {
  MeanShiftOptions o;
  o.bandwidth = 0;
  EXPECT_THROW(MeanShiftPlane({{0, 0}}, o), Error);
  o = MeanShiftOptions();
  EXPECT_THROW(MeanShiftSphere({Eigen::Vector3d::Zero()}, o), Error);
  EXPECT_TRUE(MeanShiftSphere({}, o).modes.empty());
}

}  // namespace
}  // namespace jvl::direction
