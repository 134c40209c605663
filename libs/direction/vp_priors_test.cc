#include "direction/vp_priors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "direction/synthetic_vps.h"
#include "geometry/rigid3.h"

namespace jvl::direction {
namespace {

using testing::KittiCamera;

TEST(VpPriors, SelectDirectionsSkipsNonKeyframesAndVpsAtInfinity) {
  Trajectory kf;
  kf.Append(10, Rigid3d());
  kf.Append(20, Rigid3d());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto sel = SelectDirections(kf, {{20, {600, 180}, {0, 0, 1}, 3},
                                         {15, {600, 180}, {0, 0, 1}, 3},
                                         {10, {nan, nan}, {0, 0, 1}, 3}});
  ASSERT_EQ(sel.priors.size(), 1u);
  EXPECT_EQ(sel.priors[0].keyframe, 1);  // row of frame 20
  EXPECT_EQ(sel.not_keyframe, 1);
  EXPECT_EQ(sel.at_infinity, 1);
}

// Keyframes turning slowly in yaw, each seeing the same world direction d (with pixel noise).
struct RefitCase {
  Trajectory keyframes;
  DirectionSelection selection;
  Eigen::Vector3d truth;
};

RefitCase MakeRefitCase(int n, double noise_px, double old_error_deg, uint32_t seed) {
  RefitCase rc;
  const PinholeCamera camera = KittiCamera();
  rc.truth = Eigen::Vector3d(0.02, 0.01, 1).normalized();
  const Eigen::Vector3d old =
      ExpSO3(Eigen::Vector3d(0, old_error_deg * M_PI / 180.0, 0)) * rc.truth;
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, noise_px);
  for (int i = 0; i < n; ++i) {
    const Rigid3d pose(ExpSO3(Eigen::Vector3d(0.001 * i, 0.004 * i, 0)),
                       Eigen::Vector3d(0, 0, 2.0 * i));
    rc.keyframes.Append(i, pose);
    const Eigen::Vector2d v = camera.Project(pose.rotation().conjugate() * rc.truth) +
                              Eigen::Vector2d(g(rng), g(rng));
    rc.selection.priors.push_back({i, v, old});
    rc.selection.clusters.push_back(4);
  }
  return rc;
}

// The re-estimated d_w follows the current rotations, not the old (prior) direction, and VPs of
// another direction (turn exit) are dropped.
TEST(VpPriors, RefitDirectionsFollowsTheRotationsAndDropsOutliers) {
  RefitCase rc = MakeRefitCase(40, 1.0, 1.5, 3);
  const PinholeCamera camera = KittiCamera();
  for (int i : {5, 30}) {  // 5 deg off in yaw
    const Eigen::Vector3d off = ExpSO3(Eigen::Vector3d(0, 5 * M_PI / 180.0, 0)) * rc.truth;
    rc.selection.priors[i].vp =
        camera.Project(rc.keyframes.world_from_cam[i].rotation().conjugate() * off);
  }
  const DirectionRefit r = RefitDirections(rc.keyframes, camera, rc.selection, 1.0, 3);
  EXPECT_EQ(r.outliers, 2);
  ASSERT_EQ(r.directions.count(4), 1u);
  const double err = std::acos(std::min(1.0, r.directions.at(4).dot(rc.truth))) * 180 / M_PI;
  EXPECT_LT(err, 0.05);
  EXPECT_NEAR(r.change_deg.at(4), 1.5, 0.1);
  ASSERT_EQ(r.selection.priors.size(), 38u);
  for (const auto& c : r.selection.priors) EXPECT_EQ(c.direction_world, r.directions.at(4));
  // Too little support: the cluster is left out.
  const DirectionRefit few = RefitDirections(rc.keyframes, camera, rc.selection, 1.0, 39);
  EXPECT_TRUE(few.selection.priors.empty());
  EXPECT_EQ(few.small_cluster_vps, 38);
}

// The median |v - pi(R_nw d_w)| is 0 for consistent priors and follows a rotation error.
TEST(VpPriors, MedianDirectionErrorMeasuresTheProjectionOfDw) {
  RefitCase rc = MakeRefitCase(9, 0.0, 0.0, 5);
  const PinholeCamera camera = KittiCamera();
  EXPECT_NEAR(MedianDirectionError(rc.keyframes, camera, rc.selection.priors), 0.0, 1e-6);
  // A 0.5 deg yaw error of d_w moves its projection by about fx tan(0.5 deg) = 6.2 px.
  for (auto& p : rc.selection.priors)
    p.direction_world = ExpSO3(Eigen::Vector3d(0, 0.5 * M_PI / 180.0, 0)) * p.direction_world;
  EXPECT_NEAR(MedianDirectionError(rc.keyframes, camera, rc.selection.priors),
              camera.fx * std::tan(0.5 * M_PI / 180.0), 0.3);
  EXPECT_TRUE(std::isnan(MedianDirectionError(rc.keyframes, camera, {})));
}

}  // namespace
}  // namespace jvl::direction
