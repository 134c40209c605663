#include "sim/map_check.h"

#include <gtest/gtest.h>

#include <cmath>

namespace jvl::sim {
namespace {

// A scene with one wall x = 20 (y, z in [-50, 50]) and one parked "moving" car (speed 0).
Scene WallScene() {
  Scene scene;
  scene.route = Route(ScenarioRoute(Scenario::kUrban), Eigen::Vector2d::Zero(), 0.35);
  MovingCar car;
  car.s0 = 30;
  car.speed = 0;
  scene.moving_cars.push_back(car);
  Mesh& m = scene.mesh;
  const uint32_t face = m.AddFace(Face{});
  const uint32_t a = m.AddVertex({20, -50, -50}), b = m.AddVertex({20, 50, -50});
  const uint32_t c = m.AddVertex({20, 50, 50}), d = m.AddVertex({20, -50, 50});
  m.AddTriangle(a, b, c, face);
  m.AddTriangle(a, c, d, face);
  return scene;
}

PointView View(const Eigen::Vector3d& point, const Eigen::Vector3d& center) {
  PointView v;
  v.point = point;
  v.camera_center = center;
  v.depth = (point - center).norm();
  return v;
}

TEST(MapCheckTest, DistancesToAWall) {
  const Scene scene = WallScene();
  const RayCaster caster(scene.mesh);
  const Eigen::Vector3d c(0, 0, 0);
  // Head-on: 4 cm in front of the wall; at 45 degrees 10 cm behind it along the ray; a point
  // looking away from the wall sees nothing.
  const Eigen::Vector3d d45 = Eigen::Vector3d(1, 1, 0).normalized();
  const std::vector<PointView> views = {
      View({19.96, 0, 0}, c), View(c + (20 * std::sqrt(2.0) + 0.1) * d45, c), View({-10, 0, 0}, c)};
  const auto d = MeasureSurfaceDistances(scene, caster, views, 2);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_TRUE(d[0].hit);
  EXPECT_FALSE(d[0].moving_car);
  EXPECT_NEAR(d[0].along_ray, 0.04, 1e-4);
  EXPECT_NEAR(d[0].perpendicular, 0.04, 1e-4);
  EXPECT_TRUE(d[1].hit);
  EXPECT_NEAR(d[1].along_ray, -0.1, 1e-4);
  EXPECT_NEAR(d[1].perpendicular, 0.1 / std::sqrt(2.0), 1e-4);
  EXPECT_FALSE(d[2].hit);

  SurfaceCheckOptions options;
  options.max_depth = 40;
  options.depth_bins = {0, 25, 40};
  const SurfaceCheckSummary s = SummarizeSurfaceDistances(d, options);
  EXPECT_EQ(s.total_points, 3);
  EXPECT_EQ(s.beyond_max_depth, 0);
  EXPECT_EQ(s.all.points, 3);
  EXPECT_EQ(s.all.no_hit, 1);
  EXPECT_NEAR(s.all.within_threshold, 1.0 / 3, 1e-12);  // Only the head-on point.
  ASSERT_EQ(s.bins.size(), 2u);
  EXPECT_EQ(s.bins[0].points, 2);  // Depths 19.96 and 10.
  EXPECT_EQ(s.bins[1].points, 1);
  EXPECT_NEAR(s.bins[1].median_perpendicular, 0.1 / std::sqrt(2.0), 1e-4);
  const nlohmann::json j = ToJson(s);
  EXPECT_EQ(j["all"]["points"], 3);
  EXPECT_EQ(j["depth_bins"].size(), 2u);
}

TEST(MapCheckTest, MovingCarsAreMeasuredAtTheViewTime) {
  const Scene scene = WallScene();
  const RayCaster caster(scene.mesh);
  const Box box = scene.MovingCarBox(0, 0);
  const Eigen::Vector3d top = box.center + Eigen::Vector3d(0, 0, box.size.z() / 2);
  const Eigen::Vector3d c = box.center + Eigen::Vector3d(0, 0, 10);
  const auto d =
      MeasureSurfaceDistances(scene, caster, {View(top + Eigen::Vector3d(0, 0, 0.02), c)}, 1);
  ASSERT_TRUE(d[0].hit);
  EXPECT_TRUE(d[0].moving_car);
  EXPECT_NEAR(d[0].along_ray, 0.02, 1e-5);
  EXPECT_NEAR(d[0].perpendicular, 0.02, 1e-5);
}

TEST(MapCheckTest, NearestViewIsTheSmallestPositiveDepth) {
  // Cameras looking along +x (z axis of the camera = +x of the map).
  Eigen::Matrix3d r;
  r << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const std::vector<Rigid3d> poses = {Rigid3d(r, {0, 0, 0}), Rigid3d(r, {5, 0, 0}),
                                      Rigid3d(r, {12, 0, 0})};
  const std::vector<double> times = {0, 0.1, 0.2};
  const std::vector<Eigen::Vector3d> points = {{10, 1, 0}, {3, 0, 0}, {20, 0, 0}};
  // Point 0 seen by all three (keyframe 2 has it behind), point 1 by keyframe 0 only,
  // point 2 by none.
  const auto v = NearestViews(points, poses, times, {0, 1, 2, 0}, {0, 0, 0, 1});
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0].keyframe, 1);
  EXPECT_NEAR(v[0].depth, 5, 1e-12);
  EXPECT_NEAR(v[0].time, 0.1, 1e-12);
  EXPECT_EQ(v[1].keyframe, 0);
  EXPECT_NEAR(v[1].depth, 3, 1e-12);
  EXPECT_EQ(v[2].keyframe, -1);
  EXPECT_TRUE(std::isinf(v[2].depth));
  EXPECT_THROW(NearestViews(points, poses, times, {3}, {0}), std::exception);
}

}  // namespace
}  // namespace jvl::sim
