// make_prior: turns a ground-truth trajectory into a drifting prior (a poor LiDAR odometry or an
// ORB-SLAM2-like visual odometry) for experiments on synthetic or KITTI sequences.
#include <spdlog/spdlog.h>

#include "app/tool.h"
#include "io/trajectory_io.h"
#include "sim/prior.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("make_prior", "Make a drifting prior trajectory from ground truth.");
  std::string gt_path, output, preset = "lidar-n1";
  uint64_t seed = 1;
  double yaw_drift = 0, scale_bias = 0;
  auto& cli = tool.cli();
  tool.InputFile(
      cli.add_option("--ground-truth,-g", gt_path, "Ground truth (KITTI/TUM text or .h5)")
          ->required());
  tool.OutputFile(
      cli.add_option("--output,-o", output, "Prior: .h5 trajectory artifact or .txt (KITTI)")
          ->required());
  cli.add_option("--preset", preset, "lidar-n1, orbslam2, good or none")->capture_default_str();
  cli.add_option("--seed", seed, "Random seed")->capture_default_str();
  const CLI::Option* yaw_option =
      cli.add_option("--yaw-drift", yaw_drift, "Override: constant yaw drift (deg/100 m)");
  const CLI::Option* scale_option =
      cli.add_option("--scale-bias", scale_bias, "Override: relative scale error (0.01 = 1 %)");
  return tool.Run(argc, argv, [&] {
    jvl::sim::PriorOptions options = jvl::sim::PriorPreset(preset, seed);
    if (yaw_option->count() > 0) options.yaw_bias_deg_per_100m = yaw_drift;
    if (scale_option->count() > 0) options.scale_bias = scale_bias;
    options.Check();
    tool.AddInput(gt_path);
    const jvl::Trajectory gt = jvl::io::ReadTrajectory(gt_path);
    const jvl::Trajectory prior = jvl::sim::MakePrior(gt, options);
    if (output.size() > 3 && output.substr(output.size() - 3) == ".h5") {
      jvl::io::WriteTrajectoryArtifact(output, prior, tool.MakeProvenance());
    } else {
      jvl::io::WriteTrajectoryKitti(output, prior);
    }
    const auto st = jvl::sim::ComparePrior(gt, prior);
    spdlog::info(
        "prior '{}' over {:.0f} m: APE rmse {:.2f} m, max {:.2f} m, final yaw error "
        "{:.2f} deg, rotation error {:.2f} deg",
        preset, st.length_m, st.ape_rmse_m, st.ape_max_m, st.final_yaw_error_deg,
        st.final_rotation_error_deg);
  });
}
