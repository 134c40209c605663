// vp_detect: up to 3 vanishing points per left image (Supplement 1.4, step 1) -> vps.h5.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "app/tool.h"
#include "cli_options.h"
#include "core/strings.h"
#include "io/dataset.h"
#include "io/vps_io.h"
#include "vp_detect_run.h"

int main(int argc, char** argv) {
  jvl::app::Tool tool("vp_detect", "Detect up to 3 vanishing points in every left image.");
  std::string dataset_dir, frames = ":", output, csv;
  jvl::io::DatasetOptions dataset_options;
  jvl::VpDetectRunOptions run;
  std::string detector = jvl::ToString(run.detect.segments.detector);
  CLI::App& cli = tool.cli();
  cli.add_option("--dataset", dataset_dir, "Sequence folder (KITTI odometry/raw, synthetic)")
      ->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--frames", frames, "Frame range A:B (B exclusive)")->capture_default_str();
  cli.add_option("--camera", run.camera, jvl::io::kCameraHelp)->capture_default_str();
  tool.OutputFile(cli.add_option("-o,--output", output, "Output artifact (vps.h5)")->required());
  tool.OutputFile(cli.add_option("--csv", csv, "Also write one CSV row per VP to this file"));
  cli.add_option("--debug-dir", run.debug_dir, "Write overlay images (segments by VP) here");
  jvl::tools::AddVpDetectFlags(tool, &run, &detector);

  return tool.Run(argc, argv, [&] {
    run.detect.segments.detector = jvl::ParseLineDetector(detector);
    run.detect.Check();
    run.threads = tool.threads();
    run.progress = !tool.quiet();
    cv::setNumThreads(1);  // Parallelism is over frames; keep OpenCV single-threaded inside.
    const auto dataset =
        jvl::io::OpenDataset(dataset_dir, dataset_options, jvl::ParseFrameRange(frames));
    tool.AddDataset(*dataset, dataset_dir);
    const jvl::VpDetectRunResult result = jvl::RunVpDetect(*dataset, run);
    jvl::io::WriteVpsArtifact(output, result.data, tool.MakeProvenance());
    if (!csv.empty()) jvl::io::WriteVpsCsv(csv, result.data);
    std::vector<double> ms = result.detect_ms;
    std::sort(ms.begin(), ms.end());
    spdlog::info(
        "vp_detect: {} frames, {} VPs, {} frames with VPs, {} with a forward VP; "
        "median {:.1f} ms per image -> {}",
        result.data.frames.size(), result.data.vps.size(), result.frames_with_vps,
        result.frames_with_forward, ms.empty() ? 0.0 : ms[ms.size() / 2], output);
  });
}
