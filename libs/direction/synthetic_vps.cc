#include "direction/synthetic_vps.h"

#include <cmath>
#include <random>

#include "geometry/rigid3.h"

namespace jvl::direction::testing {
namespace {

constexpr double kDeg = M_PI / 180.0;
const Eigen::Vector3d kDown(0, 1, 0);  // KITTI world y points down.

// world_from_cam rotation of a level camera looking along `forward` (horizontal).
Eigen::Matrix3d LevelCamera(const Eigen::Vector3d& forward) {
  Eigen::Matrix3d r;
  r.col(2) = forward.normalized();
  r.col(1) = kDown;
  r.col(0) = kDown.cross(r.col(2));
  return r;
}

Eigen::Vector3d Heading(double h) { return {std::sin(h), 0.0, std::cos(h)}; }

// A unit vector within ~noise of d (isotropic small rotation).
Eigen::Vector3d Perturb(const Eigen::Vector3d& d, double noise_rad, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, noise_rad);
  return (ExpSO3(Eigen::Vector3d(n(rng), n(rng), n(rng))) * d).normalized();
}

void AddVp(int64_t frame, const Eigen::Vector3d& d_cam, const PinholeCamera& camera, double score,
           std::vector<VpObservation>* out, int* index) {
  VpObservation vp;
  vp.frame = frame;
  vp.vp_index = (*index)++;
  vp.direction_cam = d_cam.z() < 0 ? Eigen::Vector3d(-d_cam) : d_cam;  // Sign: z >= 0.
  if (vp.direction_cam.z() > 1e-6) vp.uv = camera.Project(vp.direction_cam);
  vp.score = score;
  out->push_back(vp);
}

std::vector<VpObservation> Simulate(const Trajectory& truth,
                                    const std::vector<Eigen::Vector3d>& road,
                                    const std::vector<bool>& straight, const PinholeCamera& camera,
                                    const SyntheticVpOptions& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<VpObservation> out;
  for (size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Quaterniond cam_from_world = truth.world_from_cam[i].rotation().inverse();
    const Eigen::Vector3d side = kDown.cross(road[i]).normalized();
    int index = 0;
    const double noise = o.noise_deg * kDeg;
    if (u(rng) < (straight[i] ? o.forward_rate : o.curve_forward_rate)) {
      const double extra = straight[i] ? 0.0 : o.curve_noise_deg * kDeg;
      const Eigen::Vector3d d = Perturb(road[i], std::hypot(noise, extra), rng);
      AddVp(truth.frames[i], cam_from_world * d, camera, 1.0, &out, &index);
    }
    if (u(rng) < o.building_rate)
      AddVp(truth.frames[i], cam_from_world * Perturb(side, noise, rng), camera, 0.8, &out, &index);
    if (index < 3 && u(rng) < o.vertical_rate)
      AddVp(truth.frames[i], cam_from_world * Perturb(kDown, noise, rng), camera, 0.6, &out,
            &index);
    if (index < 3 && u(rng) < o.outlier_rate) {
      const Eigen::Vector3d c(n(rng), n(rng), std::abs(n(rng)) + 0.2);
      AddVp(truth.frames[i], c.normalized(), camera, 0.3, &out, &index);
    }
  }
  return out;
}

}  // namespace

SyntheticPath MakePath(const std::vector<PathSegment>& segments, double step_m,
                       double start_heading_deg) {
  SyntheticPath p;
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double heading = start_heading_deg * kDeg;
  int64_t frame = 0;
  for (size_t s = 0; s < segments.size(); ++s) {
    const int steps = std::max(1, int(std::lround(segments[s].length_m / step_m)));
    const double dh = segments[s].turn_deg * kDeg / steps;
    p.segment_road.push_back(dh == 0 ? Heading(heading) : Eigen::Vector3d::Zero());
    for (int k = 0; k < steps; ++k) {
      // Turning left (positive) about world up = -y: heading decreases in the x-z plane.
      p.truth.Append(frame++, Rigid3d(LevelCamera(Heading(heading)), t));
      p.segment.push_back(int(s));
      p.road.push_back(Heading(heading));
      t += step_m * Heading(heading - 0.5 * dh);
      heading -= dh;
    }
  }
  return p;
}

PinholeCamera KittiCamera() {
  PinholeCamera c;
  c.fx = c.fy = 707.0912;
  c.cx = 601.8873;
  c.cy = 183.1104;
  c.width = 1226;
  c.height = 370;
  return c;
}

std::vector<VpObservation> SimulateVps(const SyntheticPath& path, const PinholeCamera& camera,
                                       const SyntheticVpOptions& options) {
  std::vector<bool> straight;
  for (int s : path.segment) straight.push_back(path.segment_road[s].norm() > 0);
  return Simulate(path.truth, path.road, straight, camera, options);
}

std::vector<VpObservation> SimulateVpsFromMotion(const Trajectory& truth,
                                                 const PinholeCamera& camera,
                                                 const SyntheticVpOptions& options) {
  std::vector<Eigen::Vector3d> road(truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    const size_t a = i == 0 ? 0 : i - 1, b = std::min(truth.size() - 1, i + 1);
    Eigen::Vector3d m =
        truth.world_from_cam[b].translation() - truth.world_from_cam[a].translation();
    m.y() = 0;  // Road direction on the ground (x-z).
    road[i] = m.norm() > 1e-9
                  ? m.normalized()
                  : Eigen::Vector3d(truth.world_from_cam[i].rotation() * Eigen::Vector3d::UnitZ());
  }
  return Simulate(truth, road, std::vector<bool>(truth.size(), true), camera, options);
}

Trajectory DriftPrior(const Trajectory& truth, double sigma_deg_per_pose, uint32_t seed,
                      std::vector<double>* yaw) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, sigma_deg_per_pose * kDeg);
  Trajectory prior;
  double psi = 0;
  Eigen::Vector3d t =
      truth.empty() ? Eigen::Vector3d::Zero() : truth.world_from_cam[0].translation();
  yaw->clear();
  for (size_t i = 0; i < truth.size(); ++i) {
    if (i > 0) {
      psi += n(rng);
      const Eigen::Vector3d step =
          truth.world_from_cam[i].translation() - truth.world_from_cam[i - 1].translation();
      t += ExpSO3(-psi * kDown) * step;
    }
    // A rotation by psi about up = -y, applied in the world frame.
    const Eigen::Quaterniond drift = ExpSO3(-psi * kDown);
    prior.Append(truth.frames[i], Rigid3d(drift * truth.world_from_cam[i].rotation(), t));
    yaw->push_back(psi);
  }
  return prior;
}

}  // namespace jvl::direction::testing
