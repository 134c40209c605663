#include "vision/triangulation.h"

#include <gtest/gtest.h>

#include <random>

namespace jvl::vision {
namespace {

PinholeCamera KittiCamera() { return {718.856, 718.856, 607.1928, 185.2157, 1226, 370}; }

// Camera 1 at the origin, camera 2 1.5 m forward and 0.3 m left, slightly yawed.
struct TwoViews {
  Rigid3d cam1_from_world = Rigid3d();
  Rigid3d cam2_from_world =
      Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.02, 0)), Eigen::Vector3d(-0.3, 0.05, 1.5)).Inverse();
};

Eigen::Vector2d Normalised(const Rigid3d& cam_from_world, const Eigen::Vector3d& x) {
  const Eigen::Vector3d p = cam_from_world * x;
  return p.head<2>() / p.z();
}

TEST(Triangulation, DltAndMidpointRecoverKnownPoints) {
  const TwoViews v;
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(2, -1, 8), Eigen::Vector3d(-5, 1.5, 20),
                                   Eigen::Vector3d(0.3, 0.2, 4), Eigen::Vector3d(10, -2, 45)}) {
    const Eigen::Vector2d a = Normalised(v.cam1_from_world, x);
    const Eigen::Vector2d b = Normalised(v.cam2_from_world, x);
    const auto dlt = TriangulateDlt(v.cam1_from_world, v.cam2_from_world, a, b);
    const auto mid = TriangulateMidpoint(v.cam1_from_world, v.cam2_from_world, a, b);
    ASSERT_TRUE(dlt && mid);
    EXPECT_LT((*dlt - x).norm(), 1e-8 * x.norm());
    EXPECT_LT((*mid - x).norm(), 1e-8 * x.norm());
  }
}

TEST(Triangulation, ChecksParallaxDepthReprojectionAndScale) {
  const PinholeCamera cam = KittiCamera();
  const TwoViews v;
  const Eigen::Vector3d x(2, -1, 8);
  PointView a{v.cam1_from_world, cam.Project(v.cam1_from_world * x), 1.0};
  PointView b{v.cam2_from_world, cam.Project(v.cam2_from_world * x), 1.0};
  const TriangulationOptions options;
  TriangulationResult r = TriangulateTwoViews(cam, a, b, options);
  ASSERT_EQ(r.status, TriangulationStatus::kOk);
  EXPECT_LT((r.position - x).norm(), 1e-6);
  EXPECT_LT(r.cos_parallax, 0.999);

  // A point 2 km away has no usable parallax with a 1.5 m baseline.
  const Eigen::Vector3d far(10, 0, 2000);
  r = TriangulateTwoViews(cam, {a.cam_from_world, cam.Project(far), 1.0},
                          {b.cam_from_world, cam.Project(b.cam_from_world * far), 1.0}, options);
  EXPECT_EQ(r.status, TriangulationStatus::kLowParallax);

  // Moving one observation by 10 px along the epipolar direction breaks consistency:
  // either the rays meet behind a camera or far from the observations.
  PointView shifted = b;
  shifted.uv.y() += 10;
  r = TriangulateTwoViews(cam, a, shifted, options);
  EXPECT_EQ(r.status, TriangulationStatus::kReprojection);
  // At octave 3 (sigma 1.73 px) a 2 px error is accepted.
  shifted = b;
  shifted.uv.y() += 2;
  shifted.level_scale = 1.728;
  a.level_scale = 1.728;
  r = TriangulateTwoViews(cam, a, shifted, options);
  EXPECT_EQ(r.status, TriangulationStatus::kOk);

  // Same point observed at octave 0 in one view and octave 7 in the other: inconsistent scale.
  r = TriangulateTwoViews(cam, {a.cam_from_world, a.uv, 1.0}, {b.cam_from_world, b.uv, 3.58},
                          options);
  EXPECT_EQ(r.status, TriangulationStatus::kScaleInconsistent);

  // A point behind both cameras: rays triangulate behind.
  const Eigen::Vector3d behind(4, 1, -5);
  const Eigen::Vector2d xa = Normalised(v.cam1_from_world, behind);
  const Eigen::Vector2d xb = Normalised(v.cam2_from_world, behind);
  r = TriangulateTwoViews(cam, {a.cam_from_world, cam.Project(xa.homogeneous()), 1.0},
                          {b.cam_from_world, cam.Project(xb.homogeneous()), 1.0}, options);
  EXPECT_EQ(r.status, TriangulationStatus::kBehindCamera);
}

TEST(Triangulation, RefinePointReducesErrorFromNoisyStart) {
  const PinholeCamera cam = KittiCamera();
  const Eigen::Vector3d x(1.5, -0.8, 15);
  std::vector<PointView> views;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.5);
  for (int i = 0; i < 6; ++i) {
    const Rigid3d cam_from_world =
        Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1 * i, 0, 1.4 * i)).Inverse();
    const Eigen::Vector2d uv = cam.Project(cam_from_world * x);
    views.push_back({cam_from_world, uv + Eigen::Vector2d(noise(rng), noise(rng)), 1.0});
  }
  const Eigen::Vector3d start = x + Eigen::Vector3d(0.3, -0.2, 1.0);
  const Eigen::Vector3d refined = RefinePoint(cam, views, start);
  EXPECT_LT((refined - x).norm(), 0.15);
  double before = 0, after = 0;
  for (const auto& v : views) {
    before += SquaredReprojectionError(cam, v.cam_from_world, start, v.uv);
    after += SquaredReprojectionError(cam, v.cam_from_world, refined, v.uv);
  }
  EXPECT_LT(after, 0.05 * before);
  EXPECT_LT(std::sqrt(after / views.size()), 1.0);
}

// Points spread over a street-like volume in front of a camera at `cam_from_world`.
std::vector<PointObservation> StreetObservations(const PinholeCamera& cam,
                                                 const Rigid3d& cam_from_world, double noise_px,
                                                 int outliers, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> lateral(-12, 12), height(-1.7, 6), depth(4, 60);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::uniform_real_distribution<double> pixel(-40, 40);
  std::vector<PointObservation> obs;
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  while (obs.size() < 300) {
    const Eigen::Vector3d x =
        world_from_cam * Eigen::Vector3d(lateral(rng), height(rng), depth(rng));
    const Eigen::Vector2d uv = cam.Project(cam_from_world * x);
    if (uv.x() < 0 || uv.y() < 0 || uv.x() > cam.width || uv.y() > cam.height) continue;
    obs.push_back({x, uv + Eigen::Vector2d(noise(rng), noise(rng)), 1.0});
  }
  for (int i = 0; i < outliers; ++i)
    obs[static_cast<size_t>(i) * 3].uv += Eigen::Vector2d(pixel(rng), 25);
  return obs;
}

double AngleDeg(const Rigid3d& a, const Rigid3d& b) {
  return RotationAngle((a * b.Inverse()).rotation()) * 180.0 / M_PI;
}

TEST(RefinePose, RecoversAPerturbedPoseAndFlagsOutliers) {
  const PinholeCamera cam = KittiCamera();
  const Rigid3d truth =
      Rigid3d(ExpSO3(Eigen::Vector3d(0.01, 0.3, -0.02)), Eigen::Vector3d(4.0, -1.2, 25.0))
          .Inverse();
  const std::vector<PointObservation> obs = StreetObservations(cam, truth, 0.5, 30, 3);
  // A prior glitch: 0.8 deg of heading and 0.3 m sideways.
  const Rigid3d start =
      Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.014, 0)), Eigen::Vector3d(0.3, 0, 0)) * truth;
  const PoseRefinement r = RefinePose(cam, obs, start);
  ASSERT_TRUE(r.ok);
  EXPECT_LT(AngleDeg(r.cam_from_world, truth), 0.02);
  EXPECT_LT((r.cam_from_world.Inverse().translation() - truth.Inverse().translation()).norm(),
            0.05);
  // The 30 displaced observations are the outliers (a few true ones may fall beyond chi2 too).
  int flagged = 0;
  for (int i = 0; i < 30; ++i) flagged += r.inlier[static_cast<size_t>(i) * 3] ? 0 : 1;
  EXPECT_EQ(flagged, 30);
  EXPECT_GE(r.inliers, 300 - 30 - 15);
}

TEST(RefinePose, CenterPriorHoldsTheCentreWhereTheImageCannot) {
  const PinholeCamera cam = KittiCamera();
  const Rigid3d truth =
      Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.1, 0)), Eigen::Vector3d(1, 0, 3)).Inverse();
  const std::vector<PointObservation> obs = StreetObservations(cam, truth, 0.0, 0, 5);
  const Eigen::Vector3d center = truth.Inverse().translation();
  // Exact observations, but the prior puts the centre 0.2 m off: with a tight sigma the
  // estimate follows the prior, without one it follows the image.
  const Eigen::Vector3d off = center + Eigen::Vector3d(0.2, 0, 0);
  PoseRefinementOptions tight;
  tight.center_sigma = 1e-4;
  const PoseRefinement held = RefinePose(cam, obs, truth, tight, off);
  EXPECT_LT((held.cam_from_world.Inverse().translation() - off).norm(), 0.01);
  const PoseRefinement free = RefinePose(cam, obs, truth, {}, off);
  EXPECT_LT((free.cam_from_world.Inverse().translation() - center).norm(), 1e-6);
  EXPECT_LT(AngleDeg(free.cam_from_world, truth), 1e-6);
}

TEST(RefinePose, TooFewObservationsAreNotOk) {
  const PinholeCamera cam = KittiCamera();
  std::vector<PointObservation> obs = StreetObservations(cam, Rigid3d(), 0.5, 0, 9);
  obs.resize(5);
  EXPECT_FALSE(RefinePose(cam, obs, Rigid3d()).ok);
}

}  // namespace
}  // namespace jvl::vision
