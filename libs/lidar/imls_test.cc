#include "lidar/imls.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "lidar/surface.h"

namespace jvl::lidar {
namespace {

TEST(ImlsTest, PlaneDistanceAndProjection) {
  std::vector<Eigen::Vector3d> pts, normals;
  for (double x = -2; x <= 2; x += 0.1) {
    for (double y = -2; y <= 2; y += 0.1) {
      pts.emplace_back(x, y, 1.0);
      normals.emplace_back(0, 0, 1);
    }
  }
  ImlsModel model(0.5);
  model.AddScan(7, pts, normals);
  for (const double off : {-0.3, -0.05, 0.0, 0.12, 0.4}) {
    const Eigen::Vector3d x(0.33, -0.71, 1.0 + off);
    ImlsProjection p;
    ASSERT_TRUE(model.Project(x, 0.2, 0.5, &p)) << off;
    EXPECT_NEAR(p.distance, off, 1e-9);
    EXPECT_LT((p.projection - Eigen::Vector3d(0.33, -0.71, 1.0)).norm(), 1e-9);
    EXPECT_EQ(p.nearest_scan, 7);
  }
  ImlsProjection p;
  EXPECT_FALSE(model.Project(Eigen::Vector3d(0, 0, 1.6), 0.2, 0.5, &p));
  EXPECT_TRUE(model.HasNeighbor(Eigen::Vector3d(0, 0, 1.4), 0.5));
  EXPECT_FALSE(model.HasNeighbor(Eigen::Vector3d(0, 0, 1.6), 0.5));
}

TEST(ImlsTest, SphereDistance) {
  // Points on a sphere of radius 5 (spacing ~0.05 m), outward normals.
  const double radius = 5.0;
  std::vector<Eigen::Vector3d> pts, normals;
  for (double theta = 1.2; theta <= 1.9; theta += 0.01) {
    for (double phi = -0.35; phi <= 0.35; phi += 0.01) {
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              std::cos(theta));
      pts.push_back(radius * n);
      normals.push_back(n);
    }
  }
  ImlsModel model(0.5);
  model.AddScan(0, pts, normals);
  const Eigen::Vector3d dir = Eigen::Vector3d(1, 0.1, -0.05).normalized();
  for (const double off : {-0.2, -0.05, 0.1, 0.25}) {
    ImlsProjection p;
    ASSERT_TRUE(model.Project((radius + off) * dir, 0.1, 0.5, &p));
    // Curvature bias of the kernel average is O(h^2 / R); the normal of the nearest sample
    // is within half a grid step of dir.
    EXPECT_NEAR(p.distance, off, 0.01) << off;
    EXPECT_NEAR(p.projection.norm(), radius, 0.01) << off;
  }
}

TEST(ImlsTest, ScansAddedAndRemoved) {
  ImlsModel model(1.0);
  model.AddScan(1, {{0, 0, 0}, {0.5, 0, 0}}, {{0, 0, 1}, {0, 0, 1}});
  model.AddScan(2, {{0, 0, 0.2}}, {{0, 0, 1}});
  EXPECT_EQ(model.size(), 3u);
  EXPECT_EQ(model.scan_ids(), (std::vector<int64_t>{1, 2}));
  model.RemoveScan(1);
  EXPECT_EQ(model.size(), 1u);
  ImlsProjection p;
  ASSERT_TRUE(model.Project(Eigen::Vector3d(0, 0, 0.5), 0.1, 1.0, &p));
  EXPECT_NEAR(p.distance, 0.3, 1e-6);  // Model stored in single precision.
  EXPECT_EQ(p.nearest_scan, 2);
  model.RemoveScan(42);  // Absent: no-op.
  model.RemoveScan(2);
  EXPECT_EQ(model.size(), 0u);
  EXPECT_FALSE(model.HasNeighbor(Eigen::Vector3d::Zero(), 1.0));
}

// A sliding window of scans moving along a street (as lidar_odom's map): after thousands of
// cells were emptied and dropped from the index, the model answers exactly as one built from the
// scans still in it, and an emptied cell filled again is found.
TEST(ImlsTest, SlidingWindowAnswersAsAFreshModel) {
  auto scan = [](int s) {
    std::vector<Eigen::Vector3d> pts, normals;
    for (int i = 0; i < 400; ++i) {
      const double x = 2.0 * s + 0.05 * i, y = 0.3 * std::sin(0.7 * i + s);
      pts.emplace_back(x, y, 0.01 * (i % 7));
      normals.push_back(Eigen::Vector3d(0.1 * std::cos(i), 0, 1).normalized());
      pts.emplace_back(x, 4.0, 0.2 * (i % 11));
      normals.emplace_back(0, -1, 0);
    }
    return std::make_pair(pts, normals);
  };
  ImlsModel window(0.3);
  const int kWindow = 5, kScans = 120;
  for (int s = 0; s < kScans; ++s) {
    const auto [pts, normals] = scan(s);
    window.AddScan(s, pts, normals);
    if (s >= kWindow) window.RemoveScan(s - kWindow);
  }
  // The street driven back: the cells of scan 3, emptied long ago, filled again.
  const auto [back_pts, back_normals] = scan(3);
  window.AddScan(1000, back_pts, back_normals);
  ImlsModel fresh(0.3);
  for (const int64_t id : window.scan_ids()) {
    const auto [pts, normals] = scan(id == 1000 ? 3 : static_cast<int>(id));
    fresh.AddScan(id, pts, normals);
  }
  ASSERT_EQ(window.size(), fresh.size());
  int found = 0;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d x(0.08 * i, 0.37 * std::sin(0.3 * i) + (i % 3 == 0 ? 4 : 0),
                            0.05 * (i % 9));
    ImlsProjection a, b;
    const bool ha = window.Project(x, 0.15, 0.3, &a), hb = fresh.Project(x, 0.15, 0.3, &b);
    ASSERT_EQ(ha, hb) << i;
    ASSERT_EQ(window.HasNeighbor(x, 0.3), fresh.HasNeighbor(x, 0.3)) << i;
    if (!ha) continue;
    ++found;
    EXPECT_EQ(a.distance, b.distance) << i;  // The same sums in the same order.
    EXPECT_EQ(a.nearest_scan, b.nearest_scan) << i;
    EXPECT_EQ(a.neighbors, b.neighbors) << i;
  }
  EXPECT_GT(found, 100);
  ImlsProjection p;
  EXPECT_TRUE(window.Project(back_pts[10], 0.15, 0.3, &p));
  EXPECT_EQ(p.nearest_scan, 1000);
  EXPECT_FALSE(window.Project(scan(50).first[10], 0.15, 0.3, &p));  // Removed long ago.
}

// A query visits the cells within the radius of x: it finds what a model of one cell holding
// every point finds (the same count, nearest point and normal, the same weighted mean up to the
// order of the sums), near cell faces, edges and corners, for a radius of one cell and of 1.5
// cells (5 x 5 x 5 cells), and 3 km from the origin, where the stored single-precision points are
// rounded to 0.1 mm.
TEST(ImlsTest, QueriesFindWhatOneCellOfEveryPointFinds) {
  for (const double offset : {0.0, 3000.0}) {
    for (const double radius : {0.3, 0.45}) {
      std::mt19937 rng(11);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      const Eigen::Vector3d origin(offset, -0.5 * offset, 0.1 * offset);
      std::vector<Eigen::Vector3d> pts, normals;
      for (int i = 0; i < 4000; ++i) {
        const double a = u(rng), b = u(rng), c = u(rng);
        pts.push_back(origin + Eigen::Vector3d(a, b, 0.3 * c));
        const double nx = u(rng), ny = u(rng);
        normals.push_back(Eigen::Vector3d(0.2 * nx, 0.2 * ny, 1.0).normalized());
      }
      ImlsModel model(0.3), one_cell(1e4);
      model.AddScan(0, pts, normals);
      one_cell.AddScan(0, pts, normals);
      const double h = 0.15;
      int found = 0, missed = 0;
      for (int q = 0; q < 3000; ++q) {
        const double a = u(rng), b = u(rng), c = u(rng);
        Eigen::Vector3d x = origin + Eigen::Vector3d(a, b, 0.8 * c);  // points: |z| <= 0.3
        // Half the queries within 1 mm of the grid's faces, edges and corners.
        for (int axis = 0; axis < 3 && q % 2 == 0; ++axis) {
          const double jitter = 0.001 * u(rng);
          if (q % (4 + 2 * axis) == 0) x[axis] = 0.3 * std::round(x[axis] / 0.3) + jitter;
        }
        ASSERT_EQ(model.HasNeighbor(x, radius), one_cell.HasNeighbor(x, radius)) << q;
        ImlsProjection p, all;
        const bool hit = model.Project(x, h, radius, &p);
        ASSERT_EQ(hit, one_cell.Project(x, h, radius, &all)) << q;
        if (!hit) {
          ++missed;
          continue;
        }
        ++found;
        EXPECT_EQ(p.neighbors, all.neighbors) << q;
        EXPECT_EQ(p.nearest, all.nearest) << q;
        EXPECT_EQ(p.normal, all.normal) << q;
        EXPECT_NEAR(p.distance, all.distance, 1e-12) << q;
      }
      EXPECT_GT(found, 1000) << radius;
      EXPECT_GT(missed, 10) << radius;  // queries far from every point too
    }
  }
}

TEST(SurfaceTest, NormalsAndPlanarityOfAPlaneAndALine) {
  std::vector<Eigen::Vector3d> pts;
  for (double x = -3; x <= 3; x += 0.25) {
    for (double z = 5; z <= 11; z += 0.25) pts.emplace_back(x, 1.5, z);  // Ground below.
  }
  const size_t n_plane = pts.size();
  for (double z = 5; z <= 11; z += 0.2) pts.emplace_back(10, -3, z);  // An isolated line.
  SurfaceOptions o;
  const ScanSurface s = ComputeSurface(pts, o, 2);
  for (size_t i = 0; i < n_plane; ++i) {
    ASSERT_TRUE(s.valid[i]);
    EXPECT_NEAR(s.normals[i].y(), -1.0, 1e-9);  // Towards the sensor (up is -y).
    EXPECT_GT(s.planarity[i], 0.5);             // 1 inside the patch, lower at its border.
  }
  for (size_t i = n_plane; i < pts.size(); ++i) {
    if (s.valid[i]) {
      EXPECT_LT(s.planarity[i], 0.05);
    }
  }
  // Sampling lists: translation along y is best constrained by the ground.
  const auto lists = SamplingLists(s);
  ASSERT_FALSE(lists[7].empty());
  EXPECT_LT(static_cast<size_t>(lists[7].front()), n_plane);
  const std::vector<int> picked = SelectSamples(lists, s.size(), 5, [](int) { return true; });
  EXPECT_LE(picked.size(), 45u);
  EXPECT_GE(picked.size(), 20u);
}

}  // namespace
}  // namespace jvl::lidar
