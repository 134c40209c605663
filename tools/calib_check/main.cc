// calib_check: how well a sequence's calibration (calib.txt's Tr) aligns the LiDAR with the
// camera, measured on the data: the rotation of the extrinsic that puts the LiDAR's depth edges
// on the images' edges (libs/fidelity/edge_alignment.h), with its spread over the frames ->
// one JSON artifact, optionally a corrected calib.txt.
#include <spdlog/spdlog.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "app/option_group.h"
#include "app/tool.h"
#include "core/check.h"
#include "core/progress.h"
#include "core/strings.h"
#include "core/threads.h"
#include "fidelity/edge_alignment.h"
#include "geometry/rigid3.h"
#include "io/artifact.h"
#include "io/dataset.h"
#include "io/kitti.h"
#include "lidar/preprocess.h"

namespace {

// The frame's image with its edge points at calib.txt's extrinsic (red) and at the corrected one
// (green), as a PNG.
void WriteOverlay(const std::string& path, const cv::Mat& image,
                  const jvl::fidelity::AlignmentFrame& frame, const jvl::PinholeCamera& camera,
                  const Eigen::Vector3d& offset, const Eigen::Vector3d& correction_deg) {
  cv::Mat out;
  if (image.channels() == 1) {
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  } else {
    out = image.clone();
  }
  const Eigen::Matrix3d corrected = jvl::ExpSO3(correction_deg * (M_PI / 180.0)).toRotationMatrix();
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::Matrix3d r = pass == 0 ? Eigen::Matrix3d::Identity() : corrected;
    const cv::Vec3b colour = pass == 0 ? cv::Vec3b(0, 0, 255) : cv::Vec3b(0, 255, 0);
    for (const Eigen::Vector3d& p : frame.points) {
      const Eigen::Vector2d uv = camera.Project(r * p + offset);
      const int u = static_cast<int>(std::lround(uv.x())),
                v = static_cast<int>(std::lround(uv.y()));
      if (u >= 0 && v >= 0 && u < out.cols && v < out.rows) out.at<cv::Vec3b>(v, u) = colour;
    }
  }
  jvl::io::WriteImage(path, out);
}

}  // namespace

int main(int argc, char** argv) {
  jvl::app::Tool tool(
      "calib_check",
      "Checks a sequence's camera-LiDAR calibration on its own data: finds the rotation of "
      "calib.txt's extrinsic (Tr) that puts the LiDAR's depth edges (returns nearer than their "
      "ring neighbour) on the image edges, summed over the frames (Levinson and Thrun, RSS 2013), "
      "and its spread by a bootstrap over the frames. Only the rotation is searched.");
  std::string dataset_dir, frames = ":", output, write_calib, overlay;
  jvl::io::DatasetOptions dataset_options;
  int every = 1, camera = 0, max_frames = 200;
  jvl::lidar::PreprocessOptions preprocess;  // Only its vertical correction is used.
  jvl::fidelity::EdgeAlignmentOptions options;
  CLI::App& cli = tool.cli();
  cli.add_option("--dataset,-d", dataset_dir, "Sequence folder (KITTI odometry/raw, synthetic)")
      ->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--frames", frames, "Frame range A:B (B exclusive)")->capture_default_str();
  cli.add_option("--every", every, "Use every K-th frame of the range")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cli.add_option("--max-frames", max_frames,
                 "Use at most this many frames, spread evenly over the range (each keeps two "
                 "image-sized fields, 3.7 MB for a KITTI image); 0 = every selected frame")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cli.add_option("--camera", camera, jvl::io::kCameraHelp)->capture_default_str();
  tool.OutputFile(
      cli.add_option("-o,--output", output, "Output JSON (calib_check artifact)")->required());
  tool.OutputFile(cli.add_option(
      "--write-calib", write_calib,
      "Also write the sequence's calib.txt with Tr corrected by the rotation found here"));
  tool.OutputFile(cli.add_option(
      "--overlay", overlay,
      "Also write the first frame's image as a PNG with its LiDAR edge points at calib.txt's Tr "
      "(red) and at the corrected one (green)"));
  jvl::app::OptionGroup edges(tool, "Edges");
  edges.Add("--vertical-correction", "vertical_correction_deg", preprocess.vertical_correction_deg,
            "Raise every return's elevation by this before the check (deg; the KITTI HDL-64's "
            "elevation error, 0.205, as lidar_odom's option of that name; 0 = off)");
  edges.Add("--min-discontinuity", "min_discontinuity_m", options.min_discontinuity_m,
            "A LiDAR return is a depth edge when a ring neighbour lies this much farther (m)");
  edges.Add("--min-depth", "min_depth_m", options.min_depth_m,
            "Edge points nearer than this (camera depth, m) are not used: there a calibration's "
            "translation error moves them as much as its rotation");
  edges.Add("--max-depth", "max_depth_m", options.max_depth_m,
            "Edge points farther than this are not used (m)");
  edges.Add("--edge-decay", "edge_decay", options.edge_decay,
            "Spread of the image edges: an edge counts decay^d at d pixels from it");
  jvl::app::OptionGroup search(tool, "Search");
  search.Add("--search", "search_deg", options.search_deg,
             "Rotations searched about each axis: +- this (deg)");
  search.Add("--coarse-step", "coarse_step_deg", options.coarse_step_deg, "Coarse grid step (deg)");
  search.Add("--fine-step", "fine_step_deg", options.fine_step_deg, "Fine grid step (deg)");
  search.Add("--bootstrap", "bootstrap", options.bootstrap,
             "Resamplings of the frames for the spread of the estimate (0 = none)");
  search.Add("--seed", options.seed, "Seed of the bootstrap");
  search.Add("--min-edge-points", "min_edge_points", options.min_edge_points,
             "Fewer LiDAR depth edges in the images over all frames is an error");

  return tool.Run(argc, argv, [&] {
    options.Check();
    preprocess.Check();
    cv::setNumThreads(1);  // Parallelism is over frames and rotations.
    const auto dataset =
        jvl::io::OpenDataset(dataset_dir, dataset_options, jvl::ParseFrameRange(frames));
    tool.AddDataset(*dataset, dataset_dir);
    dataset->CheckCamera(camera);
    const jvl::Calibration& calibration = dataset->calibration();
    std::vector<int64_t> selected;
    for (size_t i = 0; i < dataset->frames().size(); i += static_cast<size_t>(every))
      selected.push_back(dataset->frames()[i]);
    JVL_CHECK(!selected.empty(), "calib_check: no frame in the range");
    std::vector<int64_t> used = selected;
    if (max_frames > 0 && selected.size() > static_cast<size_t>(max_frames)) {
      // Evenly spread: frame k * n / max_frames of the selection, k = 0 .. max_frames - 1.
      used.clear();
      for (int k = 0; k < max_frames; ++k)
        used.push_back(
            selected[static_cast<size_t>(k) * selected.size() / static_cast<size_t>(max_frames)]);
      spdlog::info(
          "calib_check: {} of the {} selected frames, spread evenly over the range (--max-frames "
          "{}; 0 takes them all, at 3.7 MB each for a KITTI image)",
          used.size(), selected.size(), max_frames);
    }
    std::vector<jvl::fidelity::AlignmentFrame> aligned(used.size());
    jvl::Progress progress("frames", static_cast<int64_t>(used.size()), !tool.quiet());
    jvl::ParallelFor(static_cast<int64_t>(used.size()), tool.threads(), [&](int64_t i) {
      jvl::PointCloud scan = dataset->LoadScan(used[i]);
      if (preprocess.vertical_correction_deg != 0)
        jvl::lidar::CorrectVerticalAngle(preprocess.vertical_correction_deg * M_PI / 180.0,
                                         &scan.points);
      aligned[i] = jvl::fidelity::MakeAlignmentFrame(scan, dataset->LoadImage(used[i], camera),
                                                     calibration, camera, options);
      progress.Tick();
    });
    const jvl::fidelity::EdgeAlignmentResult r =
        jvl::fidelity::AlignEdges(aligned, calibration.Camera(camera),
                                  calibration.CameraOffset(camera), options, tool.threads());
    nlohmann::json body = jvl::fidelity::EdgeAlignmentJson(r, options);
    body["frames"] = used;
    body["camera"] = camera;
    body["vertical_correction_deg"] = preprocess.vertical_correction_deg;
    const int better = body["frames_better"].get<int>();
    jvl::io::WriteJsonArtifact(output, "calib_check", 1, body, tool.MakeProvenance());
    if (!write_calib.empty())
      jvl::io::WriteKittiCalibration(
          write_calib, jvl::fidelity::CorrectedCalibration(calibration, r.correction_deg));
    if (!overlay.empty())
      WriteOverlay(overlay, dataset->LoadImage(used[0], camera), aligned[0],
                   calibration.Camera(camera), calibration.CameraOffset(camera), r.correction_deg);
    if (options.bootstrap > 0 && r.bootstrap_at_border * 20 > options.bootstrap)
      spdlog::warn(
          "calib_check: {} of {} bootstrap resamples found their best rotation on the border of "
          "the fine grid: the spread given is cut there and is too small",
          r.bootstrap_at_border, options.bootstrap);
    if (r.at_search_limit)
      spdlog::warn(
          "calib_check: the best rotation lies at the border of the search (+-{} deg): the "
          "calibration may be off by more; widen --search",
          options.search_deg);
    spdlog::info(
        "calib_check: {} frames, {} edge points; correction pitch {:+.3f} yaw {:+.3f} roll "
        "{:+.3f} deg (bootstrap std {:.3f} / {:.3f} / {:.3f}), {:.3f} deg in all; edge score "
        "{:.3f} -> {:.3f}, better on {} of {} frames -> {}",
        used.size(), r.edge_points, r.correction_deg.x(), r.correction_deg.y(),
        r.correction_deg.z(), r.bootstrap_std_deg.x(), r.bootstrap_std_deg.y(),
        r.bootstrap_std_deg.z(), r.correction_deg.norm(), r.score_calibration, r.score_corrected,
        better, used.size(), output);
  });
}
