// Synthetic global-optimisation inputs with a yaw-drifting prior (tests and benchmark only).
//
// A straight road along world z (cam0 axes: x right, y down, z forward); keyframe k sits at
// z = step * k, one keyframe every `frames_per_keyframe` frames. The prior accumulates
// `yaw_drift` of yaw per keyframe. Scene in road coordinates (x lateral, y down, s along the
// road): ground y = 1.7, walls x = +-8, poles every 15 m at x = +-6.
//
// As for the optim toy road (docs/optimization.md), the local measurements model a biased
// odometry: the scans and the map points are generated in the world *as the prior sees it*
// (road coordinates placed along the prior path), so visual, saved-L and fresh IMLS residuals
// are all satisfied by the drifted prior and cannot see the drift. The vanishing point of the
// road (d_w = world z) is measured from the true orientation, with 0.5 px noise.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "geometry/camera.h"
#include "geometry/trajectory.h"
#include "mapping/global/global_mapping.h"

namespace jvl::mapping::testing {

struct SyntheticGlobalOptions {
  int keyframes = 40;
  int frames_per_keyframe = 3;
  double step = 2.0;                       // m between keyframes
  double yaw_drift = 0.25 * M_PI / 180.0;  // rad per keyframe
  double scan_range = 25.0;                // m along the road, both sides
  double scan_spacing = 1.0;               // m grid of the sampled surfaces
  int map_points_per_keyframe = 30;
  uint32_t seed = 7;
  // true: the biased-odometry model above (local terms consistent with the prior). false: a
  // physically consistent world: scans and keypoints measured from the true poses in the true
  // (straight) world with `range_noise` / 0.5 px noise; map points start where the prior
  // would triangulate them. The drift is then visible to the local terms too.
  bool biased_local = true;
  double range_noise = 0.01;  // m
};

struct SyntheticGlobal {
  GlobalMapInput input;  // keyframes = the drifted prior at the keyframes
  Trajectory truth;      // full rate
  Trajectory prior;      // full rate
  std::vector<Rigid3d> truth_keyframes;
};

inline PinholeCamera SyntheticCamera() {
  PinholeCamera c;
  c.fx = c.fy = 718.856;
  c.cx = 607.1928;
  c.cy = 185.2157;
  c.width = 1241;
  c.height = 376;
  return c;
}

// Pose of the prior path at road coordinate s (interpolated between keyframes).
inline Rigid3d PriorAt(const std::vector<Rigid3d>& prior_kf, double step, double s) {
  const double f = s / step;
  const int last = static_cast<int>(prior_kf.size()) - 1;
  if (f <= 0)
    return prior_kf[0] * Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, s));
  if (f >= last)
    return prior_kf[last] *
           Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, s - step * last));
  const int k = static_cast<int>(std::floor(f));
  return Interpolate(prior_kf[k], prior_kf[k + 1], f - k);
}

inline Eigen::Vector3d Perceived(const std::vector<Rigid3d>& prior_kf, double step,
                                 const Eigen::Vector3d& road) {
  return PriorAt(prior_kf, step, road.z()) * Eigen::Vector3d(road.x(), road.y(), 0.0);
}

inline void AddScanPoint(const std::vector<Rigid3d>& prior_kf, double step,
                         const Rigid3d& cam_from_world, const Eigen::Vector3d& road,
                         const Eigen::Vector3d& road_normal, double noise, lidar::StoredScan* scan) {
  const Rigid3d frame = PriorAt(prior_kf, step, road.z());
  const Eigen::Vector3d n_w = frame.rotation() * road_normal;
  const Eigen::Vector3d p_w = Perceived(prior_kf, step, road) + noise * n_w;
  scan->points.push_back((cam_from_world * p_w).cast<float>());
  scan->normals.push_back((cam_from_world.rotation() * n_w).cast<float>());
}

inline SyntheticGlobal MakeSyntheticGlobal(const SyntheticGlobalOptions& o) {
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> pixel(0.0, 0.5), range(0.0, o.range_noise);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  SyntheticGlobal out;
  GlobalMapInput& in = out.input;
  in.camera = SyntheticCamera();
  const Rigid3d drift(ExpSO3(Eigen::Vector3d(0, o.yaw_drift, 0)), Eigen::Vector3d::Zero());
  std::vector<Rigid3d> prior_kf;
  for (int k = 0; k < o.keyframes; ++k) {
    out.truth_keyframes.emplace_back(Eigen::Quaterniond::Identity(),
                                     Eigen::Vector3d(0, 0, o.step * k));
    prior_kf.push_back(k == 0 ? out.truth_keyframes[0]
                              : prior_kf[k - 1] * out.truth_keyframes[k - 1].Inverse() *
                                    out.truth_keyframes[k] * drift);
    in.keyframes.Append(int64_t{k} * o.frames_per_keyframe, prior_kf[k]);
  }
  // Full-rate truth and prior (the prior's motion between keyframes is the true motion).
  const int64_t last_frame = int64_t{o.keyframes - 1} * o.frames_per_keyframe;
  for (int64_t f = 0; f <= last_frame; ++f) {
    const int k = static_cast<int>(f / o.frames_per_keyframe);
    const double s = o.step * static_cast<double>(f) / o.frames_per_keyframe;
    const Rigid3d t(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, s));
    out.truth.Append(f, t, 0.1 * static_cast<double>(f));
    out.prior.Append(f, prior_kf[k] * out.truth_keyframes[k].Inverse() * t,
                     0.1 * static_cast<double>(f));
  }
  const double sp = o.scan_spacing;
  // The world the sensors measure, and where the sensors are.
  const std::vector<Rigid3d>& world = o.biased_local ? prior_kf : out.truth_keyframes;
  for (int k = 0; k < o.keyframes; ++k) {
    const Rigid3d cam_from_world = world[k].Inverse();
    const double s0 = o.step * k;
    lidar::StoredScan scan;
    for (double s = s0 - o.scan_range; s <= s0 + o.scan_range; s += sp) {
      for (double x = -7.5; x <= 7.5; x += sp)  // ground
        AddScanPoint(world, o.step, cam_from_world, {x + 0.3 * u(rng), 1.7, s + 0.3 * u(rng)},
                     -Eigen::Vector3d::UnitY(), range(rng), &scan);
      for (double y = -3.0; y <= 1.5; y += sp)  // walls
        for (double side : {-1.0, 1.0})
          AddScanPoint(world, o.step, cam_from_world,
                       {8.0 * side, y + 0.3 * u(rng), s + 0.3 * u(rng)},
                       Eigen::Vector3d(-side, 0, 0), range(rng), &scan);
    }
    for (double s = 15.0 * std::floor((s0 - o.scan_range) / 15.0); s <= s0 + o.scan_range;
         s += 15.0) {  // poles (radius 0.2 m), faces sampled every 45 deg
      for (double side : {-1.0, 1.0})
        for (double y = -2.0; y <= 1.5; y += 0.5)
          for (int a = 0; a < 8; ++a) {
            const Eigen::Vector3d n(std::cos(a * M_PI / 4), 0, std::sin(a * M_PI / 4));
            AddScanPoint(world, o.step, cam_from_world, Eigen::Vector3d(6.0 * side, y, s) + 0.2 * n,
                         n, range(rng), &scan);
          }
    }
    in.scans.push_back(std::move(scan));
    // Map points on the walls created by keyframe k, seen by k..k+2 (as the toy road).
    for (int i = 0; i < o.map_points_per_keyframe; ++i) {
      const double side = i % 2 == 0 ? -1.0 : 1.0;
      const Eigen::Vector3d road(8.0 * side, -3.0 + 4.5 * u(rng), s0 + 8.0 + 20.0 * u(rng));
      const int32_t id = static_cast<int32_t>(in.map_points.size());
      in.map_points.push_back(Perceived(prior_kf, o.step, road));
      const Eigen::Vector3d measured = Perceived(world, o.step, road);
      for (int j = k; j < std::min(k + 3, o.keyframes); ++j) {
        const Eigen::Vector3d p_j = world[j].Inverse() * measured;
        if (p_j.z() < 1.0 || !in.camera.InImage(in.camera.Project(p_j))) continue;
        const int octave = static_cast<int>(u(rng) * 4);
        const Eigen::Vector2d noise(pixel(rng), pixel(rng));
        in.observations.push_back(
            {j, id, in.camera.Project(p_j) + std::pow(1.2, octave) * noise, octave});
      }
    }
    // The road's vanishing point, from the true orientation.
    const Eigen::Vector3d d_w = Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d d_c = out.truth_keyframes[k].rotation().conjugate() * d_w;
    in.directions.push_back({in.keyframes.frames[k],
                             in.camera.Project(d_c) + Eigen::Vector2d(pixel(rng), pixel(rng)), d_w,
                             0});
  }
  return out;
}

// RMSE of the position error and of the rotation angle (deg), no alignment (same gauge).
struct ApeFigures {
  double translation_m = 0, rotation_deg = 0;
};

inline ApeFigures Ape(const Trajectory& truth, const Trajectory& estimate) {
  double st = 0, sr = 0;
  int n = 0;
  for (size_t i = 0; i < estimate.size(); ++i) {
    const auto j = truth.IndexOf(estimate.frames[i]);
    if (!j) continue;
    const Rigid3d& a = truth.world_from_cam[*j];
    const Rigid3d& b = estimate.world_from_cam[i];
    st += (a.translation() - b.translation()).squaredNorm();
    const double ang = RotationAngle(a.rotation().conjugate() * b.rotation()) * 180.0 / M_PI;
    sr += ang * ang;
    ++n;
  }
  if (n == 0) return {};
  return {std::sqrt(st / n), std::sqrt(sr / n)};
}

}  // namespace jvl::mapping::testing
