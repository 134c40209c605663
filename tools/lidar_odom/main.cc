// lidar_odom: IMLS scan-to-model LiDAR odometry (paper Sec. 4.1, supplement 1.1) over a
// dataset's velodyne scans; writes the odometry artifact (world_from_cam0 per frame plus
// per-frame diagnostics) and optionally KITTI pose text.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <ctime>
#include <future>
#include <string>

#include "app/tool.h"
#include "cli_options.h"
#include "core/progress.h"
#include "core/statistics.h"
#include "core/timer.h"
#include "io/dataset.h"
#include "io/odometry_io.h"
#include "io/trajectory_io.h"
#include "lidar/odometry.h"

namespace {

void AppendFrame(const jvl::lidar::OdometryFrame& f, double stamp, jvl::io::OdometryArtifact* a) {
  const jvl::lidar::FrameDiagnostics& d = f.diagnostics;
  a->trajectory.Append(f.frame, f.world_from_cam, stamp);
  jvl::io::OdometryDiagnostics& o = a->diagnostics;
  o.iterations.push_back(d.iterations);
  o.residual.push_back(d.residual);
  o.correspondences.push_back(d.correspondences);
  o.time_ms.push_back(d.time_ms);
  o.degenerate.push_back(d.degenerate ? 1 : 0);
  o.points_after_filter.push_back(d.points_after_filter);
  o.status.push_back(static_cast<int32_t>(d.status));
  o.non_finite_points.push_back(d.non_finite_points);
  o.min_eigenvalue.push_back(d.min_eigenvalue);
}

}  // namespace

int main(int argc, char** argv) {
  jvl::app::Tool tool("lidar_odom", "IMLS scan-to-model LiDAR odometry (prior trajectory).");
  std::string dataset_dir, frames = ":", output, kitti_poses;
  jvl::io::DatasetOptions dataset_options;
  jvl::lidar::OdometryOptions options;
  std::string deskew = "auto";
  std::string vertical_correction = "auto";
  auto& cli = tool.cli();
  cli.add_option("--dataset", dataset_dir, "Sequence folder (KITTI odometry/raw, synthetic)")
      ->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--frames", frames, "Frame range A:B (B exclusive)")->capture_default_str();
  tool.OutputFile(cli.add_option("-o,--output", output, "Odometry artifact (.h5)")->required());
  tool.OutputFile(cli.add_option("--kitti-poses", kitti_poses, "Also write KITTI pose text here"));
  jvl::tools::AddLidarOdomFlags(tool, &options, &deskew, &vertical_correction);
  return tool.Run(argc, argv, [&] {
    options.Check();
    const auto dataset =
        jvl::io::OpenDataset(dataset_dir, dataset_options, jvl::ParseFrameRange(frames));
    tool.AddDataset(*dataset, dataset_dir);
    options.deskew = jvl::io::ResolveDeskew(deskew, *dataset);
    options.preprocess.vertical_correction_deg =
        jvl::io::ResolveVerticalCorrection(vertical_correction, *dataset);
    options.Check();
    jvl::lidar::Odometry odometry(dataset->calibration().cam0_from_velo, options, tool.threads());
    jvl::io::OdometryArtifact artifact;
    const auto& ids = dataset->frames();
    const std::clock_t cpu_start = std::clock();
    jvl::Progress progress("lidar_odom", static_cast<int64_t>(ids.size()), !tool.quiet());
    // With two or more threads the next scan is read while this one is registered.
    struct Loaded {
      jvl::PointCloud scan;
      size_t dropped = 0;
    };
    const auto load = [&](size_t k) {
      Loaded l;
      l.scan = dataset->LoadScan(ids[k], &l.dropped);
      return l;
    };
    const bool prefetch = tool.threads() >= 2;
    std::future<Loaded> pending;
    if (prefetch && !ids.empty()) pending = std::async(std::launch::async, load, 0);
    for (size_t k = 0; k < ids.size(); ++k) {
      const Loaded loaded = prefetch ? pending.get() : load(k);
      if (prefetch && k + 1 < ids.size()) pending = std::async(std::launch::async, load, k + 1);
      const auto f = odometry.ProcessScan(loaded.scan, ids[k], static_cast<int64_t>(loaded.dropped),
                                          dataset->ScanTimeOffsetInFrames(k));
      const auto& stamps = dataset->timestamps();
      AppendFrame(f, k < stamps.size() ? stamps[k] : static_cast<double>(ids[k]), &artifact);
      progress.Tick();
    }
    // CPU time (all threads, reading included) is also given: on a shared machine it is a
    // steadier figure than wall time.
    const double cpu_ms = 1e3 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const auto& d = artifact.diagnostics;
    const auto flagged = std::count(d.degenerate.begin(), d.degenerate.end(), 1);
    spdlog::info(
        "{} frames; per scan {:.1f} ms median, {:.1f} ms p95, {:.1f} ms max wall, "
        "{:.1f} ms CPU mean; {} flagged; {} threads; peak memory {:.0f} MiB",
        ids.size(), jvl::Quantile(d.time_ms, 0.5), jvl::Quantile(d.time_ms, 0.95),
        jvl::Quantile(d.time_ms, 1.0), cpu_ms / std::max<double>(1.0, ids.size()), flagged,
        tool.threads(), static_cast<double>(jvl::PeakMemoryBytes()) / (1 << 20));
    jvl::io::WriteOdometryArtifact(output, artifact, tool.MakeProvenance());
    if (!kitti_poses.empty()) jvl::io::WriteTrajectoryKitti(kitti_poses, artifact.trajectory);
  });
}
