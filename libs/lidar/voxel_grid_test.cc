#include "lidar/voxel_grid.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <mutex>
#include <random>
#include <set>

#include "lidar/preprocess.h"
#include "lidar/surface.h"

namespace jvl::lidar {
namespace {

// Points along scan-like rings (consecutive points close together, voxels revisited after a
// gap) plus a random cloud, so that both the consecutive and the scattered cases occur.
std::vector<Eigen::Vector3d> RingsAndCloud(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> pts;
  for (int ring = 0; ring < 8; ++ring) {
    const double elevation = -0.2 + 0.05 * ring;
    for (int k = 0; k < 1500; ++k) {
      const double azimuth = 2 * M_PI * k / 1500.0;
      const double range = 8 + 3 * std::sin(3 * azimuth) + 0.05 * u(rng);
      pts.emplace_back(range * std::cos(azimuth), range * std::sin(azimuth),
                       range * std::sin(elevation));
    }
  }
  for (int k = 0; k < 3000; ++k) pts.emplace_back(6 * u(rng), 6 * u(rng), 2 * u(rng));
  return pts;
}

std::vector<int> NeighboursWithin(const std::vector<Eigen::Vector3d>& pts, int i, double r) {
  std::vector<int> out;
  for (size_t j = 0; j < pts.size(); ++j) {
    if ((pts[j] - pts[i]).squaredNorm() <= r * r) out.push_back(static_cast<int>(j));
  }
  return out;
}

TEST(VoxelGridTest, DownsampleKeepsTheFirstPointOfEveryVoxelInInputOrder) {
  const std::vector<Eigen::Vector3d> pts = RingsAndCloud(1);
  for (const double voxel : {0.1, 0.4, 1.5}) {
    std::vector<size_t> expected;
    std::set<std::tuple<int, int, int>> seen;
    for (size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3i c = CellOf(pts[i], 1.0 / voxel);
      if (seen.insert({c.x(), c.y(), c.z()}).second) expected.push_back(i);
    }
    EXPECT_EQ(VoxelDownsample(pts, voxel), expected) << voxel;
  }
}

TEST(VoxelGridTest, EveryCellSeesItsMembersFirstAndEveryPointWithinTheCellSize) {
  const std::vector<Eigen::Vector3d> pts = RingsAndCloud(2);
  const double cell = 0.7;
  const PointGrid grid(pts, cell);
  std::vector<int> visits(pts.size(), 0);
  std::mutex mutex;
  grid.ForEachCell(2, [&](const std::vector<int>& members, const std::vector<int>& cand) {
    ASSERT_FALSE(members.empty());
    ASSERT_GE(cand.size(), members.size());
    // The cell itself first: its members, in the same order.
    EXPECT_TRUE(std::equal(members.begin(), members.end(), cand.begin()));
    const std::set<int> in(cand.begin(), cand.end());
    EXPECT_EQ(in.size(), cand.size()) << "a candidate twice";
    const Eigen::Vector3i c = CellOf(pts[members.front()], 1.0 / cell);
    for (const int m : members) {
      EXPECT_EQ(CellOf(pts[m], 1.0 / cell), c);
      for (const int j : NeighboursWithin(pts, m, cell)) {
        EXPECT_TRUE(in.count(j)) << "point " << j << " within the cell size of " << m;
      }
    }
    // Later candidates never lie in a cell nearer than the one before them (face, edge and
    // corner neighbours in that order).
    int previous = 0;
    for (size_t k = members.size(); k < cand.size(); ++k) {
      const Eigen::Vector3i d = CellOf(pts[cand[k]], 1.0 / cell) - c;
      ASSERT_LE(d.cwiseAbs().maxCoeff(), 1);
      const int nonzero = (d.x() != 0) + (d.y() != 0) + (d.z() != 0);
      EXPECT_GE(nonzero, std::max(previous, 1));
      previous = nonzero;
    }
    std::lock_guard<std::mutex> lock(mutex);
    for (const int m : members) ++visits[m];
  });
  for (size_t i = 0; i < pts.size(); ++i) ASSERT_EQ(visits[i], 1) << i;
}

TEST(VoxelGridTest, CountWithinCountsExactlyAndStopsWhereAsked) {
  const std::vector<Eigen::Vector3d> pts = RingsAndCloud(3);
  const double r = 0.5;
  const PointGrid grid(pts, r);
  for (size_t i = 0; i < pts.size(); i += 37) {
    const int n = static_cast<int>(NeighboursWithin(pts, static_cast<int>(i), r).size());
    EXPECT_EQ(grid.CountWithin(pts[i], r), n) << i;
    for (const int stop : {1, 3, 8})
      EXPECT_EQ(grid.CountWithin(pts[i], r, stop), std::min(n, stop));
  }
}

TEST(VoxelGridTest, RadiusOutlierMaskMatchesTheDefinition) {
  const std::vector<Eigen::Vector3d> pts = RingsAndCloud(4);
  for (const int min_neighbors : {1, 2, 6}) {
    const std::vector<uint8_t> keep = RadiusOutlierMask(pts, 0.3, min_neighbors, "grid", 2);
    int64_t kept = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      const int others =
          static_cast<int>(NeighboursWithin(pts, static_cast<int>(i), 0.3).size()) - 1;
      ASSERT_EQ(keep[i], others >= min_neighbors ? 1 : 0) << i << " " << min_neighbors;
      kept += keep[i];
    }
    // Both outcomes occur, so the comparison means something.
    EXPECT_GT(kept, 0);
    EXPECT_LT(kept, static_cast<int64_t>(pts.size()));
  }
}

// The normal of every point is the PCA of its k nearest neighbours within the radius (ties by
// index), found here by brute force.
TEST(VoxelGridTest, SurfaceNormalsComeFromTheNearestNeighbours) {
  const std::vector<Eigen::Vector3d> pts = RingsAndCloud(5);
  SurfaceOptions o;
  o.normal_radius = 0.6;
  const ScanSurface s = ComputeSurface(pts, o, 2);
  int checked = 0;
  for (size_t i = 0; i < pts.size(); i += 11) {
    std::vector<std::pair<double, int>> nn;
    for (size_t j = 0; j < pts.size(); ++j) {
      const double d2 = (pts[j] - pts[i]).squaredNorm();
      if (d2 <= o.normal_radius * o.normal_radius) nn.emplace_back(d2, static_cast<int>(j));
    }
    std::sort(nn.begin(), nn.end());
    if (nn.size() > static_cast<size_t>(o.normal_neighbors)) nn.resize(o.normal_neighbors);
    if (nn.size() < static_cast<size_t>(o.min_normal_neighbors)) {
      EXPECT_EQ(s.valid[i], 0) << i;
      continue;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& e : nn) mean += pts[e.second];
    mean /= static_cast<double>(nn.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& e : nn) {
      const Eigen::Vector3d d = pts[e.second] - mean;
      cov += d * d.transpose();
    }
    cov /= static_cast<double>(nn.size());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    Eigen::Vector3d n = eig.eigenvectors().col(0).normalized();
    if (n.dot(pts[i]) > 0) n = -n;
    ASSERT_EQ(s.valid[i], 1) << i;
    EXPECT_NEAR((s.normals[i] - n).norm(), 0.0, 1e-9) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

}  // namespace
}  // namespace jvl::lidar
