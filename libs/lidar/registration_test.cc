#include "lidar/registration.h"

#include <gtest/gtest.h>

#include "lidar/surface.h"
#include "lidar/test_scenes.h"
#include "lidar/voxel_grid.h"

namespace jvl::lidar {
namespace {

// Model from world points (normals by local PCA, as the odometry does).
void BuildModel(const std::vector<Eigen::Vector3d>& world, ImlsModel* model) {
  const ScanSurface s = ComputeSurface(world, SurfaceOptions(), 2);
  std::vector<Eigen::Vector3d> p, n;
  for (size_t i = 0; i < s.size(); ++i) {
    if (!s.valid[i]) continue;
    p.push_back(s.points[i]);
    n.push_back(s.normals[i]);
  }
  model->AddScan(0, p, n);
}

// IMLS-SLAM sampling of the scan (scan frame), accepting every point.
std::vector<Eigen::Vector3d> Sample(const std::vector<Eigen::Vector3d>& scan) {
  const ScanSurface s = ComputeSurface(scan, SurfaceOptions(), 2);
  const auto picked = SelectSamples(SamplingLists(s), s.size(), 100, [](int) { return true; });
  std::vector<Eigen::Vector3d> out;
  for (const int i : picked) out.push_back(scan[i]);
  return out;
}

TEST(RegistrationTest, RecoversKnownTransformFromPerturbedStarts) {
  const std::vector<Eigen::Vector3d> world = testing::StreetScene(0.15);
  const RegistrationOptions options;
  const AssociationOptions association;
  ImlsModel model(association.search_radius);
  BuildModel(world, &model);
  const Rigid3d truth(ExpSO3(Eigen::Vector3d(0.01, -0.03, 0.02)), Eigen::Vector3d(0.4, -0.1, 1.2));
  // The scan sees the same street, 0.3 m voxel like the preprocessing, from the true pose.
  std::vector<Eigen::Vector3d> scan;
  const Rigid3d scan_from_world = truth.Inverse();
  for (const size_t i : VoxelDownsample(world, 0.3)) scan.push_back(scan_from_world * world[i]);
  const std::vector<Eigen::Vector3d> samples = Sample(scan);
  ASSERT_GT(samples.size(), 300u);
  const std::vector<Vector6d> perturbations = {
      (Vector6d() << 0.2, 0, 0, 0, 0, 0).finished(),
      (Vector6d() << 0, -0.15, 0.2, 0, 0, 0).finished(),
      (Vector6d() << -0.1, 0.1, -0.25, 0.01, 0, 0.01).finished(),
      (Vector6d() << 0.05, 0.05, 0.1, -0.01, 0.02, 0).finished(),
      (Vector6d() << 0, 0, 0, 0, -0.025, -0.015).finished()};
  for (const Vector6d& d : perturbations) {
    const Rigid3d start(ExpSO3(d.tail<3>()) * truth.rotation(), truth.translation() + d.head<3>());
    const RegistrationResult r = RegisterScan(samples, model, start, association, options, 2);
    ASSERT_TRUE(r.ok);
    EXPECT_FALSE(r.degenerate) << r.min_eigenvalue;
    const Rigid3d err = truth.Inverse() * r.world_from_scan;
    EXPECT_LT(err.translation().norm(), 0.01) << d.transpose();
    EXPECT_LT(RotationAngle(err.rotation()), 2e-4) << d.transpose();
    EXPECT_LT(r.residual, 0.02);
    EXPECT_GT(r.correspondences, 300);
  }
}

TEST(RegistrationTest, CorridorIsDetectedAndKeepsTheGuessAlongIt) {
  const std::vector<Eigen::Vector3d> world = testing::CorridorScene(0.15);
  const RegistrationOptions options;
  const AssociationOptions association;
  ImlsModel model(association.search_radius);
  BuildModel(world, &model);
  std::vector<Eigen::Vector3d> scan;
  for (const size_t i : VoxelDownsample(world, 0.3)) scan.push_back(world[i]);
  // Truth is the identity; the guess is off across (x, y) and along the corridor (z).
  const Rigid3d start(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1, -0.08, 0.7));
  const RegistrationResult r = RegisterScan(Sample(scan), model, start, association, options, 2);
  ASSERT_TRUE(r.ok);
  EXPECT_TRUE(r.degenerate);
  EXPECT_GE(r.degenerate_directions, 1);  // Along z; roll has a short lever arm (3 m).
  EXPECT_LT(r.min_eigenvalue, options.degeneracy_threshold);
  EXPECT_NEAR(r.world_from_scan.translation().x(), 0.0, 0.005);
  EXPECT_NEAR(r.world_from_scan.translation().y(), 0.0, 0.005);
  EXPECT_NEAR(r.world_from_scan.translation().z(), 0.7, 0.005);  // Motion model kept.
}

TEST(RegistrationTest, EmptyModelOrScanReturnsGuessNotOk) {
  const RegistrationOptions options;
  const AssociationOptions association;
  ImlsModel empty(association.search_radius);
  const Rigid3d guess(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  const RegistrationResult a = RegisterScan({{1, 1, 1}, {2, 2, 2}}, empty, guess, association, options, 1);
  EXPECT_FALSE(a.ok);
  EXPECT_EQ(a.correspondences, 0);
  EXPECT_LT((a.world_from_scan.translation() - guess.translation()).norm(), 1e-15);
  const RegistrationResult b = RegisterScan({}, empty, guess, association, options, 1);
  EXPECT_FALSE(b.ok);
}

}  // namespace
}  // namespace jvl::lidar
