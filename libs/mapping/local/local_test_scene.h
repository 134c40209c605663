// Test-only synthetic world for local mapping: planar patches (a street with facades, recesses
// and cross walls; planes at least 1 m apart so that the IMLS surface of every patch is exact),
// keyframe scans sampled from them, and a visual map of points seen by the keyframes.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <vector>

#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "mapping/local/local_mapping.h"

namespace jvl::mapping::testing {

struct Patch {
  Eigen::Vector3d origin, u, v;  // Rectangle origin + [0,1] u + [0,1] v.
  Eigen::Vector3d normal() const { return u.cross(v).normalized(); }
};

// A street along +z in the cam0 convention (y down, ground at y = +1.7).
inline std::vector<Patch> StreetPatches() {
  std::vector<Patch> p;
  p.push_back({{-7, 1.7, -20}, {14, 0, 0}, {0, 0, 150}});  // Ground.
  for (int b = 0; b < 10; ++b) {
    const double z = -20 + 15.0 * b;
    const double xl = -8.0 - (b % 3), xr = 8.0 + ((b + 1) % 2) * 1.5;
    p.push_back({{xl, -6, z}, {0, 0, 11}, {0, 6.7, 0}});            // Left facade block.
    p.push_back({{xr, -6, z + 2}, {0, 0, 10}, {0, 6.7, 0}});        // Right facade block.
    p.push_back({{xl - 5, -6, z + 12.5}, {4, 0, 0}, {0, 6.7, 0}});  // Cross walls (normal z).
    p.push_back({{xr + 1, -6, z + 13.5}, {4, 0, 0}, {0, 6.7, 0}});
  }
  p.push_back({{2, -1.3, 30}, {2, 0, 0}, {0, 2.5, 0}});   // A box face in the street.
  p.push_back({{-3, -1.3, 70}, {0, 0, 3}, {0, 2.5, 0}});  // A wall segment along the road.
  return p;
}

// Points of every patch within `range` of the sensor on a grid of `step` shifted by a random
// offset (different per scan), in the keyframe's cam0 frame, with normals facing the sensor.
inline void SampleScan(const std::vector<Patch>& patches, const Rigid3d& world_from_cam,
                       double step, double range, uint32_t seed,
                       std::vector<Eigen::Vector3d>* points,
                       std::vector<Eigen::Vector3d>* normals) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(0.0, 1.0);
  const Rigid3d cam_from_world = world_from_cam.Inverse();
  const Eigen::Vector3d centre = world_from_cam.translation();
  for (const Patch& patch : patches) {
    const int nu = static_cast<int>(patch.u.norm() / step);
    const int nv = static_cast<int>(patch.v.norm() / step);
    const double ou = offset(rng), ov = offset(rng);
    Eigen::Vector3d n = patch.normal();
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const Eigen::Vector3d x =
            patch.origin + patch.u * ((i + ou) / nu) + patch.v * ((j + ov) / nv);
        if ((x - centre).norm() > range) continue;
        const Eigen::Vector3d nw = n.dot(centre - x) >= 0 ? n : Eigen::Vector3d(-n);
        points->push_back(cam_from_world * x);
        normals->push_back(cam_from_world.rotation() * nw);
      }
    }
  }
}

// Keyframes every `spacing` m along a gently curving road (yaw_rate rad per keyframe).
inline std::vector<Rigid3d> RoadPoses(int count, double spacing, double yaw_rate) {
  std::vector<Rigid3d> poses;
  Rigid3d pose;
  for (int k = 0; k < count; ++k) {
    poses.push_back(pose);
    // cam0: y down, so a yaw is a rotation about y.
    const Rigid3d step(Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rate, Eigen::Vector3d::UnitY())),
                       Eigen::Vector3d(0, 0, spacing));
    pose = pose * step;
  }
  return poses;
}

// A drifting odometry: every relative motion of `truth` gets extra yaw and a scale error.
inline std::vector<Rigid3d> DriftingPrior(const std::vector<Rigid3d>& truth, double yaw_per_step,
                                          double scale) {
  std::vector<Rigid3d> prior{truth.front()};
  for (size_t k = 1; k < truth.size(); ++k) {
    const Rigid3d rel = truth[k - 1].Inverse() * truth[k];
    const Rigid3d drift(
        Eigen::Quaterniond(Eigen::AngleAxisd(yaw_per_step, Eigen::Vector3d::UnitY())) *
            rel.rotation(),
        scale * rel.translation());
    prior.push_back(prior.back() * drift);
  }
  return prior;
}

// Visual map: points on the facades seen (in front, inside the image, within 40 m) by the true
// keyframes with `noise_px` pixel noise; kept if seen at least twice; positions carried by the
// prior like a triangulation from prior poses (relative to the first observer). Covisibility
// edges for pairs sharing >= 15 points.
inline LocalMappingInput MakeVisualInput(const PinholeCamera& camera,
                                         const std::vector<Rigid3d>& truth,
                                         const std::vector<Rigid3d>& prior,
                                         const std::vector<int64_t>& frames, int num_points,
                                         double noise_px, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uz(-15, 130), uy(-5.5, 0.5), side(0, 1);
  std::normal_distribution<double> noise(0, noise_px);
  LocalMappingInput in;
  in.camera = camera;
  in.frames = frames;
  in.map_poses = prior;
  in.prior = prior;
  const size_t k_count = truth.size();
  std::vector<std::vector<int>> seen_by(k_count);
  for (int m = 0; m < num_points; ++m) {
    const Eigen::Vector3d x(side(rng) < 0.5 ? -8.5 : 9.0, uy(rng), uz(rng));
    std::vector<optim::VisualObservation> obs;
    for (size_t k = 0; k < k_count; ++k) {
      const Eigen::Vector3d xc = truth[k].Inverse() * x;
      if (xc.z() < 1.0 || xc.norm() > 40) continue;
      const Eigen::Vector2d uv = camera.Project(xc);
      if (uv.x() < 0 || uv.y() < 0 || uv.x() >= camera.width || uv.y() >= camera.height) continue;
      optim::VisualObservation o;
      o.keyframe = static_cast<int64_t>(k);
      o.map_point = static_cast<int32_t>(in.map_points.size());
      o.uv = uv + Eigen::Vector2d(noise(rng), noise(rng));
      obs.push_back(o);
    }
    if (obs.size() < 2) continue;
    const size_t first = static_cast<size_t>(obs.front().keyframe);
    in.map_points.push_back(prior[first] * (truth[first].Inverse() * x));
    for (const auto& o : obs) {
      seen_by[static_cast<size_t>(o.keyframe)].push_back(o.map_point);
      in.observations.push_back(o);
    }
  }
  for (size_t a = 0; a < k_count; ++a) {
    for (size_t b = a + 1; b < k_count; ++b) {
      std::vector<int> shared;
      std::set_intersection(seen_by[a].begin(), seen_by[a].end(), seen_by[b].begin(),
                            seen_by[b].end(), std::back_inserter(shared));
      if (shared.size() >= 15)
        in.covisibility.push_back({static_cast<int>(a), static_cast<int>(b)});
    }
  }
  return in;
}

}  // namespace jvl::mapping::testing
