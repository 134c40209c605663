// local_map: joint visual + point-to-IMLS optimisation per keyframe (paper Sec. 4.2,
// supplement 1.2) over the visual map of visual_assoc and the dataset's scans.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>
#include <utility>

#include "app/tool.h"
#include "cli_options.h"
#include "core/check.h"
#include "core/progress.h"
#include "io/dataset.h"
#include "io/local_io.h"
#include "io/trajectory_io.h"
#include "io/visual_io.h"
#include "mapping/local/local_artifact.h"
#include "mapping/local/local_mapping.h"

namespace {

// Fewer surface points than this in a keyframe's scan is warned about: the IMLS term samples
// up to 9 lists of --samples-per-list points and needs a spread of normals.
constexpr size_t kFewSurfacePoints = 100;

}  // namespace

int main(int argc, char** argv) {
  using namespace jvl;
  app::Tool tool("local_map",
                 "Refine keyframe poses and map points by joint visual / point-to-IMLS local "
                 "optimisation of each keyframe.");
  std::string visual_path, dataset_dir, prior_path, output, kitti_poses;
  io::DatasetOptions dataset_options;
  std::string deskew = "auto";
  std::string vertical_correction = "auto";
  mapping::LocalMappingOptions options;
  mapping::ScanOptions scan_options;
  auto& cli = tool.cli();
  tool.InputFile(
      cli.add_option("--visual", visual_path, "visual.h5 from visual_assoc")->required());
  cli.add_option("--dataset", dataset_dir, "Dataset folder (the scans)")->required();
  tool.AddDatasetOptions(&dataset_options);
  cli.add_option("--deskew", deskew,
                 "Constant-velocity de-skewing of each keyframe's scan with the prior's motion: "
                 "auto (when the dataset's scans are not motion-compensated: KITTI raw, "
                 "sim_sequence --motion-distortion), on or off")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "on", "off"}));
  tool.InputFile(
      cli.add_option("--prior", prior_path,
                     "Initial poses (.h5, KITTI or TUM); default: the visual artifact's prior"));
  tool.OutputFile(cli.add_option("-o,--output", output, "Output local.h5")->required());
  tool.OutputFile(cli.add_option("--kitti-poses", kitti_poses,
                                 "Also write the refined keyframes as KITTI text"));
  tools::AddLocalMapFlags(tool, &options, &scan_options, &vertical_correction);
  return tool.Run(argc, argv, [&] {
    options.Check();
    scan_options.Check();
    tool.AddInput(visual_path);
    // The visual artifact is read without its descriptors (not used here; with them it took about
    // 0.4 GiB on a 4000-keyframe drive) and released once the input is assembled.
    Trajectory prior;
    const mapping::LocalMappingInput input = [&] {
      const io::VisualMapData visual =
          io::ReadVisualMap(visual_path, io::VisualMapParts::kWithoutDescriptors);
      JVL_CHECK(!visual.keyframes.empty(), visual_path << ": no keyframes (nothing to refine)");
      io::WarnIfCovisibilitySplit(visual, visual_path);
      prior = visual.prior;
      if (!prior_path.empty()) {
        tool.AddInput(prior_path);
        prior = io::ReadTrajectory(prior_path);
      }
      return mapping::MakeLocalMappingInput(
          visual, prior, prior_path.empty() ? visual_path + " (prior)" : prior_path);
    }();
    auto dataset = io::OpenDataset(dataset_dir, dataset_options, FrameRange());
    tool.AddDataset(*dataset, dataset_dir);
    const Rigid3d cam0_from_velo = dataset->calibration().cam0_from_velo;
    const bool deskew_scans = io::ResolveDeskew(deskew, *dataset);
    scan_options.preprocess.vertical_correction_deg =
        io::ResolveVerticalCorrection(vertical_correction, *dataset);
    scan_options.Check();
    Progress progress("local_map", static_cast<int64_t>(input.size()), !tool.quiet());
    mapping::LocalMappingResult result = mapping::RunLocalMapping(
        input,
        [&](size_t row) {
          const PointCloud scan = dataset->LoadScan(input.frames[row]);
          const std::optional<Rigid3d> sweep =
              deskew_scans ? mapping::SweepMotion(prior, input.frames[row]) : std::nullopt;
          const auto& ids = dataset->frames();
          const size_t index = static_cast<size_t>(
              std::lower_bound(ids.begin(), ids.end(), input.frames[row]) - ids.begin());
          mapping::KeyframeScan prepared = mapping::PrepareKeyframeScan(
              scan, cam0_from_velo, scan_options, options.association.samples_per_list,
              tool.threads(), sweep, dataset->ScanTimeOffsetInFrames(index));
          // An empty scan is reported by the dataset; a nearly empty or degenerate one (all
          // points at the origin, a few points) leaves the keyframe's IMLS term weak or empty.
          if (!scan.empty() && prepared.sampled.size() < kFewSurfacePoints) {
            spdlog::warn(
                "{}: only {} of {} points have a surface normal after filtering (frame {}): the "
                "LiDAR term of this keyframe is weak",
                dataset->ScanPath(input.frames[row]), prepared.sampled.size(), scan.size(),
                input.frames[row]);
          }
          return prepared;
        },
        options, tool.threads(),
        [&](size_t, const mapping::KeyframeStats& s) {
          spdlog::debug(
              "keyframe {}: local {}, model {}, fixed {}, visual {}, imls {} ({} new, {} "
              "reused), cost {:.1f} -> {:.1f} in {} iterations, moved {:.3f} m, {:.0f} ms ({:.0f} "
              "ms "
              "scan, {:.0f} ms association)",
              s.frame, s.local_keyframes, s.model_keyframes, s.fixed_keyframes, s.visual_residuals,
              s.imls_residuals, s.new_correspondences, s.reused_correspondences, s.cost_before,
              s.cost_after, s.iterations, s.correction_m, s.time_ms, s.scan_ms, s.associate_ms);
          progress.Tick();
        });
    const nlohmann::json summary = mapping::SummarizeLocalMap(result, options);
    // The result's scans and correspondences move into the artifact's arrays (not copied next
    // to them); its poses stay for the KITTI poses.
    io::WriteLocalMap(output, mapping::ExportLocalMap(input, std::move(result), prior, summary),
                      tool.MakeProvenance());
    if (!kitti_poses.empty()) {
      io::WriteTrajectoryKitti(kitti_poses, mapping::RefinedKeyframes(input, result));
    }
    std::printf("%s\n", summary.dump().c_str());
    spdlog::info("local_map: {} keyframes, {:.0f} ms median per keyframe; wrote {}", input.size(),
                 summary.at("median_time_ms").get<double>(), output);
  });
}
