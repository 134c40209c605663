#include "sim/road.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "sim/describe.h"
#include "sim/prior.h"
#include "sim/sequence.h"

namespace jvl::sim {
namespace {

TEST(RouteTest, ProjectInvertsAt) {
  const Route route(ScenarioRoute(Scenario::kUrban), Eigen::Vector2d(3, -2), 0.35);
  EXPECT_NEAR(route.length(), 130 + 110 + 55 + 60 + 2 * 12 * M_PI / 2 + 150 * M_PI / 6, 1e-9);
  for (double s = 1; s < route.length() - 1; s += 7.3) {
    for (double lat : {-4.0, -1.75, 0.5, 3.0}) {
      const RoadPoint rp = route.At(s);
      const Eigen::Vector2d p =
          rp.position + lat * Eigen::Vector2d(-std::sin(rp.heading), std::cos(rp.heading));
      double ps, pl;
      route.Project(p, &ps, &pl);
      // Near the inside of the 12 m corners another piece can be closer; require consistency.
      EXPECT_LE(std::abs(pl), std::abs(lat) + 1e-9) << "s=" << s;
      if (std::abs(pl - lat) < 1e-6) {
        EXPECT_NEAR(ps, s, 1e-6);
      }
    }
  }
}

TEST(RouteTest, PiecesJoinContinuously) {
  const Route route(ScenarioRoute(Scenario::kSuburban), Eigen::Vector2d::Zero(), 0.0);
  for (size_t i = 1; i < route.pieces().size(); ++i) {
    const double s = route.pieces()[i].s0;
    EXPECT_LT((route.At(s - 1e-7).position - route.At(s + 1e-7).position).norm(), 1e-5);
  }
}

TEST(RouteTest, StraightScenarioIsOneLongStraight) {
  EXPECT_EQ(ParseScenario("straight"), Scenario::kStraight);
  EXPECT_EQ(ToString(Scenario::kStraight), "straight");
  EXPECT_TRUE(IsHighwayLike(Scenario::kStraight) && IsHighwayLike(Scenario::kHighway));
  EXPECT_FALSE(IsHighwayLike(Scenario::kUrban));
  EXPECT_THROW(ParseScenario("motorway"), std::exception);
  const Route route(ScenarioRoute(Scenario::kStraight), Eigen::Vector2d::Zero(), 0.35);
  ASSERT_EQ(route.pieces().size(), 1u);
  EXPECT_TRUE(route.pieces().front().IsStraight());
  EXPECT_NEAR(route.length(), 1200.0, 1e-9);
  for (double s = 0; s <= route.length(); s += 100) EXPECT_NEAR(route.At(s).heading, 0.35, 1e-12);
}

TEST(DriveTest, DefaultDemoMeetsTheBrief) {
  SequenceOptions opt;
  const auto world = BuildWorld(opt);
  const RouteSummary r = SummarizeRoute(*world);
  EXPECT_GE(r.driven_length_m, 400);
  EXPECT_GE(r.straights_100m, 2);
  EXPECT_GE(r.turns, 2);
  EXPECT_GE(r.min_speed, 4.5);
  EXPECT_LE(r.max_speed, 12.0);
  EXPECT_GE(world->ground_truth.size(), 400u);
  EXPECT_LE(world->ground_truth.size(), 650u);
  EXPECT_GT(world->scene.buildings.size(), 20u);
  // Poses: world = cam0 of frame 0.
  EXPECT_LT(world->ground_truth.world_from_cam[0].translation().norm(), 1e-9);
}

TEST(TerrainTest, ScaleMultipliesTheHeightsAndZeroIsFlat) {
  SequenceOptions opt;
  opt.frames = 5;
  const auto rolling = BuildWorld(opt);
  opt.scene.terrain_scale = 0.5;
  const auto half = BuildWorld(opt);
  opt.scene.terrain_scale = 0.0;
  const auto flat = BuildWorld(opt);
  double max_height = 0;
  for (double x = -200; x <= 200; x += 13.7) {
    for (double y = -200; y <= 200; y += 11.3) {
      const double h = rolling->scene.terrain.Height(x, y);
      max_height = std::max(max_height, std::abs(h));
      EXPECT_NEAR(half->scene.terrain.Height(x, y), 0.5 * h, 1e-12);
      EXPECT_EQ(flat->scene.terrain.Height(x, y), 0.0);
      EXPECT_EQ(flat->scene.terrain.Gradient(x, y).norm(), 0.0);
    }
  }
  EXPECT_GT(max_height, 1.0);  // The default terrain does roll.
  EXPECT_EQ(DescribeScene(*flat)["terrain"]["scale"].get<double>(), 0.0);
  EXPECT_EQ(DescribeScene(*rolling)["terrain"]["scale"].get<double>(), 1.0);
  opt.scene.terrain_scale = -1;
  EXPECT_THROW(BuildWorld(opt), std::exception);
}

TEST(DriveTest, StopHoldsTheVehicle) {
  SequenceOptions opt;
  opt.stop = true;
  const auto world = BuildWorld(opt);
  int still = 0;
  const auto& gt = world->ground_truth.world_from_cam;
  for (size_t k = 1; k < gt.size(); ++k) {
    still += (gt[k].translation() - gt[k - 1].translation()).norm() < 0.01 ? 1 : 0;
  }
  EXPECT_GE(still, 20);  // About 3 s at 10 Hz.
}

TEST(PriorTest, PresetsDriftAsAdvertised) {
  SequenceOptions opt;
  const auto world = BuildWorld(opt);
  const Trajectory& gt = world->ground_truth;
  const PriorStats none = ComparePrior(gt, MakePrior(gt, PriorPreset("none", 1)));
  EXPECT_LT(none.ape_max_m, 1e-9);
  const Trajectory lidar = MakePrior(gt, PriorPreset("lidar-n1", 3));
  const PriorStats l = ComparePrior(gt, lidar);
  const PriorStats v = ComparePrior(gt, MakePrior(gt, PriorPreset("orbslam2", 3)));
  // ~470 m: a poor LiDAR odometry ends metres off, the VO-like prior less.
  EXPECT_GT(l.ape_rmse_m, 0.5);
  EXPECT_LT(l.ape_rmse_m, 6.0);
  EXPECT_LT(v.ape_rmse_m, l.ape_rmse_m);
  // Deterministic from the seed.
  const Trajectory again = MakePrior(gt, PriorPreset("lidar-n1", 3));
  EXPECT_EQ(again.world_from_cam.back().ToArray(), lidar.world_from_cam.back().ToArray());
  EXPECT_THROW(PriorPreset("bogus", 1), std::exception);
}

}  // namespace
}  // namespace jvl::sim
