// Synthetic straight road with a yaw-drifting prior, shared by the optim tests and benchmark.
#pragma once

#include <cmath>
#include <map>
#include <random>

#include "optim/joint_problem.h"
#include "optim/test_util.h"

namespace jvl::optim::testing {

// Toy road (see docs/optimization.md): keyframes every 2 m along the world z axis, facing along
// the road. The prior accumulates a yaw bias of kYawDriftPerStep per keyframe, and the local
// measurements (map points + keypoints, IMLS correspondences between neighbours) are generated
// from that drifted prior, as from a biased odometry: they are all satisfied by the drifted
// trajectory, so they cannot see the drift. The vanishing point of the road, detected in every
// image from the true orientation, can.
constexpr int kToyKeyframes = 30;
constexpr double kStep = 2.0;
constexpr double kYawDriftPerStep = 0.3 * M_PI / 180.0;

struct ToyRoad {
  std::map<int64_t, Rigid3d> truth;
  JointProblemInput input;
};

inline ToyRoad MakeToyRoad(bool with_directions, int num_keyframes = kToyKeyframes,
                           double yaw_drift_per_step = kYawDriftPerStep) {
  std::mt19937 rng(42);
  std::normal_distribution<double> pixel_noise(0.0, 0.5);
  std::normal_distribution<double> range_noise(0.0, 0.01);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ToyRoad toy;
  JointProblemInput& in = toy.input;
  in.camera = KittiLikeCamera();
  const Rigid3d drift(ExpSO3(Eigen::Vector3d(0, yaw_drift_per_step, 0)), Eigen::Vector3d::Zero());
  for (int k = 0; k < num_keyframes; ++k) {
    toy.truth[k] = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, kStep * k));
    in.poses[k] =
        k == 0 ? toy.truth[0] : in.poses[k - 1] * toy.truth[k - 1].Inverse() * toy.truth[k] * drift;
  }
  in.fixed = {0};
  for (int k = 0; k < num_keyframes; ++k) {
    const Rigid3d& world_from_k = in.poses[k];
    for (int i = 0; i < 40; ++i) {  // map points created by keyframe k, seen by k..k+2
      const double side = i % 2 == 0 ? -1.0 : 1.0;
      const Eigen::Vector3d p_k(side * (3.0 + 9.0 * u(rng)), -3.0 + 4.5 * u(rng),
                                6.0 + 24.0 * u(rng));
      const Eigen::Vector3d p_w = world_from_k * p_k;
      const int32_t id = static_cast<int32_t>(in.map_points.size());
      in.map_points.push_back(p_w);
      for (int j = k; j < std::min(k + 3, num_keyframes); ++j) {
        const Eigen::Vector3d p_j = in.poses[j].Inverse() * p_w;
        if (p_j.z() < 1.0 || !in.camera.InImage(in.camera.Project(p_j))) continue;
        const int octave = static_cast<int>(u(rng) * 4);
        const double sigma = std::pow(1.2, octave);
        const Eigen::Vector2d noise(pixel_noise(rng), pixel_noise(rng));
        in.observations.push_back({j, id, in.camera.Project(p_j) + sigma * noise, octave});
      }
    }
    if (k == 0) continue;
    for (int i = 0; i < 30; ++i) {  // IMLS correspondences of keyframe n = k against c = k - 1
      ImlsCorrespondence l;
      l.n = k;
      l.c = k - 1;
      const double z = 3.0 + 20.0 * u(rng);
      if (i % 4 == 0) {  // ground 1.7 m below the camera (y points down)
        l.c_p_y = Eigen::Vector3d(-6.0 + 12.0 * u(rng), 1.7, z);
        l.c_normal = -Eigen::Vector3d::UnitY();
      } else if (i % 4 ==
                 3) {  // obstacles facing the car (poles, vehicles): fix the forward motion
        l.c_p_y = Eigen::Vector3d(-6.0 + 12.0 * u(rng), -1.0 + 2.0 * u(rng), z);
        l.c_normal = Eigen::Vector3d(0.3 * (u(rng) - 0.5), 0, -1).normalized();
      } else {  // walls 8 m left and right
        const double side = i % 4 == 1 ? -1.0 : 1.0;
        l.c_p_y = Eigen::Vector3d(side * 8.0, -2.0 + 3.5 * u(rng), z);
        l.c_normal = Eigen::Vector3d(-side, 0, 0);
      }
      const Eigen::Vector3d sampled = l.c_p_y + range_noise(rng) * l.c_normal;
      l.p_x = in.poses[k].Inverse() * (in.poses[k - 1] * sampled);
      in.imls.push_back(l);
    }
    if (with_directions) {
      const Eigen::Vector3d d_w = Eigen::Vector3d::UnitZ();  // the road's direction prior
      const Eigen::Vector3d d_cam = toy.truth[k].rotation().conjugate() * d_w;
      const Eigen::Vector2d noise(pixel_noise(rng), pixel_noise(rng));
      in.directions.push_back({k, in.camera.Project(d_cam) + noise, d_w});
    }
  }
  return toy;
}

}  // namespace jvl::optim::testing
