#include "direction/vp_priors.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "direction/synthetic_vps.h"
#include "geometry/angles.h"
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
    const Eigen::Vector2d v =
        camera.Project(pose.rotation().conjugate() * rc.truth) + Eigen::Vector2d(g(rng), g(rng));
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

// Keyframes along a road with roll and pitch wobble; each sees the world's up (plus noise) and a
// forward VP; one keyframe's vertical candidate is 5 deg off (a leaning edge).
TEST(VpPriors, SelectVerticalTakesTheVpNearestUpAndGatesOutliers) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.1 * M_PI / 180.0);
  const Eigen::Vector3d up(0, -1, 0);  // KITTI camera world: y down
  Trajectory kf;
  std::vector<VpRay> rays;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Matrix3d r =
        (Eigen::AngleAxisd(0.02 * std::sin(0.3 * i), Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(0.01 * std::cos(0.2 * i), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    kf.Append(2 * i, Rigid3d(Eigen::Quaterniond(r), Eigen::Vector3d(0, 0, i)));
    Eigen::Vector3d ray = r.transpose() * up;  // up in the camera
    ray = (ray + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))).normalized();
    if (i == 17) ray = Eigen::AngleAxisd(5.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * ray;
    rays.push_back({2 * i, (i % 2 ? -1.0 : 1.0) * ray});                    // unoriented
    rays.push_back({2 * i, Eigen::Vector3d(0.01, 0.0, 1.0).normalized()});  // forward VP
  }
  rays.push_back({1, Eigen::Vector3d(0, 1, 0)});  // not a keyframe
  const VerticalSelection v = SelectVertical(kf, rays, up, 10.0, 1.0, 0.05);
  EXPECT_EQ(v.candidates, 40);
  EXPECT_EQ(v.outliers, 1);
  ASSERT_EQ(v.rows.size(), 39u);
  EXPECT_EQ(std::count(v.rows.begin(), v.rows.end(), 17), 0);
  EXPECT_LT(AngleDeg(v.direction, up), 0.1);
  EXPECT_GT(v.sigma_deg, 0.05);
  EXPECT_LT(v.sigma_deg, 0.3);
  EXPECT_GE(v.inflation, 1.0);
  // No VP near up: nothing selected.
  const VerticalSelection none =
      SelectVertical(kf, {{0, Eigen::Vector3d::UnitZ()}}, up, 10.0, 1.0, 0.05);
  EXPECT_EQ(none.candidates, 0);
  EXPECT_TRUE(none.rows.empty());
}

// Errors shared by neighbouring keyframes (the same edges seen twice) inflate sigma; independent
// ones barely do.
TEST(VpPriors, SelectVerticalInflatesSigmaForCorrelatedErrors) {
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.2 * M_PI / 180.0);
  const Eigen::Vector3d up(0, -1, 0);
  Trajectory kf;
  std::vector<VpRay> independent, correlated;
  Eigen::Vector3d shared = Eigen::Vector3d::Zero();
  for (int i = 0; i < 200; ++i) {
    kf.Append(i, Rigid3d());
    const Eigen::Vector3d e(noise(rng), 0.0, noise(rng));
    independent.push_back({i, (up + e).normalized()});
    if (i % 8 == 0) shared = e;  // the same error for 8 keyframes in a row
    correlated.push_back({i, (up + shared).normalized()});
  }
  const VerticalSelection a = SelectVertical(kf, independent, up, 10.0, 1.0, 0.05);
  const VerticalSelection b = SelectVertical(kf, correlated, up, 10.0, 1.0, 0.05);
  EXPECT_LT(a.rho, 0.2);
  EXPECT_GT(b.rho, 0.7);
  EXPECT_GT(b.inflation, 2.0 * a.inflation);
}

// White noise alone leaves no low-frequency error; a slow drift on one axis shows as about its
// RMS on that axis, and the white part is measured from consecutive differences either way.
TEST(VpPriors, MeasureSlowErrorSeparatesDriftFromWhiteNoise) {
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.2);
  std::vector<int64_t> frames;
  std::vector<Eigen::Vector2d> white, drift;
  double drift_ms = 0;
  for (int i = 0; i < 600; ++i) {
    frames.push_back(i);
    const Eigen::Vector2d e(noise(rng), noise(rng));
    white.push_back(e);
    const double slow = 0.3 * std::sin(2.0 * M_PI * i / 300.0);  // RMS 0.212 deg
    drift_ms += slow * slow / 600.0;
    drift.push_back(e + Eigen::Vector2d(0.0, slow));
  }
  const SlowError a = MeasureSlowError(frames, white, 10);
  EXPECT_NEAR(a.white_deg.x(), 0.2, 0.02);
  EXPECT_NEAR(a.white_deg.y(), 0.2, 0.02);
  EXPECT_LT(a.low_frequency_deg.maxCoeff(), 0.03);
  const SlowError b = MeasureSlowError(frames, drift, 10);
  EXPECT_NEAR(b.white_deg.y(), 0.2, 0.02);
  EXPECT_LT(b.low_frequency_deg.x(), 0.03);
  EXPECT_NEAR(b.low_frequency_deg.y(), std::sqrt(drift_ms), 0.03);
  EXPECT_NEAR(b.slow_deg, std::sqrt(drift_ms), 0.03);
  // Every third frame: the same samples in a window three times as wide.
  std::vector<int64_t> sparse;
  for (const int64_t f : frames) sparse.push_back(3 * f);
  EXPECT_NEAR(MeasureSlowError(sparse, drift, 30).low_frequency_deg.y(), std::sqrt(drift_ms), 0.03);
  // Too few samples: zeros.
  EXPECT_EQ(MeasureSlowError({0, 1}, {drift[0], drift[1]}, 10).low_frequency_deg.maxCoeff(), 0.0);
  EXPECT_THROW(MeasureSlowError({1, 0, 2}, {drift[0], drift[1], drift[2]}, 10), std::exception);
  EXPECT_THROW(MeasureSlowError({0, 1}, {drift[0]}, 10), std::exception);
}

// Exact values on a short ramp (n = 20, one frame per sample): the white covariance is half the
// squared step, and a window of one sample (half_window 0) leaves the ramp's variance less
// white^2 (1 - 1/n); a window over the whole series leaves nothing (its mean is removed). The
// slow error along a ramp at 45 deg is the same as along an axis (per axis it is 1/sqrt 2 of it).
TEST(VpPriors, MeasureSlowErrorOnARampIsExactAndRotationInvariant) {
  const int n = 20;
  std::vector<int64_t> frames;
  std::vector<Eigen::Vector2d> along_x, diagonal;
  for (int i = 0; i < n; ++i) {
    frames.push_back(i);
    along_x.emplace_back(0.01 * i, 0.0);
    diagonal.emplace_back(0.01 * i / std::sqrt(2.0), 0.01 * i / std::sqrt(2.0));
  }
  // Ramp variance (n^2 - 1) / 12 steps^2 = 33.25e-4; white^2 = 0.5e-4.
  const double expected = std::sqrt(33.25e-4 - 0.5e-4 * (1.0 - 1.0 / n));
  const SlowError a = MeasureSlowError(frames, along_x, 0);
  EXPECT_NEAR(a.white_deg.x(), std::sqrt(0.5e-4), 1e-12);
  EXPECT_NEAR(a.low_frequency_deg.x(), expected, 1e-12);
  EXPECT_NEAR(a.slow_deg, expected, 1e-12);
  const SlowError d = MeasureSlowError(frames, diagonal, 0);
  EXPECT_NEAR(d.slow_deg, expected, 1e-12);
  EXPECT_NEAR(d.low_frequency_deg.x(), expected / std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(MeasureSlowError(frames, along_x, n).slow_deg, 0.0, 1e-12);
}

// The e_D errors of a cluster whose VPs share their error over runs of keyframes are correlated;
// independent errors are not.
TEST(VpPriors, DirectionErrorCorrelationSeesSharedErrors) {
  RefitCase rc = MakeRefitCase(120, 0.0, 0.0, 5);
  const PinholeCamera camera = KittiCamera();
  std::mt19937 rng(6);
  std::normal_distribution<double> noise(0.0, 2.0);
  DirectionSelection independent = rc.selection, shared = rc.selection;
  Eigen::Vector2d run = Eigen::Vector2d::Zero();
  for (size_t i = 0; i < rc.selection.priors.size(); ++i) {
    const Eigen::Vector2d e(noise(rng), noise(rng));
    independent.priors[i].vp += e;
    if (i % 6 == 0) run = e;
    shared.priors[i].vp += run;
  }
  const double a =
      DirectionErrorCorrelation(rc.keyframes, camera, independent.priors, independent.clusters);
  const double b = DirectionErrorCorrelation(rc.keyframes, camera, shared.priors, shared.clusters);
  EXPECT_LT(a, 0.3);
  EXPECT_GT(b, 0.6);
  EXPECT_LE(b, 0.9);
  EXPECT_EQ(DirectionErrorCorrelation(rc.keyframes, camera, {}, {}), 0.0);
  EXPECT_THROW(DirectionErrorCorrelation(rc.keyframes, camera, shared.priors, {}), std::exception);
}

}  // namespace
}  // namespace jvl::direction
