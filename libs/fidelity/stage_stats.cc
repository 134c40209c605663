#include "fidelity/stage_stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/check.h"
#include "core/statistics.h"
#include "fidelity/sensor_stats.h"
#include "geometry/rigid3.h"

namespace jvl::fidelity {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kRadToDeg = 180.0 / M_PI;

// Translation error of the estimate's motion from frame row a to row b against the truth's.
double MotionError(const Trajectory& g, size_t a, size_t b, const Rigid3d& ea, const Rigid3d& eb) {
  const Rigid3d truth = g.world_from_cam[a].Inverse() * g.world_from_cam[b];
  const Rigid3d estimate = ea.Inverse() * eb;
  return (truth.Inverse() * estimate).translation().norm();
}

}  // namespace

void StageStatsOptions::Check() const {
  JVL_CHECK(std::isfinite(drift_length_m) && drift_length_m > 0,
            "stage stats: drift_length_m must be > 0, got " << drift_length_m);
  JVL_CHECK(std::isfinite(min_step_m) && min_step_m >= 0,
            "stage stats: min_step_m must be >= 0, got " << min_step_m);
  JVL_CHECK(std::isfinite(vp_lookahead_m) && vp_lookahead_m > 0,
            "stage stats: vp_lookahead_m must be > 0, got " << vp_lookahead_m);
  JVL_CHECK(std::isfinite(vp_max_turn_deg) && vp_max_turn_deg > 0,
            "stage stats: vp_max_turn_deg must be > 0, got " << vp_max_turn_deg);
}

StageSeries MakeStageSeries(const Trajectory& ground_truth) {
  StageSeries s;
  s.frames = ground_truth.frames;
  const size_t n = ground_truth.size();
  for (auto* v :
       {&s.odom_rpe_m, &s.odom_rpe_percent, &s.odom_drift_percent, &s.odom_direction_yaw_deg,
        &s.odom_direction_pitch_deg, &s.vp_forward_found, &s.vp_forward_error_deg, &s.visual_points,
        &s.visual_tracked_fraction, &s.visual_reprojection_px})
    v->assign(n, kNan);
  return s;
}

void AddOdometryStats(const Trajectory& g, const Trajectory& estimate,
                      const StageStatsOptions& options, StageSeries* series) {
  options.Check();
  JVL_CHECK(series->frames == g.frames, "stage stats: the series is not of this ground truth");
  const std::vector<double> path = PathLengths(g);
  // The estimate's pose of each ground-truth row (nullopt where it has none).
  std::vector<std::optional<size_t>> row(g.size());
  size_t found = 0;
  for (size_t k = 0; k < g.size(); ++k) {
    row[k] = estimate.IndexOf(g.frames[k]);
    found += row[k] ? 1 : 0;
  }
  JVL_CHECK(found >= 2,
            "stage stats: the odometry shares " << found << " frames with the ground truth");
  auto error = [&](size_t a, size_t b) {
    if (!row[a] || !row[b]) return kNan;
    return MotionError(g, a, b, estimate.world_from_cam[*row[a]], estimate.world_from_cam[*row[b]]);
  };
  for (size_t k = 0; k + 1 < g.size(); ++k) {
    const double e = error(k, k + 1);
    const double step = path[k + 1] - path[k];
    series->odom_rpe_m[k + 1] = e;
    series->odom_rpe_percent[k + 1] = step >= options.min_step_m ? 100.0 * e / step : kNan;
    if (step < options.min_step_m || !row[k] || !row[k + 1]) continue;
    const Eigen::Vector3d t =
        (g.world_from_cam[k].Inverse() * g.world_from_cam[k + 1]).translation();
    const Eigen::Vector3d m =
        (estimate.world_from_cam[*row[k]].Inverse() * estimate.world_from_cam[*row[k + 1]])
            .translation();
    auto yaw = [](const Eigen::Vector3d& v) { return std::atan2(v.x(), v.z()); };
    auto pitch = [](const Eigen::Vector3d& v) {
      return std::atan2(v.y(), std::hypot(v.x(), v.z()));
    };
    series->odom_direction_yaw_deg[k + 1] = (yaw(m) - yaw(t)) * kRadToDeg;
    series->odom_direction_pitch_deg[k + 1] = (pitch(m) - pitch(t)) * kRadToDeg;
  }
  size_t j = 0;
  for (size_t k = 0; k < g.size(); ++k) {
    j = std::max(j, k);
    while (j < g.size() && path[j] - path[k] < options.drift_length_m) ++j;
    if (j == g.size()) break;
    series->odom_drift_percent[k] = 100.0 * error(k, j) / (path[j] - path[k]);
  }
}

void AddVpStats(const Trajectory& g, const io::VpsData& vps, const StageStatsOptions& options,
                StageSeries* series) {
  options.Check();
  JVL_CHECK(series->frames == g.frames, "stage stats: the series is not of this ground truth");
  const std::vector<double> path = PathLengths(g);
  std::vector<std::optional<Eigen::Vector3d>> forward(g.size());
  std::vector<char> processed(g.size(), 0);
  for (const int64_t f : vps.frames)
    if (const auto k = g.IndexOf(f)) processed[*k] = 1;
  for (const io::VpRecord& vp : vps.vps)
    if (vp.is_forward)
      if (const auto k = g.IndexOf(vp.frame)) forward[*k] = vp.direction.normalized();
  size_t j = 0;
  for (size_t k = 0; k < g.size(); ++k) {
    if (!processed[k]) continue;
    series->vp_forward_found[k] = forward[k] ? 1.0 : 0.0;
    j = std::max(j, k);
    while (j < g.size() && path[j] - path[k] < options.vp_lookahead_m) ++j;
    if (!forward[k] || j == g.size()) continue;
    const Eigen::Quaterniond turn =
        g.world_from_cam[k].rotation().inverse() * g.world_from_cam[j].rotation();
    if (Eigen::AngleAxisd(turn).angle() * kRadToDeg > options.vp_max_turn_deg) continue;
    // Rectified cameras share camera 0's rotation: the direction holds for any camera choice.
    const Eigen::Vector3d travel =
        (g.world_from_cam[k].Inverse() * g.world_from_cam[j].translation()).normalized();
    const double c = std::clamp(std::abs(travel.dot(*forward[k])), 0.0, 1.0);
    series->vp_forward_error_deg[k] = std::acos(c) * kRadToDeg;
  }
}

void AddVisualStats(const io::VisualMapData& d, StageSeries* series) {
  d.Check("visual map");
  const size_t n = d.keyframes.size();
  std::vector<double> keypoints(n, 0.0);
  for (const int32_t k : d.keypoint_keyframe) keypoints[static_cast<size_t>(k)] += 1;
  std::vector<std::vector<double>> errors(n);
  std::vector<Rigid3d> cam_from_world;
  for (const Rigid3d& t : d.keyframes.world_from_cam) cam_from_world.push_back(t.Inverse());
  for (size_t o = 0; o < d.num_observations(); ++o) {
    const auto k = static_cast<size_t>(d.observation_keyframe[o]);
    const auto kp = static_cast<size_t>(d.observation_keypoint[o]);
    const auto m = static_cast<size_t>(d.observation_mappoint[o]);
    const Eigen::Vector3d x(d.mappoint_position[3 * m], d.mappoint_position[3 * m + 1],
                            d.mappoint_position[3 * m + 2]);
    const Eigen::Vector3d pc = cam_from_world[k] * x + d.camera_choice.offset;
    const Eigen::Vector2d uv(d.keypoint_uv[2 * kp], d.keypoint_uv[2 * kp + 1]);
    errors[k].push_back(pc.z() > 0 ? (d.camera.Project(pc) - uv).norm()
                                   : std::numeric_limits<double>::infinity());
  }
  for (size_t k = 0; k < n; ++k) {
    const auto i =
        std::lower_bound(series->frames.begin(), series->frames.end(), d.keyframes.frames[k]);
    if (i == series->frames.end() || *i != d.keyframes.frames[k]) continue;
    const auto r = static_cast<size_t>(i - series->frames.begin());
    const double seen = static_cast<double>(errors[k].size());
    series->visual_points[r] = seen;
    series->visual_tracked_fraction[r] = keypoints[k] > 0 ? seen / keypoints[k] : kNan;
    series->visual_reprojection_px[r] = errors[k].empty() ? kNan : Median(errors[k]);
  }
}

nlohmann::json SummariseStages(const StageSeries& s, bool odometry, bool vps, bool visual) {
  nlohmann::json out = nlohmann::json::object();
  const std::vector<std::pair<const char*, const std::vector<double>*>> parts[3] = {
      {{"odom_rpe_m", &s.odom_rpe_m},
       {"odom_rpe_percent", &s.odom_rpe_percent},
       {"odom_drift_percent", &s.odom_drift_percent},
       {"odom_direction_yaw_deg", &s.odom_direction_yaw_deg},
       {"odom_direction_pitch_deg", &s.odom_direction_pitch_deg}},
      {{"vp_forward_found", &s.vp_forward_found},
       {"vp_forward_error_deg", &s.vp_forward_error_deg}},
      {{"visual_points", &s.visual_points},
       {"visual_tracked_fraction", &s.visual_tracked_fraction},
       {"visual_reprojection_px", &s.visual_reprojection_px}}};
  const bool given[3] = {odometry, vps, visual};
  for (int p = 0; p < 3; ++p)
    if (given[p])
      for (const auto& [name, values] : parts[p])
        out[name] = SummariseValues(*values, /*with_mean=*/true);
  return out;
}

}  // namespace jvl::fidelity
