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

}  // namespace
}  // namespace jvl::vision
