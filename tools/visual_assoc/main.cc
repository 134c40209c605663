// visual_assoc: ORB features, map points and keyframes from prior poses (Sec. 4.1).
#include <spdlog/spdlog.h>

#include <cstdio>

#include "app/tool.h"
#include "cli_options.h"
#include "core/check.h"
#include "core/progress.h"
#include "io/dataset.h"
#include "io/directions_io.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "mapping/visual/map_builder.h"
#include "mapping/visual/visual_artifact.h"

int main(int argc, char** argv) {
  using namespace jvl;
  app::Tool tool("visual_assoc",
                 "Build the visual map (ORB keyframes, map points, observations, covisibility) "
                 "from prior poses.");
  std::string dataset_dir, frames = ":", prior_path, directions_path, output;
  io::DatasetOptions dataset_options;
  int camera = 0;
  mapping::VisualMapOptions options;
  auto& cli = tool.cli();
  cli.add_option("--dataset", dataset_dir, "Dataset folder (KITTI sequence)")->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--frames", frames, "Frame range A:B (B exclusive)")->capture_default_str();
  cli.add_option("--camera", camera, io::kCameraHelp)->capture_default_str();
  tool.InputFile(
      cli.add_option("--prior", prior_path, "Prior trajectory (.h5, KITTI or TUM)")->required());
  tool.InputFile(cli.add_option("--directions", directions_path,
                                "directions.h5: its frames become keyframes"));
  tool.OutputFile(cli.add_option("-o,--output", output, "Output visual.h5")->required());
  tools::AddVisualMapFlags(tool, &options);
  return tool.Run(argc, argv, [&] {
    options.Check();
    auto dataset = io::OpenDataset(dataset_dir, dataset_options, ParseFrameRange(frames));
    tool.AddDataset(*dataset, dataset_dir);
    tool.AddInput(prior_path);
    const Trajectory prior = io::ReadTrajectory(prior_path);
    dataset->CheckCamera(camera);
    const CameraChoice choice = CameraChoice::Of(dataset->calibration(), camera);
    // The map is built in the chosen camera's frame (world_from_camera = world_from_cam0 *
    // cam0_from_camera) and its keyframe poses are written back as world_from_cam0.
    Trajectory poses = mapping::SelectPriorPoses(prior, dataset->frames(), prior_path);
    for (Rigid3d& pose : poses.world_from_cam) pose = pose * choice.camera_from_cam0().Inverse();
    std::vector<int64_t> direction_frames;
    if (!directions_path.empty()) {
      for (const auto& a : io::ReadDirectionsArtifact(directions_path).associations)
        direction_frames.push_back(a.frame);
      tool.AddInput(directions_path);
    }
    Progress progress("visual_assoc", static_cast<int64_t>(poses.size()), !tool.quiet());
    const mapping::VisualMapResult result = mapping::BuildVisualMap(
        dataset->calibration().Camera(camera), poses, direction_frames,
        [&](int64_t f) { return dataset->LoadImage(f, camera); }, options, tool.threads(),
        [&](const mapping::FrameReport& r) {
          spdlog::debug(
              "frame {}: {} keypoints, tracked {}/{}, keyframe {} ({}), new {}, fused {}, "
              "culled {}, pose {} ({} inliers, {} predicted, correction {:.4f} deg {:.4f} m; "
              "{:.3f} deg / {:.3f} "
              "m from the prior), {:.1f} ms",
              r.frame, r.keypoints, r.tracked, r.candidates, r.keyframe,
              mapping::ToString(r.reason), r.new_points, r.fused, r.culled,
              r.pose_refined ? "refined" : "predicted", r.pose_inliers, r.predicted_inliers,
              r.correction_deg, r.correction_m, r.pose_change_deg, r.pose_change_m, r.ms);
          progress.Tick();
        });
    io::VisualMapData data =
        mapping::ExportVisualMap(result.map, prior, options.min_covisibility_weight);
    for (Rigid3d& pose : data.keyframes.world_from_cam) pose = pose * choice.camera_from_cam0();
    data.camera_choice = choice;
    data.summary = mapping::Summarize(result, mapping::ComputeStats(data));
    io::WriteVisualMap(output, data, tool.MakeProvenance());
    std::printf("%s\n", mapping::FormatSummary(data.summary).c_str());
    spdlog::info("visual_assoc: wrote {}", output);
  });
}
