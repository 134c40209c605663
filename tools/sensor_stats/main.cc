// sensor_stats: statistics of a sequence's raw LiDAR scans and camera images (points per ring,
// ranges, ground and shape classes; brightness, contrast, gradients, corners), computed the same
// way on real and simulated data -> one JSON artifact. scripts/sensor_fidelity.py puts several
// side by side (the simulator's fidelity table, docs/sim.md).
#include <spdlog/spdlog.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "app/option_group.h"
#include "app/tool.h"
#include "core/check.h"
#include "core/progress.h"
#include "core/statistics.h"
#include "core/strings.h"
#include "core/threads.h"
#include "fidelity/sensor_stats.h"
#include "fidelity/stage_stats.h"
#include "io/artifact.h"
#include "io/dataset.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "io/vps_io.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("sensor_stats",
                      "Statistics of the raw LiDAR scans and camera images of a sequence (real or "
                      "simulated), for the simulator's fidelity table: median, 10 % and 90 % "
                      "quantile over the frames of every statistic, and the per-frame values.");
  std::string dataset_dir, frames = ":", output, gt_path, odometry_path, vps_path, visual_path;
  jvl::io::DatasetOptions dataset_options;
  int every = 1, camera = 0;
  bool no_scans = false, no_images = false;
  jvl::fidelity::ScanStatsOptions scan_options;
  jvl::fidelity::ImageStatsOptions image_options;
  jvl::fidelity::StageStatsOptions stage_options;
  CLI::App& cli = tool.cli();
  cli.add_option("--dataset,-d", dataset_dir, "Sequence folder (KITTI odometry/raw, synthetic)")
      ->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--frames", frames, "Frame range A:B (B exclusive)")->capture_default_str();
  cli.add_option("--camera", camera, jvl::io::kCameraHelp)->capture_default_str();
  cli.add_option("--every", every, "Use every K-th frame of the range")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  tool.OutputFile(
      cli.add_option("-o,--output", output, "Output JSON (sensor_stats artifact)")->required());
  cli.add_flag("--no-scans", no_scans, "Skip the LiDAR statistics");
  cli.add_flag("--no-images", no_images, "Skip the image statistics");
  jvl::app::OptionGroup stages(tool, "What the stages see (against the ground truth)");
  stages.Add("--odometry", odometry_path,
             "A trajectory of the sequence (lidar_odom's odom.h5, KITTI or TUM text): its frame-to-"
             "frame error and drift");
  stages.Add("--vps", vps_path,
             "vp_detect's vps artifact: forward VP found, its angle to the "
             "direction of travel");
  stages.Add("--visual", visual_path,
             "visual_assoc's visual artifact: map points, tracked share of the keypoints and "
             "reprojection error per keyframe");
  stages.Add("--gt", gt_path,
             "Ground-truth poses for --odometry and --vps (default: the dataset's own)");
  stages.Add("--drift-length", stage_options.drift_length_m,
             "Path length of the odometry's drift windows (m)");
  stages.Add("--vp-lookahead", stage_options.vp_lookahead_m,
             "The direction of travel points at the position this far ahead (m)");
  stages.Add("--vp-max-turn", stage_options.vp_max_turn_deg,
             "The forward VP's error only where the path turns by at most this over the lookahead "
             "(deg)");
  tool.FieldFlag("drift_length_m", "--drift-length");
  tool.FieldFlag("vp_lookahead_m", "--vp-lookahead");
  tool.FieldFlag("vp_max_turn_deg", "--vp-max-turn");
  jvl::app::OptionGroup stats(tool, "Statistics");
  stats.Add("--sensor-height", scan_options.sensor_height,
            "Nominal height of the LiDAR above the road (m)");
  stats.Add("--shape-radius", scan_options.radius, "Neighbourhood radius of the shape classes (m)");
  stats.Add("--shape-max-range", scan_options.shape_max_range,
            "Shape classes of points up to this range (m)");
  stats.Add(
      "--far-range", scan_options.far_range,
      "Non-ground returns beyond this horizontal distance (m), ahead and behind, are far_ahead "
      "and far_behind");
  stats.Add("--fast-threshold", image_options.fast_threshold, "FAST threshold of the corner count");

  return tool.Run(argc, argv, [&] {
    scan_options.Check();
    image_options.Check();
    const bool any_stage = !odometry_path.empty() || !vps_path.empty() || !visual_path.empty();
    JVL_CHECK(!(no_scans && no_images && !any_stage),
              "sensor_stats: --no-scans and --no-images leave nothing (without a stage artifact)");
    cv::setNumThreads(1);  // Parallelism is over frames.
    const auto dataset =
        jvl::io::OpenDataset(dataset_dir, dataset_options, jvl::ParseFrameRange(frames));
    tool.AddDataset(*dataset, dataset_dir);
    // Stage artifacts of another sequence are refused (their provenance names it).
    for (const std::string* path : {&odometry_path, &vps_path, &visual_path})
      if (!path->empty()) tool.AddInput(*path);
    if (!gt_path.empty()) tool.AddInput(gt_path, /*same_dataset=*/false);
    if (!no_images) dataset->CheckCamera(camera);
    std::vector<int64_t> used;
    for (size_t i = 0; i < dataset->frames().size(); i += static_cast<size_t>(every))
      used.push_back(dataset->frames()[i]);
    std::vector<jvl::fidelity::ScanStats> scans(no_scans ? 0 : used.size());
    std::vector<jvl::fidelity::ImageStats> images(no_images ? 0 : used.size());
    const int64_t sensor_frames = no_scans && no_images ? 0 : static_cast<int64_t>(used.size());
    jvl::Progress progress("frames", sensor_frames, !tool.quiet() && sensor_frames > 0);
    jvl::ParallelFor(sensor_frames, tool.threads(), [&](int64_t i) {
      if (!no_scans)
        scans[i] = jvl::fidelity::ComputeScanStats(dataset->LoadScan(used[i]), scan_options);
      if (!no_images)
        images[i] =
            jvl::fidelity::ComputeImageStats(dataset->LoadImage(used[i], camera), image_options);
      progress.Tick();
    });
    nlohmann::json body;
    body["frames"] = used;
    body["scan"] = no_scans ? nlohmann::json() : jvl::fidelity::SummariseScans(scans);
    body["image"] = no_images ? nlohmann::json() : jvl::fidelity::SummariseImages(images);
    body["stages"] = nlohmann::json();
    if (any_stage) {
      stage_options.Check();
      // The ground truth over the frame range (every frame, whatever --every).
      const jvl::Trajectory all = !gt_path.empty()          ? jvl::io::ReadTrajectory(gt_path)
                                  : dataset->ground_truth() ? *dataset->ground_truth()
                                                            : jvl::Trajectory();
      jvl::Trajectory gt;
      for (const int64_t f : dataset->frames())
        if (const auto i = all.IndexOf(f)) gt.Append(f, all.world_from_cam[*i]);
      JVL_CHECK(gt.size() >= 2 || (odometry_path.empty() && vps_path.empty()),
                "sensor_stats: --odometry and --vps need ground-truth poses of the frames (the "
                "dataset has "
                    << gt.size() << "; give --gt POSES)");
      if (gt.empty())  // --visual alone: its keyframes need no ground truth.
        for (const int64_t f : dataset->frames()) gt.Append(f, jvl::Rigid3d());
      jvl::fidelity::StageSeries series = jvl::fidelity::MakeStageSeries(gt);
      if (!odometry_path.empty())
        jvl::fidelity::AddOdometryStats(gt, jvl::io::ReadTrajectory(odometry_path), stage_options,
                                        &series);
      if (!vps_path.empty())
        jvl::fidelity::AddVpStats(gt, jvl::io::ReadVpsArtifact(vps_path), stage_options, &series);
      if (!visual_path.empty())
        jvl::fidelity::AddVisualStats(jvl::io::ReadVisualMap(visual_path), &series);
      body["stage_frames"] = series.frames;
      body["stages"] = jvl::fidelity::SummariseStages(series, !odometry_path.empty(),
                                                      !vps_path.empty(), !visual_path.empty());
    }
    jvl::io::WriteJsonArtifact(output, "sensor_stats", 1, body, tool.MakeProvenance());
    auto report = [&](const char* kind, const nlohmann::json& part) {
      if (part.is_null()) return;
      for (const auto& [name, v] : part.items()) {
        const auto& m = v["median"];
        spdlog::info("{} {:<20} median {}", kind, name,
                     m.is_null() ? std::string("-") : fmt::format("{:.4g}", m.get<double>()));
      }
    };
    report("scan ", body["scan"]);
    report("image", body["image"]);
    report("stage", body["stages"]);
    spdlog::info("sensor_stats: {} frames of {} -> {}", used.size(), dataset->id(), output);
  });
}
