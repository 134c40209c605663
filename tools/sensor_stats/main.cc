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
#include "io/artifact.h"
#include "io/dataset.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("sensor_stats",
                      "Statistics of the raw LiDAR scans and camera images of a sequence (real or "
                      "simulated), for the simulator's fidelity table: median, 10 % and 90 % "
                      "quantile over the frames of every statistic, and the per-frame values.");
  std::string dataset_dir, frames = ":", output;
  jvl::io::DatasetOptions dataset_options;
  int every = 1, camera = 0;
  bool no_scans = false, no_images = false;
  jvl::fidelity::ScanStatsOptions scan_options;
  jvl::fidelity::ImageStatsOptions image_options;
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
    JVL_CHECK(!(no_scans && no_images), "sensor_stats: --no-scans and --no-images leave nothing");
    cv::setNumThreads(1);  // Parallelism is over frames.
    const auto dataset =
        jvl::io::OpenDataset(dataset_dir, dataset_options, jvl::ParseFrameRange(frames));
    tool.AddDataset(*dataset, dataset_dir);
    if (!no_images) dataset->CheckCamera(camera);
    std::vector<int64_t> used;
    for (size_t i = 0; i < dataset->frames().size(); i += static_cast<size_t>(every))
      used.push_back(dataset->frames()[i]);
    std::vector<jvl::fidelity::ScanStats> scans(no_scans ? 0 : used.size());
    std::vector<jvl::fidelity::ImageStats> images(no_images ? 0 : used.size());
    jvl::Progress progress("frames", static_cast<int64_t>(used.size()), !tool.quiet());
    jvl::ParallelFor(static_cast<int64_t>(used.size()), tool.threads(), [&](int64_t i) {
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
    spdlog::info("sensor_stats: {} frames of {} -> {}", used.size(), dataset->id(), output);
  });
}
