#include "fidelity/stage_stats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "io/schema_check.h"

namespace jvl::fidelity {
namespace {

// A drive along the camera's z axis (forward), 1 m per frame, `n` frames, then turning: from
// frame `turn` on the heading turns by `deg_per_frame` about the camera's y axis per frame.
Trajectory Drive(int n, int turn = 1000, double deg_per_frame = 0) {
  Trajectory t;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  double yaw = 0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Quaterniond q(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()));
    t.Append(k, Rigid3d(q, p));
    if (k >= turn) yaw += deg_per_frame * M_PI / 180;
    p += Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())) *
         Eigen::Vector3d::UnitZ();
  }
  return t;
}

TEST(StageStats, OdometryStepIsSeenOnceAndInTheDriftWindowsOverIt) {
  const Trajectory gt = Drive(100);
  Trajectory est;
  for (size_t k = 0; k < gt.size(); ++k) {
    if (k == 70) continue;  // The estimate has no pose for frame 70.
    Rigid3d pose = gt.world_from_cam[k];
    if (k >= 30) pose = Rigid3d(pose.rotation(), pose.translation() + Eigen::Vector3d(0.05, 0, 0));
    est.Append(gt.frames[k], pose);
  }
  StageSeries s = MakeStageSeries(gt);
  StageStatsOptions o;
  AddOdometryStats(gt, est, o, &s);
  EXPECT_TRUE(std::isnan(s.odom_rpe_m[0]));
  EXPECT_NEAR(s.odom_rpe_m[30], 0.05, 1e-12);
  EXPECT_NEAR(s.odom_rpe_percent[30], 5.0, 1e-9);
  EXPECT_NEAR(s.odom_rpe_m[29], 0, 1e-12);
  EXPECT_NEAR(s.odom_rpe_m[31], 0, 1e-12);
  EXPECT_TRUE(std::isnan(s.odom_rpe_m[70]) && std::isnan(s.odom_rpe_m[71]));
  // The step at frame 30 points 0.05 m right of the 1 m the car moved: atan(0.05) to the right.
  EXPECT_NEAR(s.odom_direction_yaw_deg[30], std::atan(0.05) * 180 / M_PI, 1e-9);
  EXPECT_NEAR(s.odom_direction_pitch_deg[30], 0, 1e-9);
  EXPECT_NEAR(s.odom_direction_yaw_deg[31], 0, 1e-9);
  EXPECT_TRUE(std::isnan(s.odom_direction_yaw_deg[70]));
  // 50 m windows: those from frames 0..29 end at 50..79 and span the step (frame 20's window
  // ends at frame 70, which the estimate lacks); those from 30 on do not; from 50 on there is
  // not 50 m of path left.
  EXPECT_NEAR(s.odom_drift_percent[0], 0.1, 1e-9);
  EXPECT_NEAR(s.odom_drift_percent[29], 0.1, 1e-9);
  EXPECT_TRUE(std::isnan(s.odom_drift_percent[20]));
  EXPECT_NEAR(s.odom_drift_percent[30], 0, 1e-12);
  EXPECT_NEAR(s.odom_drift_percent[49], 0, 1e-12);
  EXPECT_TRUE(std::isnan(s.odom_drift_percent[50]));
  // No common frames: an error, not a silent table.
  Trajectory other;
  other.Append(500, Rigid3d());
  other.Append(501, Rigid3d());
  EXPECT_THROW(AddOdometryStats(gt, other, o, &s), std::exception);
}

TEST(StageStats, OdometryExpressedInARotatedFrameShowsAsADirectionBias) {
  // The estimate's motion expressed in a frame pitched 0.3 deg down and yawed 0.5 deg right of
  // the camera (x_est = R x_cam): every step's direction is off by that much.
  const Trajectory gt = Drive(40);
  const Eigen::Quaterniond r(Eigen::AngleAxisd(-0.3 * M_PI / 180, Eigen::Vector3d::UnitX()) *
                             Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d::UnitY()));
  const Rigid3d off(r, Eigen::Vector3d::Zero());
  Trajectory est;
  for (size_t k = 0; k < gt.size(); ++k)
    est.Append(gt.frames[k], off * gt.world_from_cam[k] * off.Inverse());
  StageSeries s = MakeStageSeries(gt);
  AddOdometryStats(gt, est, StageStatsOptions{}, &s);
  for (size_t k = 1; k < gt.size(); ++k) {
    EXPECT_NEAR(s.odom_direction_yaw_deg[k], 0.5, 1e-3);
    EXPECT_NEAR(s.odom_direction_pitch_deg[k], 0.3, 1e-3);
  }
}

TEST(StageStats, ForwardVpAgainstTheDirectionOfTravelAhead) {
  // Straight for 40 frames, then a steady left turn: the direction 20 m ahead leaves the
  // optical axis before the car turns.
  const Trajectory gt = Drive(80, 40, 1.0);
  io::VpsData vps;
  for (int64_t f = 0; f < 70; ++f) vps.frames.push_back(f);  // Frames 70-79 not processed.
  auto add = [&](int64_t frame, const Eigen::Vector3d& d) {
    io::VpRecord r;
    r.frame = frame;
    r.direction = d.normalized();
    r.is_forward = true;
    vps.vps.push_back(r);
  };
  add(5, Eigen::Vector3d::UnitZ());  // Exactly along the road.
  const double one = M_PI / 180;
  add(6, Eigen::Vector3d(std::sin(one), 0, std::cos(one)));  // 1 deg off.
  io::VpRecord side;  // A VP that is not the forward one does not count.
  side.frame = 7;
  side.direction = Eigen::Vector3d::UnitX();
  vps.vps.push_back(side);
  // Frame 21: the path turns by 1 deg within 20 m ahead (at frame 41); the exact direction to
  // the position 20 m ahead gives no error. Frame 36: the path turns by 16 deg over the 20 m
  // ahead, more than vp_max_turn_deg (2): no error is measured unless the limit is raised.
  const Eigen::Vector3d ahead =
      gt.world_from_cam[21].Inverse() * gt.world_from_cam[41].translation();
  add(21, ahead);
  add(36, Eigen::Vector3d::UnitZ());
  add(65, Eigen::Vector3d::UnitZ());  // Less than 20 m of path ahead: found, no error.
  StageSeries s = MakeStageSeries(gt);
  AddVpStats(gt, vps, StageStatsOptions{}, &s);
  EXPECT_EQ(s.vp_forward_found[5], 1.0);
  EXPECT_EQ(s.vp_forward_found[7], 0.0);
  EXPECT_TRUE(std::isnan(s.vp_forward_found[75]));
  EXPECT_NEAR(s.vp_forward_error_deg[5], 0, 1e-6);
  EXPECT_NEAR(s.vp_forward_error_deg[6], 1.0, 1e-6);
  EXPECT_TRUE(std::isnan(s.vp_forward_error_deg[7]));
  EXPECT_NEAR(s.vp_forward_error_deg[21], 0, 1e-6);
  EXPECT_EQ(s.vp_forward_found[36], 1.0);
  EXPECT_TRUE(std::isnan(s.vp_forward_error_deg[36]));
  StageStatsOptions wide;
  wide.vp_max_turn_deg = 30;
  AddVpStats(gt, vps, wide, &s);
  EXPECT_GT(s.vp_forward_error_deg[36], 1.0);
  EXPECT_EQ(s.vp_forward_found[65], 1.0);
  EXPECT_TRUE(std::isnan(s.vp_forward_error_deg[65]));
}

TEST(StageStats, VisualPointsTrackedShareAndReprojection) {
  io::VisualMapData d;
  d.camera = {500, 500, 320, 240, 640, 480};
  d.keyframes.Append(3, Rigid3d());
  d.keyframes.Append(4, Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1)));
  d.prior = d.keyframes;
  // Map points 10 m ahead of keyframe 3.
  const std::vector<Eigen::Vector3d> points = {{0, 0, 10}, {1, 0, 10}, {0, 1, 10}};
  for (const auto& p : points) {
    d.mappoint_position.insert(d.mappoint_position.end(), {p.x(), p.y(), p.z()});
    d.mappoint_descriptor.insert(d.mappoint_descriptor.end(), 32, 0);
    d.mappoint_normal.insert(d.mappoint_normal.end(), {0, 0, 1});
  }
  // Keyframe 3: 4 keypoints, 3 observations (one 3 px off); keyframe 4: 2 keypoints, 1
  // observation, exact.
  auto keypoint = [&](int keyframe, double u, double v) {
    d.keypoint_keyframe.push_back(keyframe);
    d.keypoint_uv.insert(d.keypoint_uv.end(), {static_cast<float>(u), static_cast<float>(v)});
    d.keypoint_octave.push_back(0);
    d.keypoint_angle.push_back(0);
    d.keypoint_descriptor.insert(d.keypoint_descriptor.end(), 32, 0);
    return static_cast<int32_t>(d.keypoint_keyframe.size() - 1);
  };
  auto observe = [&](int32_t keyframe, int32_t kp, int32_t m) {
    d.observation_keyframe.push_back(keyframe);
    d.observation_keypoint.push_back(kp);
    d.observation_mappoint.push_back(m);
  };
  observe(0, keypoint(0, 320, 240), 0);
  observe(0, keypoint(0, 370, 240), 1);
  observe(0, keypoint(0, 320, 293), 2);  // 50 px expected: 3 px off.
  keypoint(0, 100, 100);
  observe(1, keypoint(1, 320 + 500.0 / 9, 240), 1);
  keypoint(1, 10, 10);
  Trajectory frames;
  for (int64_t f = 0; f < 6; ++f) frames.Append(f, Rigid3d());
  StageSeries s = MakeStageSeries(frames);
  AddVisualStats(d, &s);
  EXPECT_EQ(s.visual_points[3], 3);
  EXPECT_DOUBLE_EQ(s.visual_tracked_fraction[3], 0.75);
  EXPECT_NEAR(s.visual_reprojection_px[3], 0, 1e-4);  // Median of {0, 0, 3}.
  EXPECT_EQ(s.visual_points[4], 1);
  EXPECT_DOUBLE_EQ(s.visual_tracked_fraction[4], 0.5);
  EXPECT_NEAR(s.visual_reprojection_px[4], 0, 1e-4);
  EXPECT_TRUE(std::isnan(s.visual_points[2]));
}

TEST(StageStats, SummaryMatchesTheSchemaAndLeavesOutStagesNotGiven) {
  const Trajectory gt = Drive(60);
  StageSeries s = MakeStageSeries(gt);
  AddOdometryStats(gt, gt, StageStatsOptions{}, &s);
  s.vp_forward_found = std::vector<double>(60, 1.0);
  s.vp_forward_found[0] = 0;
  const nlohmann::json stages = SummariseStages(s, true, true, false);
  EXPECT_TRUE(stages.contains("odom_rpe_m") && stages.contains("vp_forward_found"));
  EXPECT_FALSE(stages.contains("visual_points"));
  EXPECT_NEAR(stages["vp_forward_found"]["mean"].get<double>(), 59.0 / 60, 1e-12);
  EXPECT_EQ(stages["vp_forward_found"]["median"].get<double>(), 1.0);
  EXPECT_TRUE(stages["vp_forward_error_deg"]["median"].is_null());
  EXPECT_TRUE(stages["odom_rpe_m"]["frames"][0].is_null());
  nlohmann::json doc = {{"schema", "sensor_stats"},
                        {"schema_version", 1},
                        {"provenance", nlohmann::json::object()},
                        {"frames", {0}},
                        {"scan", nullptr},
                        {"image", nullptr},
                        {"stage_frames", s.frames},
                        {"stages", stages}};
  const std::string schema = std::string(JVL_SOURCE_DIR) + "/schemas/sensor_stats.schema.json";
  EXPECT_TRUE(io::CheckJsonAgainstSchema(doc, schema).empty());
  doc["stages"]["unknown"] = doc["stages"]["odom_rpe_m"];
  EXPECT_FALSE(io::CheckJsonAgainstSchema(doc, schema).empty());
}

TEST(StageStats, BadOptions) {
  StageStatsOptions o;
  o.drift_length_m = 0;
  EXPECT_THROW(o.Check(), std::exception);
  o = StageStatsOptions{};
  o.vp_lookahead_m = std::nan("");
  EXPECT_THROW(o.Check(), std::exception);
  o = StageStatsOptions{};
  o.vp_max_turn_deg = 0;
  EXPECT_THROW(o.Check(), std::exception);
}

}  // namespace
}  // namespace jvl::fidelity
