#include "sim/prior.h"

#include <cmath>

#include "core/check.h"
#include "sim/random.h"

namespace jvl::sim {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

}  // namespace

void PriorOptions::Check() const {
  for (double v : {yaw_bias_walk, yaw_noise_deg, pitch_roll_walk, pitch_roll_noise_deg, scale_walk,
                   jitter_translation_m, jitter_rotation_deg}) {
    JVL_CHECK(v >= 0 && std::isfinite(v), "the noise levels (yaw_bias_walk, yaw_noise_deg, pitch_roll_walk, pitch_roll_noise_deg, scale_walk, jitter_translation_m, jitter_rotation_deg) must be finite and >= 0");
  }
  JVL_CHECK(std::abs(scale_bias) < 0.5,
            "scale bias (--scale-bias) must be in (-0.5, 0.5), got " << scale_bias);
  JVL_CHECK(
      std::abs(yaw_bias_deg_per_100m) <= 180,
      "yaw drift (--yaw-drift) must be within +-180 deg/100 m, got " << yaw_bias_deg_per_100m);
}

std::vector<std::string> PriorPresetNames() { return {"lidar-n1", "orbslam2", "good", "none"}; }

PriorOptions PriorPreset(const std::string& name, uint64_t seed) {
  PriorOptions o;
  o.seed = seed;
  if (name == "lidar-n1") {
    // Scan-to-scan LiDAR odometry (local map of one scan): heading drift of a few tenths of a
    // degree per 100 m, pitch drift, ~1 % scale error; APE of several metres per km.
    o.yaw_bias_deg_per_100m = 0.25;
    o.yaw_bias_walk = 0.15;
    o.yaw_noise_deg = 0.08;
    o.pitch_roll_walk = 0.08;
    o.pitch_roll_noise_deg = 0.03;
    o.scale_bias = 0.008;
    o.scale_walk = 0.004;
    o.jitter_translation_m = 0.03;
    o.jitter_rotation_deg = 0.05;
  } else if (name == "orbslam2") {
    // Stereo visual odometry (ORB-SLAM2 without loop closure): small rotation drift, ~0.1 %
    // scale error, more per-frame jitter than the LiDAR.
    o.yaw_bias_deg_per_100m = 0.03;
    o.yaw_bias_walk = 0.02;
    o.yaw_noise_deg = 0.02;
    o.pitch_roll_walk = 0.02;
    o.pitch_roll_noise_deg = 0.01;
    o.scale_bias = 0.001;
    o.scale_walk = 0.001;
    o.jitter_translation_m = 0.03;
    o.jitter_rotation_deg = 0.05;
  } else if (name == "good") {
    o.yaw_bias_deg_per_100m = 0.02;
    o.yaw_noise_deg = 0.01;
    o.scale_walk = 0.001;
    o.jitter_translation_m = 0.01;
    o.jitter_rotation_deg = 0.01;
  } else if (name != "none") {
    JVL_THROW("unknown prior preset '" << name << "' (expected lidar-n1, orbslam2, good or none)");
  }
  return o;
}

Trajectory MakePrior(const Trajectory& gt, const PriorOptions& options) {
  options.Check();
  gt.Check("ground truth");
  Trajectory out;
  if (gt.empty()) return out;
  Rng rng(HashCombine(options.seed, 0x9a10a));
  // Drift state: yaw/pitch/roll rate biases (rad per m) and scale offset.
  double yaw_rate = options.yaw_bias_deg_per_100m * kDeg / 100.0;
  double pitch_rate = 0, roll_rate = 0, scale = options.scale_bias;
  Rigid3d pose = gt.world_from_cam[0];
  for (size_t k = 0; k < gt.size(); ++k) {
    if (k > 0) {
      const Rigid3d delta = gt.world_from_cam[k - 1].Inverse() * gt.world_from_cam[k];
      const double ds = delta.translation().norm();
      const double walk = std::sqrt(ds / 100.0);  // Random-walk step for ds metres.
      yaw_rate += options.yaw_bias_walk * kDeg / 100.0 * walk * rng.Normal();
      pitch_rate += options.pitch_roll_walk * kDeg / 100.0 * walk * rng.Normal();
      roll_rate += options.pitch_roll_walk * kDeg / 100.0 * walk * rng.Normal();
      scale += options.scale_walk * walk * rng.Normal();
      // Camera frame: yaw about -y (y points down), pitch about x, roll about z.
      const Eigen::Vector3d omega(
          pitch_rate * ds + options.pitch_roll_noise_deg * kDeg * walk * rng.Normal(),
          -(yaw_rate * ds + options.yaw_noise_deg * kDeg * walk * rng.Normal()),
          roll_rate * ds + options.pitch_roll_noise_deg * kDeg * walk * rng.Normal());
      const Rigid3d noisy(delta.rotation() * ExpSO3(omega), (1.0 + scale) * delta.translation());
      pose = pose * noisy;
    }
    Rigid3d jittered = pose;
    if (k > 0) {
      const Eigen::Vector3d dr(rng.Normal(), rng.Normal(), rng.Normal());
      const Eigen::Vector3d dt(rng.Normal(), rng.Normal(), rng.Normal());
      jittered = pose * Rigid3d(ExpSO3(options.jitter_rotation_deg * kDeg * dr),
                                options.jitter_translation_m * dt);
    }
    out.Append(gt.frames[k], jittered,
               gt.has_timestamps() ? std::optional<double>(gt.timestamps[k]) : std::nullopt);
  }
  return out;
}

PriorStats ComparePrior(const Trajectory& gt, const Trajectory& prior) {
  JVL_CHECK(gt.size() == prior.size(),
            "prior has " << prior.size() << " poses, ground truth " << gt.size());
  PriorStats st;
  double sum2 = 0;
  for (size_t k = 0; k < gt.size(); ++k) {
    const double e =
        (gt.world_from_cam[k].translation() - prior.world_from_cam[k].translation()).norm();
    sum2 += e * e;
    st.ape_max_m = std::max(st.ape_max_m, e);
    if (k > 0) {
      st.length_m +=
          (gt.world_from_cam[k].translation() - gt.world_from_cam[k - 1].translation()).norm();
    }
  }
  if (!gt.empty()) {
    st.ape_rmse_m = std::sqrt(sum2 / static_cast<double>(gt.size()));
    const Rigid3d err = gt.world_from_cam.back().Inverse() * prior.world_from_cam.back();
    st.final_rotation_error_deg = RotationAngle(err.rotation()) / kDeg;
    // Heading error: rotation about the camera's vertical (y) axis.
    const Eigen::Vector3d z = err.rotation() * Eigen::Vector3d::UnitZ();
    st.final_yaw_error_deg = std::atan2(z.x(), z.z()) / kDeg;
  }
  return st;
}

}  // namespace jvl::sim
