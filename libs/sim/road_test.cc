#include "sim/road.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "sim/describe.h"
#include "sim/prior.h"
#include "sim/random.h"
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

// Project() looks up a grid cell's pieces first; the nearest centre-line point must still be the
// nearest over the whole route, near the road and far from it (where it falls back to all pieces).
TEST(RouteTest, ProjectFindsTheNearestPieceOnALongRoute) {
  const Route route(ScenarioRoute(Scenario::kUrban, 9), Eigen::Vector2d(3, -2), 0.35);
  std::vector<Eigen::Vector2d> samples;
  for (double s = 0; s <= route.length(); s += 0.05) samples.push_back(route.At(s).position);
  Rng rng(3);
  int far = 0;
  for (int k = 0; k < 400; ++k) {
    const RoadPoint rp = route.At(rng.Uniform() * route.length());
    const double off = (k % 4 == 0 ? 150.0 : 30.0) * (2 * rng.Uniform() - 1);
    const Eigen::Vector2d p =
        rp.position + Eigen::Vector2d(off * rng.Uniform(), off * (2 * rng.Uniform() - 1));
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector2d& q : samples) nearest = std::min(nearest, (p - q).norm());
    double s, lateral;
    route.Project(p, &s, &lateral);
    EXPECT_LE(std::abs(lateral), nearest + 1e-9) << "point " << p.transpose();
    EXPECT_GE(std::abs(lateral), nearest - 0.03) << "point " << p.transpose();
    EXPECT_NEAR((route.At(s).position - p).norm(), std::abs(lateral), 1e-6);
    far += nearest > 40 ? 1 : 0;
  }
  EXPECT_GT(far, 10);  // The fallback to all pieces was exercised.
}

TEST(RouteTest, PieceIndexAndPiecesStartingIn) {
  const Route route(ScenarioRoute(Scenario::kUrban), Eigen::Vector2d::Zero(), 0.0);
  const auto& pieces = route.pieces();
  for (size_t i = 0; i < pieces.size(); ++i) {
    EXPECT_EQ(route.PieceIndex(pieces[i].s0 + 0.5 * pieces[i].length), i);
    const auto [first, last] = route.PiecesStartingIn(pieces[i].s0 - 0.1, pieces[i].s0 + 0.1);
    EXPECT_EQ(first, i);
    EXPECT_EQ(last, i + 1);
  }
  EXPECT_EQ(route.PieceIndex(pieces[1].s0), 0u);  // A shared end belongs to the earlier piece.
  EXPECT_EQ(route.PieceIndex(-5), 0u);
  EXPECT_EQ(route.PieceIndex(route.length() + 5), pieces.size() - 1);
  const auto [first, last] = route.PiecesStartingIn(route.length(), route.length() + 10);
  EXPECT_EQ(first, last);
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

// Every repeated piece of `route` lies on the geometry laid out before it (Distance ignores
// repeated pieces). Returns their total length.
double RepeatedLengthOnTheRoad(const Route& route) {
  double repeated = 0;
  for (const RoadPiece& piece : route.pieces()) {
    if (!piece.repeat) continue;
    repeated += piece.length;
    for (double t = 0; t <= piece.length; t += piece.length / 20)
      EXPECT_LT(route.Distance(route.At(piece.s0 + t).position), 1e-6) << "piece at " << piece.s0;
  }
  return repeated;
}

struct ThreeAndTwoLaps {
  std::unique_ptr<World> three, two;
};

// The world of `scenario` with 3 and with 2 laps (no scans or images): a third lap adds no world
// (the same buildings and as many plants), there are more than `min_buildings` buildings, and
// every one stands clear of every road.
ThreeAndTwoLaps BuildThreeAndTwoLaps(Scenario scenario, size_t min_buildings) {
  SequenceOptions opt;
  opt.scenario = scenario;
  opt.laps = 3;
  opt.render_images = opt.simulate_scans = false;
  ThreeAndTwoLaps w;
  w.three = BuildWorld(opt);
  opt.laps = 2;
  w.two = BuildWorld(opt);
  const Scene& scene = w.three->scene;
  EXPECT_EQ(w.two->scene.buildings.size(), scene.buildings.size());
  for (size_t i = 0; i < std::min(scene.buildings.size(), w.two->scene.buildings.size()); ++i)
    EXPECT_EQ(w.two->scene.buildings[i].center, scene.buildings[i].center);
  EXPECT_EQ(w.two->scene.plants.size(), scene.plants.size());
  EXPECT_GT(scene.buildings.size(), min_buildings);
  for (const Building& b : scene.buildings)
    for (const auto& c : b.Corners())
      EXPECT_GT(scene.route.Distance(c),
                scene.options.road_half_width + scene.options.sidewalk_width - 0.3);
  return w;
}

// The loop scenario: a street, three circuits of a block and back. Every repeated piece lies on
// the geometry laid out before it (Distance ignores repeated pieces), the drive ends where it
// started, and the world has every building and plant once, clear of every road.
TEST(RouteTest, LoopRevisitsTheBlockAndTheStreet) {
  EXPECT_EQ(ParseScenario("loop"), Scenario::kLoop);
  EXPECT_EQ(ToString(Scenario::kLoop), "loop");
  const Route route(ScenarioRoute(Scenario::kLoop, 3), Eigen::Vector2d(5, -3), 0.35);
  // 150 m there, 3 x 459.4 m around the block, 150 m back (the corners at J shorten both by R
  // and add a quarter circle each).
  const double circuit = 2 * (130 + 110) - 8 * 12 + 2 * M_PI * 12;
  EXPECT_NEAR(route.length(), 150 + 3 * circuit + 150, 1e-6);
  EXPECT_LT((route.At(route.length()).position - Eigen::Vector2d(5, -3)).norm(), 1e-9);
  const double repeated = RepeatedLengthOnTheRoad(route);
  // Revisited: circuits 2 and 3 but for the new left turn at J, and the street back.
  EXPECT_NEAR(repeated, 2 * circuit - 12 * M_PI / 2 + 138, 1e-6);
  const ThreeAndTwoLaps worlds = BuildThreeAndTwoLaps(Scenario::kLoop, 20);
  const Scene& scene = worlds.three->scene;
  // Poles along the way out move.
  EXPECT_LE(scene.poles.size(), worlds.two->scene.poles.size() + 2);
  for (size_t i = 0; i < scene.plants.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      EXPECT_GT((scene.plants[i].center - scene.plants[j].center).norm(), 1.0);
}

// The figure-eight scenario: a street, three eights round two blocks and back. Every repeated
// piece lies on the geometry laid out before it, the drive ends where it started, the route
// crosses itself at X (once per eight heading west, once heading north: at right angles), and
// a third eight adds no world; the world stays clear of every street, the crossing's included.
TEST(RouteTest, FigureEightCrossesItselfAndRevisitsBothBlocks) {
  EXPECT_EQ(ParseScenario("figure8"), Scenario::kFigureEight);
  EXPECT_EQ(ToString(Scenario::kFigureEight), "figure8");
  EXPECT_TRUE(IsUrbanLike(Scenario::kFigureEight));  // The loop's city scenery.
  EXPECT_FALSE(IsUrbanLike(Scenario::kSuburban));
  const Route route(ScenarioRoute(Scenario::kFigureEight, 3), Eigen::Vector2d(5, -3), 0.35);
  const double R = 12, arc = M_PI / 2 * R;
  // Round B (four sides, three corners) and round A from X to the corner before J (three
  // sides, two corners), then J to X: straight on (130 m) on the first eight, a right corner
  // and 118 m on the others.
  const double b = 2 * (110 + 130) - 6 * R + 3 * arc, a = 2 * 110 + 130 - 5 * R + 2 * arc;
  EXPECT_NEAR(route.length(), 150 + (130 + b + a) + 2 * (arc + 130 - R + b + a) + arc + 150 - R,
              1e-6);
  EXPECT_LT((route.At(route.length()).position - Eigen::Vector2d(5, -3)).norm(), 1e-9);
  const double repeated = RepeatedLengthOnTheRoad(route);
  // Revisited: eights 2 and 3 but for the new right corner at J, and the street back.
  EXPECT_NEAR(repeated, 2 * (arc + 130 - R + b + a) - arc + 150 - R, 1e-6);
  // X: 280 m (the street and J-X) into the drive, in the start heading; again after B's
  // circuit (three left corners), a quarter turn to the right of it.
  const RoadPoint west = route.At(150 + 130), north = route.At(150 + 130 + b);
  EXPECT_LT((west.position - north.position).norm(), 1e-6);
  EXPECT_NEAR(std::remainder(north.heading - west.heading, 2 * M_PI), -M_PI / 2, 1e-9);
  BuildThreeAndTwoLaps(Scenario::kFigureEight, 30);
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

// The road and the world continue beyond both ends of the drive: the drive covers exactly the
// scenario's pieces, from the map origin, and buildings stand along the road past its end.
TEST(DriveTest, TheWorldContinuesBeyondBothEndsOfTheDrive) {
  const std::vector<RoadPiece> pieces = ScenarioRoute(Scenario::kUrban);
  double driven = 0;
  for (const RoadPiece& p : pieces) driven += p.length;
  SequenceOptions opt;
  ASSERT_EQ(opt.road_beyond, 120.0);
  const auto world = BuildWorld(opt);
  const Route& route = world->scene.route;
  ASSERT_EQ(route.pieces().size(), pieces.size() + 2);
  EXPECT_TRUE(route.pieces().front().lead && route.pieces().back().lead);
  EXPECT_NEAR(route.drive_begin(), 120.0, 1e-9);
  EXPECT_NEAR(route.drive_end() - route.drive_begin(), driven, 1e-9);
  EXPECT_NEAR(route.length(), driven + 240.0, 1e-9);
  EXPECT_LT(route.At(route.drive_begin()).position.norm(), 1e-9);  // The drive starts at 0.
  EXPECT_DOUBLE_EQ(world->drive.s.front(), route.drive_begin());
  EXPECT_DOUBLE_EQ(world->drive.s.back(), route.drive_end());
  // Buildings along the lead pieces, beyond both ends of the drive.
  int before = 0, after = 0;
  for (const Building& b : world->scene.buildings) {
    double s, lateral;
    route.Project(b.center, &s, &lateral);
    before += s < route.drive_begin() - 20 ? 1 : 0;
    after += s > route.drive_end() + 20 ? 1 : 0;
  }
  EXPECT_GE(before, 4);
  EXPECT_GE(after, 4);
  // The summary describes the drive only (the leads are not turns or straights of it).
  const RouteSummary r = SummarizeRoute(*world);
  opt.road_beyond = 0;  // The former world: it ends where the drive does.
  const auto bare = BuildWorld(opt);
  const RouteSummary r0 = SummarizeRoute(*bare);
  EXPECT_EQ(r.turns, r0.turns);
  EXPECT_EQ(r.straights_100m, r0.straights_100m);
  EXPECT_NEAR(r.driven_length_m, r0.driven_length_m, 0.5);
  EXPECT_EQ(bare->scene.route.pieces().size(), pieces.size());
  EXPECT_EQ(bare->scene.route.drive_begin(), 0.0);
  EXPECT_EQ(bare->scene.route.drive_end(), bare->scene.route.length());
  opt.road_beyond = -1;
  EXPECT_THROW(BuildWorld(opt), std::exception);
}

// A loop route ends driving back along its first street: the trailing lead retraces the
// leading one (marked repeat), so the world is laid out there once.
TEST(RouteTest, LoopLeadsRetraceEachOther) {
  const Route route(WithLeads(ScenarioRoute(Scenario::kLoop, 2), 100), Eigen::Vector2d(-100, 0),
                    0.0);
  const RoadPiece& in = route.pieces().front();
  const RoadPiece& out = route.pieces().back();
  EXPECT_TRUE(in.lead && out.lead && out.repeat && !in.repeat);
  EXPECT_LT((route.At(route.length()).position - in.start).norm(), 1e-6);
  EXPECT_LT(route.At(route.drive_begin()).position.norm(), 1e-9);
  EXPECT_LT(route.At(route.drive_end()).position.norm(), 1e-6);
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

// Largest change of the yaw rate (rad/s) between consecutive 10 ms steps of the urban drive, and
// the largest angle (rad) between the vehicle's heading and its direction of motion.
struct YawRateChange {
  double max_change = 0;
  double max_slip = 0;
};

YawRateChange MeasureYawRate(double steer_transition) {
  const Route route(ScenarioRoute(Scenario::kUrban), Eigen::Vector2d::Zero(), 0.0);
  DriveOptions options;
  options.steer_transition = steer_transition;
  const Drive drive = PlanDrive(route, options);
  const Terrain terrain;
  const auto yaw_at = [&](double t) {
    const Eigen::Matrix3d R = VehiclePose(route, terrain, drive, options, t, 7).RotationMatrix();
    return std::atan2(R(1, 0), R(0, 0));
  };
  YawRateChange out;
  const double dt = 0.01;
  double previous_rate = std::numeric_limits<double>::quiet_NaN();
  for (double t = dt; t < drive.duration() - dt; t += dt) {
    const double rate = std::remainder(yaw_at(t + dt) - yaw_at(t), 2 * M_PI) / dt;
    if (std::isfinite(previous_rate)) {
      out.max_change = std::max(out.max_change, std::abs(rate - previous_rate));
    }
    previous_rate = rate;
    const Eigen::Vector3d step =
        VehiclePose(route, terrain, drive, options, t + dt, 7).translation() -
        VehiclePose(route, terrain, drive, options, t - dt, 7).translation();
    if (step.head<2>().norm() > 1e-3) {
      const double motion = std::atan2(step.y(), step.x());
      out.max_slip = std::max(out.max_slip, std::abs(std::remainder(motion - yaw_at(t), 2 * M_PI)));
    }
  }
  return out;
}

// Where a straight meets a 12 m corner, following the centre line steps the yaw rate by v k
// (about 0.6 rad/s) within one instant; the steering transition ramps it over 6 m, so between
// 10 ms steps it changes by v^2 k / 6 m * 10 ms (below 0.01 rad/s). The heading stays the
// direction of motion either way (no side slip beyond the lane-keeping weave's).
TEST(DriveTest, SteerTransitionRampsTheYawRate) {
  const YawRateChange stepped = MeasureYawRate(0.0);
  const YawRateChange ramped = MeasureYawRate(6.0);
  EXPECT_GT(stepped.max_change, 0.3);
  EXPECT_LT(ramped.max_change, 0.02);
  EXPECT_LT(stepped.max_slip, 0.01);
  EXPECT_LT(ramped.max_slip, 0.01);
  DriveOptions bad;
  bad.steer_transition = -1;
  EXPECT_THROW(bad.Check(), std::exception);
}

// A motion-distorted sweep reaches 0.05 s before the first frame and after the last: the vehicle
// keeps moving there instead of standing at the route's ends.
TEST(DriveTest, SweepsBeyondTheDriveKeepMoving) {
  const Route route(ScenarioRoute(Scenario::kUrban), Eigen::Vector2d::Zero(), 0.0);
  const DriveOptions options;
  const Drive drive = PlanDrive(route, options);
  const Terrain terrain;
  const auto position = [&](double t) {
    return VehiclePose(route, terrain, drive, options, t, 7).translation();
  };
  const double end = drive.duration();
  EXPECT_NEAR((position(0) - position(-0.05)).norm(), 0.05 * drive.v.front(), 1e-3);
  EXPECT_NEAR((position(end + 0.05) - position(end)).norm(), 0.05 * drive.v.back(), 1e-3);
  EXPECT_NEAR(DriveArcLength(drive, -0.05), drive.s.front() - 0.05 * drive.v.front(), 1e-12);
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
